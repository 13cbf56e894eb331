//! The one error type of the planning vocabulary, and small validation helpers that produce it.
//!
//! `Err` is for misuse and invalid input (style rule 6). A planner that runs but does not find a good
//! answer returns a value with a status instead (see [`crate::SolveStatus`]).

use trust_geometry::scale::{self, CountError, Quantity, ScaleError, Sci};

use crate::Vec3;

/// Three decimals for ordinary magnitudes, scientific notation for huge or tiny ones.
struct Sci3(f64);

impl std::fmt::Display for Sci3 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if self.0.is_finite() && (a == 0.0 || (1e-3..1e6).contains(&a)) {
            write!(f, "{:.3}", self.0)
        } else {
            write!(f, "{}", Sci(self.0))
        }
    }
}

/// Why a planning call was rejected.
///
/// Every variant names the offending field and value, so that a user who passes a bad scenario file or
/// a NaN from a sensor can see at once what to fix.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlanError {
    /// A number or vector is out of its valid range (non-finite, negative, empty, ...).
    #[error("invalid `{field}` = {value}: expected {expected}")]
    InvalidInput {
        /// Dotted path of the field, e.g. `start.v` or `durations[3]`.
        field: String,
        /// The offending value, formatted.
        value: String,
        /// What would have been accepted.
        expected: String,
    },
    /// A point that must lie in free space lies inside (or too close to) an obstacle.
    #[error(
        "`{field}` at {point:?} is in collision (clearance {} m, needed {} m)",
        Sci3(*.clearance),
        Sci3(*.needed)
    )]
    InCollision {
        /// Which point (`start`, `goal`, ...).
        field: String,
        /// The point.
        point: [f64; 3],
        /// Its signed distance to the nearest obstacle.
        clearance: f64,
        /// The clearance that was required.
        needed: f64,
    },
    /// A point that must lie inside the map bounds does not.
    #[error("`{field}` at {point:?} is outside the map bounds {min:?}..{max:?}")]
    OutOfBounds {
        /// Which point.
        field: String,
        /// The point.
        point: [f64; 3],
        /// Lower corner of the bounds.
        min: [f64; 3],
        /// Upper corner of the bounds.
        max: [f64; 3],
    },
    /// A request needs something a component does not support (e.g. a time-based homotopy check on an
    /// untimed path).
    #[error("{component} cannot handle this input: {reason}")]
    Unsupported {
        /// The component (its `name()`).
        component: String,
        /// Why.
        reason: String,
    },
    /// Invalid geometry (shape or map construction).
    #[error(transparent)]
    Geometry(#[from] trust_geometry::GeometryError),
    /// Invalid obstacle forecast.
    #[error(transparent)]
    Predict(#[from] trust_predict::PredictError),
    /// A number outside the scale policy (`trust_geometry::scale`, re-exported as
    /// [`crate::scale`]).
    #[error(transparent)]
    Scale(#[from] ScaleError),
    /// A count above its cap ([`crate::scale`]).
    #[error(transparent)]
    Count(#[from] CountError),
    /// An error reported by a concrete component (optimizer, frontend, ...), kept with its source.
    #[error("{component}: {source}")]
    Component {
        /// The component (its `name()`).
        component: String,
        /// The underlying error.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
}

/// Which variant a [`PlanError`] is, without its fields: for code that decides by the kind of
/// error (a report's events, [`PlanError::kind`]) and for logs (serialized as the variant's name
/// in snake case, `"in_collision"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum PlanErrorKind {
    /// [`PlanError::InvalidInput`].
    InvalidInput,
    /// [`PlanError::InCollision`].
    InCollision,
    /// [`PlanError::OutOfBounds`].
    OutOfBounds,
    /// [`PlanError::Unsupported`].
    Unsupported,
    /// [`PlanError::Geometry`].
    Geometry,
    /// [`PlanError::Predict`].
    Predict,
    /// [`PlanError::Scale`].
    Scale,
    /// [`PlanError::Count`].
    Count,
    /// [`PlanError::Component`].
    Component,
}

impl PlanError {
    /// Which variant this is.
    pub fn kind(&self) -> PlanErrorKind {
        match self {
            PlanError::InvalidInput { .. } => PlanErrorKind::InvalidInput,
            PlanError::InCollision { .. } => PlanErrorKind::InCollision,
            PlanError::OutOfBounds { .. } => PlanErrorKind::OutOfBounds,
            PlanError::Unsupported { .. } => PlanErrorKind::Unsupported,
            PlanError::Geometry(_) => PlanErrorKind::Geometry,
            PlanError::Predict(_) => PlanErrorKind::Predict,
            PlanError::Scale(_) => PlanErrorKind::Scale,
            PlanError::Count(_) => PlanErrorKind::Count,
            PlanError::Component { .. } => PlanErrorKind::Component,
        }
    }

    /// Shorthand for [`PlanError::InvalidInput`].
    pub fn invalid(
        field: impl Into<String>,
        value: impl std::fmt::Debug,
        expected: impl Into<String>,
    ) -> Self {
        PlanError::InvalidInput {
            field: field.into(),
            value: format!("{value:?}"),
            expected: expected.into(),
        }
    }
}

/// Checks that `x` is finite.
pub fn check_finite(field: &str, x: f64) -> Result<(), PlanError> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(PlanError::invalid(field, x, "a finite number"))
    }
}

/// Checks that `x` is finite and strictly positive.
pub fn check_positive(field: &str, x: f64) -> Result<(), PlanError> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(PlanError::invalid(field, x, "a finite number > 0"))
    }
}

/// Checks that `x` is finite and not negative.
pub fn check_non_negative(field: &str, x: f64) -> Result<(), PlanError> {
    if x.is_finite() && x >= 0.0 {
        Ok(())
    } else {
        Err(PlanError::invalid(field, x, "a finite number >= 0"))
    }
}

/// Checks that `x` is finite and inside the scale policy's range for `quantity`
/// ([`crate::scale`]).
pub fn check_scaled(field: &str, x: f64, quantity: Quantity) -> Result<(), PlanError> {
    check_finite(field, x)?;
    scale::check(field, x, quantity)?;
    Ok(())
}

/// Checks that every component of `v` is finite and inside the scale policy's range for
/// `quantity` ([`crate::scale`]).
pub fn check_scaled_vec(field: &str, v: &Vec3, quantity: Quantity) -> Result<(), PlanError> {
    check_finite_vec(field, v)?;
    scale::check_vec(field, v, quantity)?;
    Ok(())
}

/// Checks that `x` lies in the closed range `[lo, hi]` (in `unit`, `""` for a dimensionless
/// number); NaN and infinities are outside. Parameter structs use it for ranges derived from the
/// scale policy ([`crate::scale`]) that are narrower than a [`Quantity`]'s.
///
/// # Errors
/// [`PlanError::Scale`] naming `field`, the value in scientific notation and the range.
pub fn check_range(
    field: &str,
    x: f64,
    lo: f64,
    hi: f64,
    unit: &'static str,
) -> Result<(), PlanError> {
    if x >= lo && x <= hi {
        Ok(())
    } else {
        Err(PlanError::Scale(ScaleError {
            field: field.to_owned(),
            value: x,
            lo,
            hi,
            unit,
        }))
    }
}

/// Checks that every component of `v` is finite.
pub fn check_finite_vec(field: &str, v: &Vec3) -> Result<(), PlanError> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(PlanError::invalid(
            field,
            [v.x, v.y, v.z],
            "a vector with finite components",
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_field_and_value() {
        let e = check_positive("limits.v_max", -1.0).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("limits.v_max"), "{msg}");
        assert!(msg.contains("-1.0"), "{msg}");
        assert!(msg.contains("> 0"), "{msg}");

        let e = check_finite_vec("start.p", &Vec3::new(0.0, f64::NAN, 1.0)).unwrap_err();
        assert!(e.to_string().contains("start.p"));
        assert!(e.to_string().contains("NaN"));
    }

    #[test]
    fn accepts_valid_numbers() {
        assert!(check_finite("x", -3.0).is_ok());
        assert!(check_non_negative("x", 0.0).is_ok());
        assert!(check_non_negative("x", -0.1).is_err());
        assert!(check_positive("x", 0.0).is_err());
        assert!(check_finite("x", f64::INFINITY).is_err());
        assert!(check_range("x", 1.0, 0.0, 1.0, "m").is_ok());
        let e = check_range("p.w", 1e300, 0.0, 1e6, "")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("p.w") && e.contains("1.0e300") && e.contains("1.0e6"),
            "{e}"
        );
        assert!(check_range("x", f64::NAN, 0.0, 1.0, "m").is_err());
    }
}

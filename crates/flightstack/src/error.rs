//! The one error type of the crate, and the checks that produce it.

use trust_core::PlanError;
use trust_core::scale::{CountError, ScaleError, Sci};

/// Why an export was refused. Every variant names the offending field and value.
///
/// `Err` means invalid input or a trajectory the target cannot carry; a valid trajectory inside
/// the target's limits always exports.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FlightStackError {
    /// A number or setting outside its valid range (non-finite, negative, zero, …).
    #[error("invalid `{field}` = {value}: expected {expected}")]
    InvalidInput {
        /// Dotted path of the field, e.g. `rate_hz` or `yaw.min_speed_m_s`.
        field: String,
        /// The offending value, formatted.
        value: String,
        /// What would have been accepted.
        expected: String,
    },
    /// An evaluation time outside the trajectory's span (exports never extrapolate).
    #[error(
        "`{field}` = {} s lies outside the trajectory's span [{}, {}] s",
        Sci(*.t),
        Sci(*.t_start),
        Sci(*.t_end)
    )]
    TimeOutside {
        /// Which time.
        field: String,
        /// The time (s).
        t: f64,
        /// The trajectory's start (s).
        t_start: f64,
        /// The trajectory's end (s).
        t_end: f64,
    },
    /// A controlled value that the target's number type cannot hold (beyond `f32`, a timestamp
    /// past `u64`/`u32`).
    #[error("`{field}` = {} does not fit in {target}", Sci(*.value))]
    NotRepresentable {
        /// Which value.
        field: String,
        /// The value.
        value: f64,
        /// The target type, e.g. `f32`.
        target: &'static str,
    },
    /// More pieces than the target's trajectory memory holds.
    #[error("`{field}`: {count} pieces, but {target} holds at most {max}")]
    TooManyPieces {
        /// Which count (`traj.piece_count()`, `piece_offset + pieces`).
        field: String,
        /// The number of pieces asked for.
        count: usize,
        /// The most the target takes.
        max: usize,
        /// The target, e.g. `the Crazyflie's 4096-byte trajectory memory`.
        target: &'static str,
    },
    /// A setting the target has no way to express.
    #[error("{target} cannot express {what}")]
    Unsupported {
        /// The target, e.g. `Crazyflie poly4d`.
        target: &'static str,
        /// What it cannot express.
        what: String,
    },
    /// The trajectory itself is invalid (empty, non-finite coefficients, bad durations), as
    /// found by [`trust_core::PolyTraj::new`].
    #[error(transparent)]
    Trajectory(#[from] PlanError),
    /// A number outside the scale policy ([`trust_core::scale`]).
    #[error(transparent)]
    Scale(#[from] ScaleError),
    /// A count above its cap ([`trust_core::scale`]).
    #[error(transparent)]
    Count(#[from] CountError),
    /// Writing an export failed.
    #[error("writing {what}: {source}")]
    Io {
        /// What was being written.
        what: &'static str,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
}

impl FlightStackError {
    /// Shorthand for [`FlightStackError::InvalidInput`].
    pub fn invalid(
        field: impl Into<String>,
        value: impl std::fmt::Debug,
        expected: impl Into<String>,
    ) -> Self {
        FlightStackError::InvalidInput {
            field: field.into(),
            value: format!("{value:?}"),
            expected: expected.into(),
        }
    }
}

/// `x` as an `f32`, or [`FlightStackError::NotRepresentable`] if it is not finite or beyond
/// `f32::MAX` (values below `f32`'s smallest subnormal round to zero, as any cast does).
pub(crate) fn to_f32(field: impl FnOnce() -> String, x: f64) -> Result<f32, FlightStackError> {
    let y = x as f32;
    if x.is_finite() && y.is_finite() {
        Ok(y)
    } else {
        Err(FlightStackError::NotRepresentable {
            field: field(),
            value: x,
            target: "f32",
        })
    }
}

/// Each component of `v` as an `f32` (see [`to_f32`]), the field named `name[i]`.
pub(crate) fn vec_to_f32(name: &str, v: &trust_core::Vec3) -> Result<[f32; 3], FlightStackError> {
    Ok([
        to_f32(|| format!("{name}[0]"), v.x)?,
        to_f32(|| format!("{name}[1]"), v.y)?,
        to_f32(|| format!("{name}[2]"), v.z)?,
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f32_conversion_rejects_what_does_not_fit() {
        assert_eq!(to_f32(|| "x".into(), 1.5).unwrap(), 1.5);
        assert_eq!(to_f32(|| "x".into(), 1e-50).unwrap(), 0.0);
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e39, -1e39] {
            let e = to_f32(|| "position[2]".into(), bad)
                .unwrap_err()
                .to_string();
            assert!(e.contains("position[2]") && e.contains("f32"), "{e}");
        }
    }

    #[test]
    fn messages_name_field_and_value() {
        let e = FlightStackError::invalid("rate_hz", -1.0, "a rate in [2, 1e6] Hz").to_string();
        assert!(e.contains("rate_hz") && e.contains("-1.0"), "{e}");
        let e = FlightStackError::TimeOutside {
            field: "t".into(),
            t: 5.0,
            t_start: 0.0,
            t_end: 2.0,
        }
        .to_string();
        assert!(e.contains("`t` = 5") && e.contains("[0"), "{e}");
    }
}

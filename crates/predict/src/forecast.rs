//! Constant-velocity obstacle forecasts with a linearly growing uncertainty (paper Sec. III-D, the
//! dynamic distance field, DDF).

use serde::{Deserialize, Serialize};
use trust_geometry::{Aabb, Vec3, cylinder_sdf_with_size_gradient, sphere_sdf};

use crate::PredictError;
use crate::error::{check_finite, check_non_negative, check_positive, check_vec};
use trust_geometry::scale::Quantity;

/// Base shape of a moving obstacle.
///
/// The shape is inflated by `r_safe + mu·(t − t0)` (see [`Forecast::inflation`]): a sphere's radius
/// grows by that amount; a vertical cylinder's radius **and** half-height both grow by it. Growing
/// both is the conservative choice: the paper bounds the unmodelled displacement by
/// `‖δ(t)‖ ≤ mu·(t − t0)` in every direction, including vertically, and a cylinder inflated by `δ`
/// in radius and half-height contains its Minkowski sum with a ball of radius `δ`. (The paper's
/// "geometric scaling by r/r_o" would blow a tall cylinder up vertically by the same *factor*;
/// an additive inflation matches the displacement bound.)
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum ObstacleShape {
    /// A ball of radius `r_o` (before inflation).
    Sphere,
    /// A vertical (z-axis) cylinder of radius `r_o` and this half-height (before inflation),
    /// centred on the forecast centre.
    Cylinder {
        /// Half of the cylinder's height before inflation (m); must be finite and `> 0`.
        half_height: f64,
    },
}

/// A forecast of one moving obstacle made at time `t0` (paper Sec. III-B and III-D).
///
/// The obstacle centre moves at constant velocity, `center(t) = p0 + v0·(t − t0)`, and its
/// avoidance radius grows linearly, `radius(t) = r_o + r_safe + mu·(t − t0)` (paper eq. design-of-Io
/// and the text above it). This is the building block of the dynamic distance field (DDF):
/// [`Forecast::signed_distance`] and [`Forecast::distance_and_gradients`].
///
/// Conventions:
/// * Times before `t0`: the centre is extrapolated backwards along `v0` (the same straight line),
///   but the inflation is clamped at its `t0` value (`r_safe`) — an uncertainty never shrinks below
///   its value at the observation. Consequently `radius_rate(t) = 0` for `t < t0` and `mu` for
///   `t ≥ t0` (the right derivative at `t0`).
/// * Beyond the paper, the growth may stop `growth_s` seconds after `t0`
///   ([`Forecast::with_growth_for`]): `radius(t) = r_o + r_safe + mu·min(t − t0, growth_s)`, and
///   `radius_rate` is 0 from then on. [`Forecast::new`] grows for ever (`growth_s = ∞`).
/// * The fields are public for serde and for reading; build forecasts with [`Forecast::new`] (or
///   call [`Forecast::validate`] after deserializing or editing one). The query methods assume a
///   valid forecast and finite query arguments; non-finite arguments propagate per IEEE 754.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Forecast {
    /// Base shape.
    pub shape: ObstacleShape,
    /// Observed centre at `t0` (m).
    pub p0: Vec3,
    /// Estimated velocity (m/s).
    pub v0: Vec3,
    /// Time of the observation (s).
    pub t0: f64,
    /// Intrinsic size `r_o` (m): sphere radius or cylinder radius; `> 0`.
    pub r_o: f64,
    /// Additional safety margin `r_safe` (m); `≥ 0`.
    pub r_safe: f64,
    /// Uncertainty growth rate `mu_o` (m/s); `≥ 0`.
    pub mu: f64,
    /// How long after `t0` the uncertainty grows (s); `> 0`, `∞` (the default, and the paper's
    /// model) for ever. Absent from serialized forecasts that grow for ever.
    #[serde(default = "forever", skip_serializing_if = "is_forever")]
    pub growth_s: f64,
    /// The box the obstacle is known to stay inside, turning at its walls (beyond the paper): a
    /// prior the world gives, as the map's bounds are for every obstacle. The manager mirrors
    /// the forecast at these walls ([`crate::wall_images`]) instead of the map's. `None` (the
    /// default, absent when serialized): only the map's bounds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub walls: Option<Aabb>,
}

fn forever() -> f64 {
    f64::INFINITY
}

fn is_forever(s: &f64) -> bool {
    *s == f64::INFINITY
}

impl Forecast {
    /// Builds and validates a forecast.
    ///
    /// # Errors
    /// [`PredictError`] naming the field if any number is non-finite, `r_o ≤ 0`, `r_safe < 0`,
    /// `mu < 0`, or a cylinder's `half_height ≤ 0`.
    pub fn new(
        shape: ObstacleShape,
        p0: Vec3,
        v0: Vec3,
        t0: f64,
        r_o: f64,
        r_safe: f64,
        mu: f64,
    ) -> Result<Self, PredictError> {
        let f = Forecast {
            shape,
            p0,
            v0,
            t0,
            r_o,
            r_safe,
            mu,
            growth_s: f64::INFINITY,
            walls: None,
        };
        f.validate()?;
        Ok(f)
    }

    /// A sphere forecast; shorthand for [`Forecast::new`] with [`ObstacleShape::Sphere`].
    ///
    /// # Errors
    /// As [`Forecast::new`].
    pub fn sphere(
        p0: Vec3,
        v0: Vec3,
        t0: f64,
        r_o: f64,
        r_safe: f64,
        mu: f64,
    ) -> Result<Self, PredictError> {
        Self::new(ObstacleShape::Sphere, p0, v0, t0, r_o, r_safe, mu)
    }

    /// Checks the invariants listed on [`Forecast::new`].
    ///
    /// # Errors
    /// The first violated invariant, naming the field and value.
    pub fn validate(&self) -> Result<(), PredictError> {
        check_vec("forecast.p0", &self.p0, Quantity::Position)?;
        check_vec("forecast.v0", &self.v0, Quantity::Velocity)?;
        check_finite("forecast.t0", self.t0, Quantity::Time)?;
        check_positive("forecast.r_o", self.r_o, Quantity::Length)?;
        check_non_negative("forecast.r_safe", self.r_safe, Quantity::Length)?;
        check_non_negative("forecast.mu", self.mu, Quantity::Rate)?;
        if self.growth_s.is_nan() || self.growth_s <= 0.0 {
            return Err(PredictError::OutOfRange {
                field: "forecast.growth_s".into(),
                value: self.growth_s,
                expected: "> 0 s (∞: grows for ever)",
            });
        }
        if let ObstacleShape::Cylinder { half_height } = self.shape {
            check_positive("forecast.shape.half_height", half_height, Quantity::Length)?;
        }
        Ok(())
    }

    /// Obstacle centre at time `t`: `p0 + v0·(t − t0)` (also for `t < t0`). Finite for every `t`
    /// inside the scale policy (`|t| ≤ 1e7` s); a NaN `t` gives NaN (no time, no place).
    #[inline]
    pub fn center(&self, t: f64) -> Vec3 {
        self.p0 + self.v0 * (t - self.t0)
    }

    /// `d center/dt = v0`.
    #[inline]
    pub fn center_rate(&self) -> Vec3 {
        self.v0
    }

    /// This forecast with its growth held after `duration` seconds from `t0`: the same motion,
    /// `r_safe` raised to `r_safe + mu·max(duration, 0)` and `mu` zero. For a judgement that the
    /// next observations will revise anyway (the manager's fallback and its rest hold): grown
    /// without end, the uncertainty swallows every place near an obstacle's path.
    #[inline]
    pub fn growth_held_after(&self, duration: f64) -> Forecast {
        Forecast {
            r_safe: self.r_safe + self.mu * duration.clamp(0.0, self.growth_s),
            mu: 0.0,
            ..*self
        }
    }

    /// This forecast with its growth stopping `seconds` after `t0` (or sooner if it already
    /// did): the radius grows as before up to then and stays. For a replanning planner that
    /// judges a whole horizon against forecasts it revises every cycle (the manager's
    /// `forecast_growth_s`). `seconds` must be `> 0` ([`Forecast::validate`]).
    #[inline]
    pub fn with_growth_for(&self, seconds: f64) -> Forecast {
        Forecast {
            growth_s: self.growth_s.min(seconds),
            ..*self
        }
    }

    /// This forecast with the box the obstacle stays inside ([`Forecast::walls`]).
    #[inline]
    pub fn with_walls(&self, walls: Aabb) -> Forecast {
        Forecast {
            walls: Some(walls),
            ..*self
        }
    }

    /// Inflation added to the base shape at time `t`: `r_safe + mu·clamp(t − t0, 0, growth_s)`.
    #[inline]
    pub fn inflation(&self, t: f64) -> f64 {
        self.r_safe + self.mu * (t - self.t0).clamp(0.0, self.growth_s)
    }

    /// Avoidance radius `r_o + r_safe + mu·max(t − t0, 0)` (sphere radius or cylinder radius).
    #[inline]
    pub fn radius(&self, t: f64) -> f64 {
        self.r_o + self.inflation(t)
    }

    /// `d radius/dt`: `mu` for `t0 ≤ t < t0 + growth_s`, `0` before and after (the radius is
    /// clamped there). The inflated cylinder half-height grows at the same rate.
    #[inline]
    pub fn radius_rate(&self, t: f64) -> f64 {
        if t >= self.t0 && t - self.t0 < self.growth_s {
            self.mu
        } else {
            0.0
        }
    }

    /// Half of the vertical extent of the inflated obstacle at `t`: the radius for a sphere,
    /// `half_height + inflation(t)` for a cylinder.
    #[inline]
    pub fn vertical_half_extent(&self, t: f64) -> f64 {
        match self.shape {
            ObstacleShape::Sphere => self.radius(t),
            ObstacleShape::Cylinder { half_height } => half_height + self.inflation(t),
        }
    }

    /// Signed distance (m) from `p` to the inflated obstacle at time `t` (negative inside). This is
    /// the dynamic distance field (DDF) of paper Sec. III-D.
    #[inline]
    pub fn signed_distance(&self, p: &Vec3, t: f64) -> f64 {
        let c = self.center(t);
        match self.shape {
            ObstacleShape::Sphere => sphere_sdf(&c, self.radius(t), p).0,
            ObstacleShape::Cylinder { .. } => {
                cylinder_sdf_with_size_gradient(&c, self.radius(t), self.vertical_half_extent(t), p)
                    .distance
            }
        }
    }

    /// Returns `(d, ∂d/∂p, ∂d/∂t)`: the signed distance `d` from `p` to the inflated obstacle at
    /// time `t`, its gradient in `p` (a unit vector), and its total derivative in `t` for a fixed
    /// `p`, `∂d/∂t = −∂d/∂p · v0 + ∂d/∂size · radius_rate(t)` (paper eq. gradients-of-Io (b): centre
    /// motion plus size growth).
    ///
    /// A non-finite `p` or `t`, or one beyond `trust_geometry::scale::QUERY_LIMIT` (`1e90` s for
    /// `t`), gives `(-inf, 0, 0)`: "not free".
    ///
    /// Where `d` is not differentiable (sphere centre, cylinder axis, medial surfaces, and `t = t0`
    /// where the radius rate jumps) the gradient is a documented element of the subdifferential
    /// (see `trust_geometry::shapes`; at `t = t0` the right derivative). Add the ego term
    /// `∂d/∂p · ṗ` yourself for eq. gradients-of-Io (a).
    #[inline]
    pub fn distance_and_gradients(&self, p: &Vec3, t: f64) -> (f64, Vec3, f64) {
        // Beyond these magnitudes (or for non-finite input) the answer is "not free", with zero
        // gradients, as for the static map's non-finite queries.
        if !(trust_geometry::scale::queryable(&[p.x, p.y, p.z]) && t.abs() <= 1e90) {
            return (f64::NEG_INFINITY, Vec3::zeros(), 0.0);
        }
        let c = self.center(t);
        let rate = self.radius_rate(t);
        let (distance, d_p, d_size) = match self.shape {
            ObstacleShape::Sphere => {
                let (d, g) = sphere_sdf(&c, self.radius(t), p);
                // ∂d/∂radius = −1.
                (d, g, -rate)
            }
            ObstacleShape::Cylinder { .. } => {
                let s = cylinder_sdf_with_size_gradient(
                    &c,
                    self.radius(t),
                    self.vertical_half_extent(t),
                    p,
                );
                (
                    s.distance,
                    s.gradient,
                    (s.d_radius + s.d_half_height) * rate,
                )
            }
        };
        (distance, d_p, -d_p.dot(&self.v0) + d_size)
    }

    /// Axis-aligned box enclosing the inflated obstacle over every time in `[t_a, t_b]` (broad phase
    /// for the optimizer). Exact per axis for the centre path; the size used is the largest one in
    /// the window.
    ///
    /// # Errors
    /// [`PredictError`] if a time is non-finite or `t_a > t_b`.
    pub fn aabb_over(&self, t_a: f64, t_b: f64) -> Result<Aabb, PredictError> {
        check_finite("t_a", t_a, Quantity::Time)?;
        check_finite("t_b", t_b, Quantity::Time)?;
        if t_a > t_b {
            return Err(PredictError::InvalidWindow {
                t_start: t_a,
                t_end: t_b,
                hint: String::new(),
            });
        }
        let (ca, cb) = (self.center(t_a), self.center(t_b));
        let r = self.radius(t_b);
        let half = Vec3::new(r, r, self.vertical_half_extent(t_b));
        Ok(Aabb {
            min: ca.inf(&cb) - half,
            max: ca.sup(&cb) + half,
        })
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn growth_that_stops_holds_the_radius_and_its_rate() {
        let f = Forecast::sphere(Vec3::zeros(), Vec3::x(), 1.0, 0.5, 0.2, 0.4)
            .unwrap()
            .with_growth_for(1.5);
        assert_relative_eq!(f.radius(0.0), 0.7); // before t0: clamped
        assert_relative_eq!(f.radius(2.0), 0.7 + 0.4);
        assert_relative_eq!(f.radius(2.5), 0.7 + 0.6);
        assert_relative_eq!(f.radius(9.0), 0.7 + 0.6);
        assert_eq!(f.radius_rate(2.0), 0.4);
        assert_eq!(f.radius_rate(2.5), 0.0);
        assert_eq!(f.radius_rate(9.0), 0.0);
        // A shorter cap wins, a longer one does not lengthen it.
        assert_eq!(f.with_growth_for(1.0).growth_s, 1.0);
        assert_eq!(f.with_growth_for(3.0).growth_s, 1.5);
        // Held after 4 s: the growth stopped at 1.5 s.
        assert_relative_eq!(f.growth_held_after(4.0).radius(1.0), 0.7 + 0.6);
        // The default grows for ever.
        let g = Forecast::sphere(Vec3::zeros(), Vec3::x(), 1.0, 0.5, 0.2, 0.4).unwrap();
        assert_relative_eq!(g.radius(9.0), 0.7 + 3.2);
        let bad = Forecast { growth_s: 0.0, ..g };
        let e = bad.validate().unwrap_err().to_string();
        assert!(e.contains("forecast.growth_s"), "{e}");
        let nan = Forecast {
            growth_s: f64::NAN,
            ..g
        };
        assert!(nan.validate().is_err());
        // Serialized without the field when it grows for ever, with it otherwise.
        let json = serde_json::to_string(&g).unwrap();
        assert!(!json.contains("growth_s"), "{json}");
        assert_eq!(serde_json::from_str::<Forecast>(&json).unwrap(), g);
        let json = serde_json::to_string(&f).unwrap();
        assert_eq!(serde_json::from_str::<Forecast>(&json).unwrap(), f);
    }

    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    const H: f64 = 1e-6;

    fn v3(r: f64) -> impl Strategy<Value = Vec3> {
        (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    fn cylinder(p0: Vec3, v0: Vec3, half_height: f64, mu: f64) -> Forecast {
        Forecast::new(
            ObstacleShape::Cylinder { half_height },
            p0,
            v0,
            1.0,
            0.6,
            0.2,
            mu,
        )
        .unwrap()
    }

    /// Central differences of the signed distance in p and t.
    fn finite_differences(f: &Forecast, p: &Vec3, t: f64) -> (Vec3, f64) {
        let g =
            trust_numdiff::gradient_array(|q| f.signed_distance(&Vec3::from(q), t), (*p).into(), H);
        let gt = trust_numdiff::central_difference(|s| f.signed_distance(p, s), t, H);
        let g = Vec3::from(g);
        (g, gt)
    }

    /// Distance of `p` at `t` from the places where the cylinder distance is not differentiable
    /// (axis, mid-plane when a cap is involved, the inside medial surface).
    fn cylinder_kink_distance(f: &Forecast, p: &Vec3, t: f64) -> f64 {
        let q = p - f.center(t);
        let rho = q.x.hypot(q.y);
        let dr = rho - f.radius(t);
        let dz = q.z.abs() - f.vertical_half_extent(t);
        let mut k = rho.min(q.z.abs());
        if dr < 0.0 && dz < 0.0 {
            k = k.min((dr - dz).abs() / 2.0);
        }
        k
    }

    #[test]
    fn held_growth_stops_at_the_given_age() {
        let f = cylinder(Vec3::zeros(), Vec3::x(), 0.9, 0.5);
        let held = f.growth_held_after(2.0);
        held.validate().unwrap();
        assert_eq!(held.center(7.0), f.center(7.0));
        // The same size up to t0 + 2, then constant.
        assert_relative_eq!(held.radius(3.0), f.radius(3.0), epsilon = 1e-12);
        assert_relative_eq!(held.radius(9.0), f.radius(3.0), epsilon = 1e-12);
        assert!(held.radius(2.0) >= f.radius(2.0));
        assert_eq!(held.radius_rate(5.0), 0.0);
        assert_eq!(f.growth_held_after(-1.0).r_safe, f.r_safe);
    }

    #[test]
    fn validation_names_the_field() {
        let bad = Forecast::new(
            ObstacleShape::Sphere,
            Vec3::zeros(),
            Vec3::zeros(),
            0.0,
            0.0,
            0.1,
            0.1,
        );
        match bad {
            Err(PredictError::OutOfRange { field, value, .. }) => {
                assert_eq!(field, "forecast.r_o");
                assert_eq!(value, 0.0);
            }
            other => panic!("unexpected {other:?}"),
        }
        let nan = Forecast::sphere(
            Vec3::new(0.0, f64::NAN, 0.0),
            Vec3::zeros(),
            0.0,
            1.0,
            0.1,
            0.1,
        );
        assert!(
            matches!(nan, Err(PredictError::NonFinite { ref field, .. }) if field == "forecast.p0.y")
        );
        assert!(Forecast::sphere(Vec3::zeros(), Vec3::zeros(), 0.0, 1.0, -0.1, 0.1).is_err());
        assert!(Forecast::sphere(Vec3::zeros(), Vec3::zeros(), 0.0, 1.0, 0.1, -0.1).is_err());
        assert!(
            Forecast::sphere(Vec3::zeros(), Vec3::zeros(), f64::INFINITY, 1.0, 0.1, 0.1).is_err()
        );
        let cyl = Forecast::new(
            ObstacleShape::Cylinder { half_height: 0.0 },
            Vec3::zeros(),
            Vec3::zeros(),
            0.0,
            1.0,
            0.0,
            0.0,
        );
        assert!(
            matches!(cyl, Err(PredictError::OutOfRange { ref field, .. }) if field == "forecast.shape.half_height")
        );
        let msg = Forecast::sphere(Vec3::zeros(), Vec3::zeros(), 0.0, -2.0, 0.1, 0.1)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("forecast.r_o") && msg.contains("-2"), "{msg}");
    }

    #[test]
    fn center_radius_and_rates() {
        let f = Forecast::sphere(
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(1.0, 0.0, -1.0),
            2.0,
            0.5,
            0.25,
            0.1,
        )
        .unwrap();
        assert_relative_eq!(f.center(4.0), Vec3::new(3.0, 2.0, 1.0));
        assert_relative_eq!(f.center(1.0), Vec3::new(0.0, 2.0, 4.0)); // extrapolated backwards
        assert_eq!(f.center_rate(), f.v0);
        assert_relative_eq!(f.radius(4.0), 0.95);
        assert_relative_eq!(f.radius(0.0), 0.75); // clamped before t0
        assert_eq!(f.radius_rate(4.0), 0.1);
        assert_eq!(f.radius_rate(2.0), 0.1);
        assert_eq!(f.radius_rate(1.0), 0.0);
        assert_relative_eq!(f.vertical_half_extent(4.0), 0.95);
        let c = cylinder(Vec3::zeros(), Vec3::zeros(), 2.0, 0.5);
        assert_relative_eq!(c.vertical_half_extent(3.0), 2.0 + 0.2 + 1.0);
        assert_relative_eq!(c.radius(3.0), 0.6 + 0.2 + 1.0);
    }

    #[test]
    fn cylinder_regions_have_expected_distances() {
        let f = cylinder(Vec3::zeros(), Vec3::zeros(), 1.0, 0.0); // R = 0.8, H = 1.2 at any t
        let side = f.distance_and_gradients(&Vec3::new(2.0, 0.0, 0.3), 1.0);
        assert_relative_eq!(side.0, 1.2);
        assert_relative_eq!(side.1, Vec3::x());
        let cap = f.distance_and_gradients(&Vec3::new(0.1, 0.2, -2.0), 1.0);
        assert_relative_eq!(cap.0, 0.8);
        assert_relative_eq!(cap.1, -Vec3::z());
        let rim = f.distance_and_gradients(&Vec3::new(0.0, 1.1, 1.6), 1.0);
        assert_relative_eq!(rim.0, 0.5, epsilon = 1e-12);
        assert_relative_eq!(rim.1, Vec3::new(0.0, 0.6, 0.8), epsilon = 1e-12);
        let inside = f.distance_and_gradients(&Vec3::new(0.7, 0.0, 0.0), 1.0);
        assert_relative_eq!(inside.0, -0.1, epsilon = 1e-12);
        // A static obstacle with no growth: ∂d/∂t = 0.
        assert_eq!(inside.2, 0.0);
    }

    #[test]
    fn gradients_defined_at_centre_and_axis() {
        let f =
            Forecast::sphere(Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0), 0.0, 1.0, 0.0, 0.5).unwrap();
        let (d, g, dt) = f.distance_and_gradients(&Vec3::new(1.0, 0.0, 0.0), 1.0);
        assert_relative_eq!(d, -1.5);
        assert_relative_eq!(g.norm(), 1.0);
        assert!(dt.is_finite());
        let c = cylinder(Vec3::zeros(), Vec3::new(0.0, 1.0, 0.0), 1.0, 0.2);
        let (d, g, dt) = c.distance_and_gradients(&c.center(2.0), 2.0);
        assert!(d < 0.0 && g.iter().all(|x| x.is_finite()) && dt.is_finite());
    }

    #[test]
    fn aabb_over_bounds_the_swept_obstacle() {
        let f = cylinder(
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, -2.0, 0.5),
            1.5,
            0.3,
        );
        let b = f.aabb_over(1.0, 3.0).unwrap();
        for i in 0..=50 {
            let t = 1.0 + 2.0 * i as f64 / 50.0;
            let c = f.center(t);
            let ext = Vec3::new(f.radius(t), f.radius(t), f.vertical_half_extent(t));
            assert!(b.contains(&(c + ext)) && b.contains(&(c - ext)));
        }
        assert_relative_eq!(b.max.x, 3.0 + f.radius(3.0));
        assert!(matches!(
            f.aabb_over(2.0, 1.0),
            Err(PredictError::InvalidWindow { .. })
        ));
        assert!(f.aabb_over(f64::NAN, 1.0).is_err());
    }

    #[test]
    fn serde_round_trip_and_unknown_fields() {
        let f = cylinder(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.5, 0.0, 0.0), 1.5, 0.3);
        let json = serde_json::to_string(&f).unwrap();
        let back: Forecast = serde_json::from_str(&json).unwrap();
        assert_eq!(back, f);
        let extra = json.replacen('{', "{\"colour\":1,", 1);
        assert!(serde_json::from_str::<Forecast>(&extra).is_err());
    }

    proptest! {
        #[test]
        fn sphere_gradients_match_finite_differences(
            p0 in v3(2.0), v0 in v3(2.0), p in v3(4.0), dt in prop_oneof![-2.0..-0.01f64, 0.01..3.0f64],
            r_o in 0.1..1.5f64, r_safe in 0.0..0.5f64, mu in 0.0..1.0f64,
        ) {
            let f = Forecast::sphere(p0, v0, 1.0, r_o, r_safe, mu).unwrap();
            let t = 1.0 + dt;
            prop_assume!((p - f.center(t)).norm() > 1e-2);
            let (d, g, gt) = f.distance_and_gradients(&p, t);
            prop_assert!((d - f.signed_distance(&p, t)).abs() < 1e-12);
            let (fd_g, fd_t) = finite_differences(&f, &p, t);
            prop_assert!((g - fd_g).norm() < 1e-5, "grad {g:?} vs fd {fd_g:?}");
            prop_assert!((gt - fd_t).abs() < 1e-5, "d/dt {gt} vs fd {fd_t}");
        }

        #[test]
        fn cylinder_gradients_match_finite_differences(
            p0 in v3(1.0), v0 in v3(2.0), p in v3(3.0), dt in prop_oneof![-2.0..-0.01f64, 0.01..3.0f64],
            half_height in 0.1..2.0f64, mu in 0.0..1.0f64,
        ) {
            let f = cylinder(p0, v0, half_height, mu);
            let t = 1.0 + dt;
            prop_assume!(cylinder_kink_distance(&f, &p, t) > 1e-2);
            let (d, g, gt) = f.distance_and_gradients(&p, t);
            prop_assert!((d - f.signed_distance(&p, t)).abs() < 1e-12);
            let (fd_g, fd_t) = finite_differences(&f, &p, t);
            prop_assert!((g - fd_g).norm() < 1e-5, "grad {g:?} vs fd {fd_g:?}");
            prop_assert!((gt - fd_t).abs() < 1e-5, "d/dt {gt} vs fd {fd_t}");
        }

        /// Rim, side and cap regions are all reached: points placed relative to the inflated size.
        #[test]
        fn cylinder_gradients_in_each_region(
            region in 0usize..4, angle in 0.0..std::f64::consts::TAU, out_r in 0.05..1.0f64, out_z in 0.05..1.0f64,
            up in proptest::bool::ANY, dt in 0.01..2.0f64, mu in 0.0..1.0f64, v0 in v3(2.0),
        ) {
            let f = cylinder(Vec3::new(0.3, -0.2, 0.5), v0, 1.0, mu);
            let t = 1.0 + dt;
            let (r, h) = (f.radius(t), f.vertical_half_extent(t));
            let (rho, z) = match region {
                0 => (r + out_r, h + out_z),              // rim
                1 => (r + out_r, h * (0.9 - 0.8 * out_z)), // side
                2 => (r * (0.9 - 0.8 * out_r), h + out_z), // cap
                _ => (r * (1.0 - 0.9 * out_r), h * (1.0 - 0.9 * out_z)), // inside
            };
            let z = if up { z } else { -z };
            let p = f.center(t) + Vec3::new(rho * angle.cos(), rho * angle.sin(), z);
            prop_assume!(cylinder_kink_distance(&f, &p, t) > 1e-2);
            let (_, g, gt) = f.distance_and_gradients(&p, t);
            let (fd_g, fd_t) = finite_differences(&f, &p, t);
            prop_assert!((g - fd_g).norm() < 1e-5, "region {region}: grad {g:?} vs fd {fd_g:?}");
            prop_assert!((gt - fd_t).abs() < 1e-5, "region {region}: d/dt {gt} vs fd {fd_t}");
        }
    }
}

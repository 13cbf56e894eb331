//! Temporal visibility deformation (TVD, paper Sec. III-A): the spatial-temporal homotopy test of
//! TRUST-Planner's multi-branch manager.
//!
//! Two trajectories τ₁, τ₂ are equivalent iff for every sampled time `t_c` the chord
//! `τ₁(t_c) → τ₂(t_c)` misses every obstacle as it is at `t_c`: each forecast's shape centred at
//! `center(t_c)` with radius `radius(t_c)`, and the static map. Times are sampled every `dt` seconds
//! over the span where both trajectories are defined, ends included. Untimed curves (guide paths) are
//! rejected with [`PlanError::Unsupported`].

use serde::{Deserialize, Serialize};

use trust_core::scale::{self, Quantity};
use trust_core::{Curve, HomotopyChecker, PlanError, Scene, Vec3};

/// Upper bound on the number of sampled times of one comparison.
pub const MAX_SAMPLES: usize = 1_000_000;

/// The chord test of TVD at one time: `[p, q]` keeps `clearance` from every forecast obstacle as it is
/// at time `t` ([`trust_core::Forecast::segment_clear`], the predictive directional cone of a window
/// of length zero) and from the static map. A non-finite time counts as blocking.
pub fn chord_clear(scene: &Scene<'_>, p: &Vec3, q: &Vec3, t: f64, clearance: f64) -> bool {
    scene
        .forecasts
        .iter()
        .all(|f| f.segment_clear(p, q, t, clearance))
        && scene.map.segment_clear(p, q, clearance)
}

/// The sampled times of a TVD comparison: `t_lo, t_lo + dt, …` and always `t_hi`.
///
/// # Errors
/// [`PlanError::Scale`] naming `tvd.dt_s` for a step outside `[1e-9, 1e7]` s, `t_lo` / `t_hi`
/// outside the scale policy's times; [`PlanError::InvalidInput`] naming the span `t_hi − t_lo` if
/// it needs more than [`MAX_SAMPLES`] samples at this step.
pub fn sample_times(t_lo: f64, t_hi: f64, dt: f64) -> Result<Vec<f64>, PlanError> {
    crate::ranges::quantity("tvd.dt_s", dt, Quantity::PositiveDuration)?;
    crate::ranges::quantity("t_lo", t_lo, Quantity::Time)?;
    crate::ranges::quantity("t_hi", t_hi, Quantity::Time)?;
    let span = (t_hi - t_lo).max(0.0);
    check_sample_count("t_hi − t_lo", span, dt)?;
    let steps = (span / dt).floor();
    let steps = steps as usize;
    let mut times: Vec<f64> = (0..=steps).map(|k| t_lo + k as f64 * dt).collect();
    if t_lo + steps as f64 * dt < t_hi {
        times.push(t_hi);
    }
    Ok(times)
}

/// TVD equivalence of two timed curves in `scene`, sampling every `dt` seconds with clearance 0.
///
/// The compared span is where both are defined, `[max(starts), min(ends)]`; if they do not overlap the
/// single time `max(starts)` is compared (positions clamp to the curves' ends). Errors:
/// [`PlanError::Unsupported`] for an untimed curve, [`PlanError::InvalidInput`] for a bad `dt`.
pub fn equivalent(
    a: &dyn Curve,
    b: &dyn Curve,
    scene: &Scene<'_>,
    dt: f64,
) -> Result<bool, PlanError> {
    equivalent_with_clearance(a, b, scene, dt, 0.0)
}

/// [`equivalent`] with a chord clearance (m).
pub fn equivalent_with_clearance(
    a: &dyn Curve,
    b: &dyn Curve,
    scene: &Scene<'_>,
    dt: f64,
    clearance: f64,
) -> Result<bool, PlanError> {
    crate::ranges::quantity("tvd.clearance", clearance, Quantity::Length)?;
    let (Some((a0, a1)), Some((b0, b1))) = (a.time_span(), b.time_span()) else {
        return Err(PlanError::Unsupported {
            component: "tvd".into(),
            reason: "temporal visibility deformation needs timed curves (trajectories), got an \
                     untimed path; use UVD for guide paths"
                .into(),
        });
    };
    // The scene may have been built without `Scene::new` (its fields are public): check its
    // forecasts as every other component does.
    Scene::new(scene.map, scene.forecasts, scene.t0)?;
    crate::ranges::quantity("tvd.dt_s", dt, Quantity::PositiveDuration)?;
    let t_lo = a0.max(b0);
    let t_hi = a1.min(b1).max(t_lo);
    // A long common span (a long hold) needs many samples: name the curves, not the step.
    check_sample_count(
        "common time span of the two trajectories",
        (t_hi - t_lo).max(0.0),
        dt,
    )?;
    for t in sample_times(t_lo, t_hi, dt)? {
        let (Some(p), Some(q)) = (a.position_at_time(t), b.position_at_time(t)) else {
            return Ok(false);
        };
        if !chord_clear(scene, &p, &q, t, clearance) {
            return Ok(false);
        }
    }
    Ok(true)
}

/// `Ok` if a span of `span` s sampled every `dt` s needs fewer than [`MAX_SAMPLES`] samples; the
/// error names `what` (the span), with the step and the longest span it allows.
fn check_sample_count(what: &str, span: f64, dt: f64) -> Result<(), PlanError> {
    let steps = (span / dt).floor();
    if steps.is_finite() && steps < MAX_SAMPLES as f64 {
        return Ok(());
    }
    Err(PlanError::invalid(
        what,
        span,
        format!(
            "a span of at most {} s at tvd.dt_s = {} s ({MAX_SAMPLES} samples, tvd::MAX_SAMPLES); \
             compare shorter trajectories or raise tvd.dt_s",
            scale::Sci(dt * (MAX_SAMPLES - 1) as f64),
            scale::Sci(dt)
        ),
    ))
}

/// Parameters of the [`Tvd`] checker.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TvdParams {
    /// Time step between compared instants (s), accepted in `[1e-9, 1e7]` s (the scale policy's
    /// positive durations). The paper samples `t_c` without giving a step; our
    /// default 0.05 s lets an obstacle at 3 m/s (the fastest in experiment E1) move 0.15 m between
    /// checks, half of Fast-Planner's 0.3 m sampling clearance.
    pub dt_s: f64,
    /// A chord is blocked if it comes closer than this to an obstacle (m), accepted in `[0, 1e6]` m.
    /// Default 0: the paper's
    /// condition `τ₁(t_c)τ₂(t_c) ∩ O(t_c) = ∅`.
    pub clearance: f64,
}

impl Default for TvdParams {
    fn default() -> Self {
        TvdParams {
            dt_s: 0.05,
            clearance: 0.0,
        }
    }
}

impl TvdParams {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), PlanError> {
        crate::ranges::quantity("tvd.dt_s", self.dt_s, Quantity::PositiveDuration)?;
        crate::ranges::quantity("tvd.clearance", self.clearance, Quantity::Length)?;
        Ok(())
    }
}

/// Temporal visibility deformation as a [`HomotopyChecker`] (trajectories only).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Tvd {
    params: TvdParams,
}

impl Tvd {
    /// A checker with validated parameters.
    pub fn new(params: TvdParams) -> Result<Self, PlanError> {
        params.validate()?;
        Ok(Tvd { params })
    }

    /// The parameters.
    pub fn params(&self) -> &TvdParams {
        &self.params
    }
}

impl HomotopyChecker for Tvd {
    fn name(&self) -> &str {
        "tvd"
    }

    fn equivalent(
        &self,
        a: &dyn Curve,
        b: &dyn Curve,
        scene: &Scene<'_>,
    ) -> Result<bool, PlanError> {
        self.params.validate()?;
        equivalent_with_clearance(a, b, scene, self.params.dt_s, self.params.clearance)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use trust_core::{Aabb, Forecast, GuidePath, ObstacleShape, PolyTraj, StaticMap};

    fn empty_map() -> StaticMap {
        StaticMap::new(Aabb::new(Vec3::repeat(-20.0), Vec3::repeat(20.0)).unwrap()).unwrap()
    }

    /// Constant-velocity trajectory from `p` with velocity `v` over `[0, d]`.
    fn line(p: Vec3, v: Vec3, d: f64) -> PolyTraj {
        let mut c = [Vec3::zeros(); 6];
        c[0] = p;
        c[1] = v;
        PolyTraj::new(0.0, vec![d], vec![c]).unwrap()
    }

    fn ball(p0: Vec3, v0: Vec3) -> Forecast {
        Forecast {
            shape: ObstacleShape::Sphere,
            p0,
            v0,
            t0: 0.0,
            r_o: 0.5,
            r_safe: 0.0,
            mu: 0.0,
            growth_s: f64::INFINITY,
            walls: None,
        }
    }

    #[test]
    fn a_moving_obstacle_separates_only_when_it_is_between() {
        let map = empty_map();
        // Two parallel trajectories along x at y = ±2.
        let t1 = line(Vec3::new(0.0, 2.0, 0.0), Vec3::new(1.0, 0.0, 0.0), 4.0);
        let t2 = line(Vec3::new(0.0, -2.0, 0.0), Vec3::new(1.0, 0.0, 0.0), 4.0);
        // An obstacle that sits between them at x = 2 at t = 2 (moves with them): separates.
        let between = [ball(Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0))];
        let scene = Scene::new(&map, &between, 0.0).unwrap();
        assert!(!equivalent(&t1, &t2, &scene, 0.05).unwrap());
        // The same obstacle path in space, but far ahead in time (it has passed): equivalent, although
        // it crosses the region between them.
        let passed = [ball(Vec3::new(20.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0))];
        let scene = Scene::new(&map, &passed, 0.0).unwrap();
        assert!(equivalent(&t1, &t2, &scene, 0.05).unwrap());
        // A crossing obstacle that reaches the gap only after both trajectories ended.
        let late = [ball(Vec3::new(2.0, -15.0, 0.0), Vec3::new(0.0, 1.0, 0.0))];
        let scene = Scene::new(&map, &late, 0.0).unwrap();
        assert!(equivalent(&t1, &t2, &scene, 0.05).unwrap());
        assert!(Tvd::default().equivalent(&t1, &t2, &scene).unwrap());
    }

    #[test]
    fn untimed_curves_are_unsupported() {
        let map = empty_map();
        let scene = Scene::new(&map, &[], 0.0).unwrap();
        let p = GuidePath::new(vec![Vec3::zeros(), Vec3::x()]).unwrap();
        let t = line(Vec3::zeros(), Vec3::x(), 1.0);
        let e = Tvd::default().equivalent(&p, &t, &scene).unwrap_err();
        assert!(matches!(e, PlanError::Unsupported { .. }), "{e}");
    }

    #[test]
    fn bad_steps_are_rejected_and_times_include_the_end() {
        assert!(sample_times(0.0, 1.0, 0.0).is_err());
        assert!(sample_times(0.0, 1.0, f64::NAN).is_err());
        assert!(sample_times(0.0, 1e9, 1e-6).is_err());
        let t = sample_times(0.0, 1.05, 0.5).unwrap();
        assert_eq!(t, vec![0.0, 0.5, 1.0, 1.05]);
        assert_eq!(sample_times(2.0, 2.0, 0.1).unwrap(), vec![2.0]);
        assert!(
            Tvd::new(TvdParams {
                dt_s: -1.0,
                ..TvdParams::default()
            })
            .is_err()
        );
    }

    #[test]
    fn disjoint_spans_compare_one_instant() {
        let map = empty_map();
        let scene = Scene::new(&map, &[], 0.0).unwrap();
        let a = line(Vec3::zeros(), Vec3::x(), 1.0);
        let b = line(Vec3::zeros(), Vec3::x(), 1.0)
            .with_start_time(5.0)
            .unwrap();
        assert!(equivalent(&a, &b, &scene, 0.1).unwrap());
    }
}

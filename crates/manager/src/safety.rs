//! The safety check every branch passes each cycle: the trajectory against the static map, the map
//! bounds and the *current* forecasts, continuously in time, plus the dynamic limits.
//!
//! Instead of sampling at a fixed step, the check steps by a **proven** amount: at a checked
//! instant with clearance `c` from everything, no obstacle can be reached before `c / R`, where `R`
//! bounds how fast the clearance can shrink — the vehicle's speed (a bound from the Bézier control
//! points of the velocity) times the static distance's Lipschitz constant (1 for analytic shapes,
//! √3 for the trilinear ESDF), or the vehicle's speed plus an obstacle's forecast speed and radius
//! growth. A trajectory that passes is therefore collision-free at *every* instant of the window,
//! not only at the samples (up to the `min_step_s` floor near contact, where it samples densely).
//!
//! A trajectory that ends moving is also checked for what comes after it: braking straight along
//! its final velocity ([`crate::braking_tail`], at 0.9·`a_max`) must stay clear ([`SafetyParams::braking_tail`]). A free-terminal
//! trajectory can otherwise end at full speed just in front of an obstacle, and a vehicle whose
//! replanning then fails has nowhere to go.

use serde::{Deserialize, Serialize};
use trust_core::{Aabb, Forecast, Limits, Piece, PolyTraj, Scene, State, Vec3, bernstein_points};

use crate::SafetyParams;
use crate::brake::braking_tail;

/// What the clearance was violated against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Hit {
    /// The static map.
    Static,
    /// The forecast with this index in the scene.
    Obstacle(usize),
    /// The map bounds.
    Bounds,
}

/// The first violation of a checked trajectory.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Violation {
    /// Absolute time (s).
    pub t: f64,
    /// What was hit.
    pub with: Hit,
    /// Clearance there minus the required clearance (m, negative).
    pub margin_m: f64,
}

/// Result of [`check_trajectory`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SafetyVerdict {
    /// No violation in the window and within the limits' tolerance.
    pub safe: bool,
    /// Smallest static clearance minus the required one over the checked instants (m; `+∞` for an
    /// empty map), and minus how far the vehicle's centre leaves the bounds (shrunk by the static
    /// clearance) where it does.
    pub min_static_margin_m: f64,
    /// Smallest dynamic clearance minus the required one (m; `+∞` without nearby forecasts).
    pub min_dynamic_margin_m: f64,
    /// The first violation, if any.
    pub violation: Option<Violation>,
    /// The trajectory started inside an obstacle's margin and was accepted because its clearance
    /// never decreased until it was out (a branch escaping from a forecast that grew over it).
    pub escaping: bool,
    /// Largest speed and acceleration norm (sampled, 16 per piece).
    pub max_speed: f64,
    /// See `max_speed`.
    pub max_accel: f64,
    /// Speed or acceleration above the limits by more than the tolerance.
    pub over_limits: bool,
    /// The trajectory itself was clear but what follows its end would not be: stopping
    /// (straight braking, [`crate::braking_tail`], at 0.9·`a_max`;
    /// [`SafetyParams::braking_tail`]) or then staying at rest for
    /// [`SafetyParams::rest_hold_s`].
    pub braking_tail_violated: bool,
    /// Instants checked.
    pub sample_count: usize,
}

impl SafetyVerdict {
    /// The smaller of the two margins.
    pub fn min_margin_m(&self) -> f64 {
        self.min_static_margin_m.min(self.min_dynamic_margin_m)
    }
}

/// An upper bound of the speed of one piece of duration `duration`: the largest norm of its
/// velocity's Bernstein control points ([`bernstein_points`]).
pub(crate) fn piece_speed_bound(piece: &Piece, duration: f64) -> f64 {
    let mut b = [Vec3::zeros(); 5];
    let mut tk = 1.0;
    for (k, bk) in b.iter_mut().enumerate() {
        *bk = piece[k + 1] * ((k + 1) as f64 * tk);
        tk *= duration;
    }
    bernstein_points(&b)
        .iter()
        .map(|p| p.norm())
        .fold(0.0, f64::max)
}

/// A box containing one piece of duration `duration`: the box of its position's Bernstein
/// control points ([`bernstein_points`]).
pub(crate) fn piece_box(piece: &Piece, duration: f64) -> Aabb {
    let mut b = [Vec3::zeros(); 6];
    let mut tk = 1.0;
    for (k, bk) in b.iter_mut().enumerate() {
        *bk = piece[k] * tk;
        tk *= duration;
    }
    Aabb::from_points(&bernstein_points(&b)).unwrap_or(Aabb {
        min: piece[0],
        max: piece[0],
    })
}

/// Speed bound and bounding box of the part of `traj` that overlaps `[from, until]` (whole pieces).
pub(crate) fn window_bounds(traj: &PolyTraj, from: f64, until: f64) -> (f64, Aabb) {
    let mut speed: f64 = 0.0;
    let mut bbox: Option<Aabb> = None;
    let mut t0 = traj.t_start();
    for (piece, &d) in traj.pieces().iter().zip(traj.durations()) {
        let t1 = t0 + d;
        if t1 >= from && t0 <= until {
            speed = speed.max(piece_speed_bound(piece, d));
            let b = piece_box(piece, d);
            bbox = Some(bbox.map_or(b, |x| x.union(&b)));
        }
        t0 = t1;
    }
    // Outside the trajectory's span the position holds at an end.
    let hold = if from < traj.t_start() || until > traj.t_end() {
        let a = traj.position(traj.t_start());
        let b = traj.position(traj.t_end());
        Some(Aabb::from_points(&[a, b]).unwrap_or(Aabb { min: a, max: a }))
    } else {
        None
    };
    let bbox = match (bbox, hold) {
        (Some(x), Some(h)) => x.union(&h),
        (Some(x), None) => x,
        (None, Some(h)) => h,
        (None, None) => {
            let p = traj.position(from);
            Aabb { min: p, max: p }
        }
    };
    (speed, bbox)
}

/// Indices of the forecasts of `scene` that can come within `margin` of `region` at some time of
/// `[from, until]` (their swept boxes, [`trust_core::Forecast::aabb_over`]). A forecast whose swept
/// box cannot be computed (a non-finite window) counts as near. The safety check and the
/// manager's homotopy checks both filter the scene with it.
pub(crate) fn forecasts_near(
    scene: &Scene<'_>,
    region: &Aabb,
    from: f64,
    until: f64,
    margin: f64,
    out: &mut Vec<usize>,
) {
    out.clear();
    let region = region.inflated(margin);
    for (i, f) in scene.forecasts.iter().enumerate() {
        let near = f
            .aabb_over(from, until.max(from))
            .map_or(true, |b| b.intersects(&region));
        if near {
            out.push(i);
        }
    }
}

/// Checks `traj` over `[from, until]` against `scene` (static map, bounds, forecasts) with the
/// clearances of `params`, and its speed and acceleration against `limits`.
///
/// Never panics and never loops unboundedly: at most `⌈(until − from)/min_step_s⌉ + 2` instants
/// are checked; a non-finite window checks the single instant `from` (or the start).
pub fn check_trajectory(
    traj: &PolyTraj,
    scene: &Scene<'_>,
    from: f64,
    until: f64,
    limits: &Limits,
    params: &SafetyParams,
) -> SafetyVerdict {
    check(traj, scene, from, until, limits, params, false)
}

/// [`check_trajectory`] that does not stop at the first violation: the margins are the minima over
/// the whole window (with the same proven steps where the trajectory is clear and `min_step_s`
/// where it is not), so that colliding trajectories can be compared by how deep they go. The
/// braking fallback uses it to choose among imperfect options.
pub fn assess_trajectory(
    traj: &PolyTraj,
    scene: &Scene<'_>,
    from: f64,
    until: f64,
    limits: &Limits,
    params: &SafetyParams,
) -> SafetyVerdict {
    check(traj, scene, from, until, limits, params, true)
}

/// A trajectory ending slower than this fraction of `v_max` ends in a resting place (the rest
/// hold, [`SafetyParams::rest_hold_s`]).
const REST_SPEED_FRACTION: f64 = 0.1;

fn check(
    traj: &PolyTraj,
    scene: &Scene<'_>,
    from: f64,
    until: f64,
    limits: &Limits,
    params: &SafetyParams,
    full: bool,
) -> SafetyVerdict {
    let mut verdict = check_window(traj, scene, from, until, limits, params, full);
    if until < traj.t_end() {
        return verdict;
    }
    let mut tail_params = params.clone();
    tail_params.limit_tolerance = f64::INFINITY;
    let merge = |verdict: &mut SafetyVerdict, t: SafetyVerdict| {
        verdict.sample_count += t.sample_count;
        verdict.min_static_margin_m = verdict.min_static_margin_m.min(t.min_static_margin_m);
        verdict.min_dynamic_margin_m = verdict.min_dynamic_margin_m.min(t.min_dynamic_margin_m);
        if verdict.violation.is_none() && t.violation.is_some() {
            verdict.violation = t.violation;
            verdict.safe = false;
            verdict.braking_tail_violated = true;
        }
    };
    // The braking tail: a trajectory that ends moving must leave room to stop after its end
    // (against the growing forecasts).
    let mut rest = traj.state(traj.t_end());
    let end_speed = rest.v.norm();
    if end_speed > 1e-6 {
        if !params.braking_tail {
            return verdict;
        }
        if (verdict.violation.is_none() || full)
            && let Ok(tail) = braking_tail(&rest, limits.a_max, params.min_step_s)
        {
            let t = check_window(
                &tail,
                scene,
                tail.t_start(),
                tail.t_end(),
                limits,
                &tail_params,
                full,
            );
            merge(&mut verdict, t);
            rest = State::at_rest(tail.t_end(), tail.position(tail.t_end()));
        } else {
            return verdict;
        }
    }
    // The rest hold: a trajectory that ends slowly (below a tenth of `v_max`) ends in a resting
    // place, and where the vehicle comes to rest (the end, or where the braking tail stops) it
    // must stay clear for `rest_hold_s` of the forecasts' motion, their growth held after
    // `rest_hold_s` (grown on, they swallow every resting place near a path, and the next
    // cycles replan anyway). A plan that slowed to rest on an oncoming obstacle's line just
    // outside its forecast passed without it, and the obstacle arrived half a second later.
    // Faster ends are in transit: the next cycles replan them long before they are reached
    // (held after those too, the rooms with people timed out in 21 of 120 flights).
    if params.rest_hold_s > 0.0
        && end_speed <= REST_SPEED_FRACTION * limits.v_max
        && (verdict.violation.is_none() || full)
        && let Ok(hold) = braking_tail(&rest, limits.a_max, params.rest_hold_s)
    {
        let held: Vec<Forecast> = scene
            .forecasts
            .iter()
            .map(|f| f.growth_held_after((rest.t - f.t0).min(params.rest_hold_s)))
            .collect();
        let frozen = Scene {
            forecasts: &held,
            ..*scene
        };
        let t = check_window(
            &hold,
            &frozen,
            hold.t_start(),
            hold.t_end(),
            limits,
            &tail_params,
            full,
        );
        merge(&mut verdict, t);
    }
    verdict
}

/// The window one check covers: its time span (non-finite ends replaced), the forecasts that can
/// reach the trajectory in it, and how fast each clearance can shrink there.
struct Window {
    from: f64,
    until: f64,
    /// Indices of the forecasts near the trajectory ([`forecasts_near`]).
    near: Vec<usize>,
    /// Bound of the static clearance's rate of decrease (m/s).
    static_rate: f64,
    /// Bound of the dynamic clearance's rate of decrease (m/s).
    dynamic_rate: f64,
}

impl Window {
    fn new(
        traj: &PolyTraj,
        scene: &Scene<'_>,
        from: f64,
        until: f64,
        params: &SafetyParams,
    ) -> Self {
        let from = if from.is_finite() {
            from
        } else {
            traj.t_start()
        };
        let until = if until.is_finite() {
            until.max(from)
        } else {
            from
        };
        let (speed_bound, bbox) = window_bounds(traj, from, until);
        let mut near = Vec::new();
        forecasts_near(
            scene,
            &bbox,
            from,
            until,
            params.dynamic_clearance_m,
            &mut near,
        );
        let obstacle_rate = near
            .iter()
            .map(|&i| {
                let f = &scene.forecasts[i];
                f.v0.norm() + f.mu
            })
            .fold(0.0, f64::max);
        let lipschitz = if scene.map.esdf().is_some() {
            3f64.sqrt()
        } else {
            1.0
        };
        Window {
            from,
            until,
            near,
            static_rate: lipschitz * speed_bound,
            dynamic_rate: speed_bound + obstacle_rate,
        }
    }

    /// The static and dynamic margins (m) at `p` and time `t`, and the nearest forecast.
    fn margins(&self, scene: &Scene<'_>, p: &Vec3, t: f64, params: &SafetyParams) -> Margins {
        let static_m = scene.map.signed_distance(p) - params.static_clearance_m;
        let (mut dynamic_m, mut nearest) = (f64::INFINITY, 0);
        for &i in &self.near {
            let d = scene.forecasts[i].signed_distance(p, t) - params.dynamic_clearance_m;
            if d < dynamic_m {
                dynamic_m = d;
                nearest = i;
            }
        }
        Margins {
            static_m,
            dynamic_m,
            nearest,
        }
    }

    /// The next instant after `t`: the proven step `margin / rate` where the trajectory is clear,
    /// the small step where it is not (or may still be escaping an initial overlap), clamped to
    /// `[min_step_s, max_step_s]` and to the window's end.
    fn next(&self, t: f64, m: &Margins, inside: bool, params: &SafetyParams) -> f64 {
        let violating = m.static_m.min(m.dynamic_m) < 0.0;
        let proven = if inside || violating {
            params.min_step_s.max(0.01f64.min(params.max_step_s))
        } else {
            let s = m.static_m / self.static_rate.max(1e-12);
            let d = m.dynamic_m / self.dynamic_rate.max(1e-12);
            s.min(d)
        };
        let step = proven.clamp(params.min_step_s, params.max_step_s);
        (t + step).min(self.until)
    }
}

/// Clearance margins at one instant.
struct Margins {
    /// To the static map (m, negative inside).
    static_m: f64,
    /// To the nearest forecast (m, negative inside; `∞` without forecasts).
    dynamic_m: f64,
    /// Index of the nearest forecast.
    nearest: usize,
}

impl Margins {
    /// What the vehicle at `p` hits, with the margin: the bounds, else the nearer of the static
    /// map and the forecasts when a margin is negative (or NaN).
    fn hit(&self, bounds: &Aabb, p: &Vec3) -> Option<(Hit, f64)> {
        let margin = self.static_m.min(self.dynamic_m);
        if !bounds.contains(p) {
            Some((Hit::Bounds, -bounds.distance_to_point(p)))
        } else if margin < 0.0 || margin.is_nan() {
            let with = if self.static_m <= self.dynamic_m {
                Hit::Static
            } else {
                Hit::Obstacle(self.nearest)
            };
            Some((with, margin))
        } else {
            None
        }
    }
}

/// `bounds` shrunk by `by` on every side, to the mid-plane on an axis thinner than `2·by`.
fn shrunk(bounds: &Aabb, by: f64) -> Aabb {
    let mut out = *bounds;
    for a in 0..3 {
        let d = by.min(0.5 * (bounds.max[a] - bounds.min[a])).max(0.0);
        out.min[a] += d;
        out.max[a] -= d;
    }
    out
}

fn check_window(
    traj: &PolyTraj,
    scene: &Scene<'_>,
    from: f64,
    until: f64,
    limits: &Limits,
    params: &SafetyParams,
    full: bool,
) -> SafetyVerdict {
    let window = Window::new(traj, scene, from, until, params);
    // The vehicle's body stays inside the bounds (a room's walls): its centre within the bounds
    // shrunk by the static clearance (to their mid-plane where they are thinner than that).
    let bounds = &shrunk(scene.map.bounds(), params.static_clearance_m);
    let (max_speed, max_accel) = traj.max_speed_and_acceleration(16);
    let tol = 1.0 + params.limit_tolerance;
    let over_limits = max_speed > limits.v_max * tol || max_accel > limits.a_max * tol;
    let mut verdict = SafetyVerdict {
        safe: true,
        min_static_margin_m: f64::INFINITY,
        min_dynamic_margin_m: f64::INFINITY,
        violation: None,
        escaping: false,
        max_speed,
        max_accel,
        over_limits,
        braking_tail_violated: false,
        sample_count: 0,
    };
    let (from, until) = (window.from, window.until);
    let max_samples = ((until - from) / params.min_step_s).ceil().min(1e7) as usize + 2;
    let mut t = from;
    let mut previous = f64::NEG_INFINITY;
    let mut inside = true; // until the first clear instant, an initial overlap may be escaped
    for _ in 0..max_samples {
        verdict.sample_count += 1;
        let p = traj.position(t);
        let m = window.margins(scene, &p, t, params);
        verdict.min_static_margin_m = verdict.min_static_margin_m.min(m.static_m);
        if !bounds.contains(&p) {
            verdict.min_static_margin_m = verdict
                .min_static_margin_m
                .min(-bounds.distance_to_point(&p));
        }
        verdict.min_dynamic_margin_m = verdict.min_dynamic_margin_m.min(m.dynamic_m);
        match m.hit(bounds, &p) {
            Some((with, margin)) => {
                // Escaping an overlap present at the start: allowed while the clearance grows.
                let escaping = inside && margin >= previous - 1e-9;
                if !escaping {
                    verdict.safe = false;
                    if verdict.violation.is_none() {
                        verdict.violation = Some(Violation {
                            t,
                            with,
                            margin_m: if margin.is_nan() {
                                f64::NEG_INFINITY
                            } else {
                                margin
                            },
                        });
                    }
                    if !full {
                        break;
                    }
                    inside = false;
                } else {
                    verdict.escaping = true;
                }
                previous = margin;
            }
            None => inside = false,
        }
        if t >= until {
            break;
        }
        t = window.next(t, &m, inside, params);
    }
    if over_limits {
        verdict.safe = false;
    }
    verdict
}

#[cfg(test)]
mod tests {
    use super::*;
    use trust_core::{Forecast, ObstacleShape, StaticMap, eval_piece};
    use trust_geometry::{Shape, Sphere};

    fn line(t0: f64, from: Vec3, velocity: Vec3, duration: f64) -> PolyTraj {
        let mut piece = [Vec3::zeros(); 6];
        piece[0] = from;
        piece[1] = velocity;
        PolyTraj::new(t0, vec![duration], vec![piece]).unwrap()
    }

    fn map(shapes: Vec<Shape>) -> StaticMap {
        let b = Aabb::new(Vec3::new(-50.0, -50.0, -10.0), Vec3::new(50.0, 50.0, 10.0)).unwrap();
        StaticMap::from_shapes(b, shapes).unwrap()
    }

    #[test]
    fn bernstein_bounds_contain_the_curve() {
        let piece: Piece = [
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(-3.0, 1.0, 0.5),
            Vec3::new(2.0, -1.0, 0.0),
            Vec3::new(0.5, 0.2, -1.0),
            Vec3::new(-0.3, 0.1, 0.2),
        ];
        let d = 1.7;
        let vmax = piece_speed_bound(&piece, d);
        let bbox = piece_box(&piece, d);
        for k in 0..=200 {
            let s = d * k as f64 / 200.0;
            assert!(eval_piece(&piece, 1, s).norm() <= vmax + 1e-12);
            let p = eval_piece(&piece, 0, s);
            assert!(bbox.inflated(1e-12).contains(&p), "{p:?} not in {bbox:?}");
        }
        // The end control points are the curve's ends.
        assert!((bbox.min.x - 1.0).abs() < 10.0);
    }

    #[test]
    fn a_clear_line_passes_with_few_samples() {
        let m = map(vec![]);
        let scene = Scene::new(&m, &[], 0.0).unwrap();
        let traj = line(0.0, Vec3::zeros(), Vec3::new(5.0, 0.0, 0.0), 4.0);
        let no_tail = SafetyParams {
            braking_tail: false,
            ..SafetyParams::default()
        };
        let v = check_trajectory(&traj, &scene, 0.0, 4.0, &Limits::default(), &no_tail);
        assert!(v.safe && v.violation.is_none());
        assert!(v.sample_count <= 4.0f64.div_euclid(0.05) as usize + 2);
    }

    #[test]
    fn a_stop_that_an_obstacle_reaches_soon_after_the_end_is_unsafe() {
        // At rest at the origin for 2 s; a ball walking at it reaches it at t = 2.25 s, within
        // the default 0.5 s rest hold and after the trajectory's end.
        let m = map(vec![]);
        let ball = Forecast::new(
            ObstacleShape::Sphere,
            Vec3::new(0.0, 5.0, 0.0),
            Vec3::new(0.0, -2.0, 0.0),
            0.0,
            0.5,
            0.0,
            0.0,
        )
        .unwrap();
        let forecasts = [ball];
        let scene = Scene::new(&m, &forecasts, 0.0).unwrap();
        let z = Vec3::zeros();
        let rest = PolyTraj::new(0.0, vec![2.0], vec![[z, z, z, z, z, z]]).unwrap();
        let v = check_trajectory(
            &rest,
            &scene,
            0.0,
            2.0,
            &Limits::default(),
            &SafetyParams::default(),
        );
        assert!(!v.safe && v.braking_tail_violated, "{v:?}");
        assert!(v.violation.unwrap().t > 2.0);
        let no_hold = SafetyParams {
            rest_hold_s: 0.0,
            ..SafetyParams::default()
        };
        assert!(check_trajectory(&rest, &scene, 0.0, 2.0, &Limits::default(), &no_hold).safe);
        // A 0.2 s hold ends before it arrives.
        let short = SafetyParams {
            rest_hold_s: 0.2,
            ..SafetyParams::default()
        };
        assert!(check_trajectory(&rest, &scene, 0.0, 2.0, &Limits::default(), &short).safe);
    }

    #[test]
    fn a_trajectory_that_cannot_stop_after_its_end_is_unsafe() {
        // Ends at 5 m/s, 0.5 m in front of a sphere: braking needs 5²/(2·15) = 0.83 m.
        let sphere = Shape::Sphere(Sphere::new(Vec3::new(11.5, 0.0, 0.0), 1.0).unwrap());
        let m = map(vec![sphere]);
        let scene = Scene::new(&m, &[], 0.0).unwrap();
        let traj = line(0.0, Vec3::zeros(), Vec3::new(5.0, 0.0, 0.0), 2.0);
        let v = check_trajectory(
            &traj,
            &scene,
            0.0,
            2.0,
            &Limits::default(),
            &SafetyParams::default(),
        );
        assert!(!v.safe && v.braking_tail_violated, "{v:?}");
        assert!(v.violation.unwrap().t > 2.0);
        let no_tail = SafetyParams {
            braking_tail: false,
            ..SafetyParams::default()
        };
        let v = check_trajectory(&traj, &scene, 0.0, 2.0, &Limits::default(), &no_tail);
        assert!(v.safe, "{v:?}");
        // 2 m in front it can stop.
        let traj = line(0.0, Vec3::zeros(), Vec3::new(5.0, 0.0, 0.0), 1.7);
        let v = check_trajectory(
            &traj,
            &scene,
            0.0,
            1.7,
            &Limits::default(),
            &SafetyParams::default(),
        );
        assert!(v.safe, "{v:?}");
    }

    #[test]
    fn a_static_hit_between_fixed_samples_is_found() {
        // A thin sphere crossed for 0.004 s at 5 m/s: a 0.05 s grid can miss it, the proven step
        // cannot.
        let sphere = Shape::Sphere(Sphere::new(Vec3::new(10.0, 0.05, 0.0), 0.06).unwrap());
        let m = map(vec![sphere]);
        let scene = Scene::new(&m, &[], 0.0).unwrap();
        let traj = line(0.0, Vec3::new(0.0, 0.0, 0.0), Vec3::new(5.0, 0.0, 0.0), 4.0);
        let v = check_trajectory(
            &traj,
            &scene,
            0.0,
            4.0,
            &Limits::default(),
            &SafetyParams::default(),
        );
        assert!(!v.safe);
        let hit = v.violation.unwrap();
        assert_eq!(hit.with, Hit::Static);
        assert!((hit.t - 2.0).abs() < 0.02, "{hit:?}");
    }

    #[test]
    fn a_moving_obstacle_crossing_the_path_is_found_and_named() {
        let m = map(vec![]);
        let f0 = Forecast::new(
            ObstacleShape::Sphere,
            Vec3::new(30.0, 30.0, 0.0),
            Vec3::zeros(),
            0.0,
            0.5,
            0.0,
            0.0,
        )
        .unwrap();
        // Crosses y = 0 at x = 10 at t = 2, when the vehicle is there.
        let f1 = Forecast::new(
            ObstacleShape::Sphere,
            Vec3::new(10.0, -6.0, 0.0),
            Vec3::new(0.0, 3.0, 0.0),
            0.0,
            0.5,
            0.3,
            0.1,
        )
        .unwrap();
        let forecasts = [f0, f1];
        let scene = Scene::new(&m, &forecasts, 0.0).unwrap();
        let traj = line(0.0, Vec3::zeros(), Vec3::new(5.0, 0.0, 0.0), 4.0);
        let v = check_trajectory(
            &traj,
            &scene,
            0.0,
            4.0,
            &Limits::default(),
            &SafetyParams::default(),
        );
        let hit = v.violation.expect("collides");
        assert_eq!(hit.with, Hit::Obstacle(1));
        assert!(hit.t > 1.5 && hit.t < 2.1, "{hit:?}");
        // The same obstacle a second later is missed: safe.
        let late = Forecast {
            p0: Vec3::new(10.0, -9.0, 0.0),
            ..forecasts[1]
        };
        let forecasts = [f0, late];
        let scene = Scene::new(&m, &forecasts, 0.0).unwrap();
        let v = check_trajectory(
            &traj,
            &scene,
            0.0,
            4.0,
            &Limits::default(),
            &SafetyParams::default(),
        );
        assert!(v.safe, "{v:?}");
    }

    #[test]
    fn escaping_an_initial_overlap_is_allowed_entering_one_is_not() {
        let m = map(vec![]);
        let f = Forecast::new(
            ObstacleShape::Sphere,
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::zeros(),
            0.0,
            1.0,
            0.0,
            0.0,
        )
        .unwrap();
        let forecasts = [f];
        let scene = Scene::new(&m, &forecasts, 0.0).unwrap();
        let away = line(0.0, Vec3::zeros(), Vec3::new(-3.0, 0.0, 0.0), 2.0);
        let v = check_trajectory(
            &away,
            &scene,
            0.0,
            2.0,
            &Limits::default(),
            &SafetyParams::default(),
        );
        assert!(v.safe && v.escaping, "{v:?}");
        let through = line(0.0, Vec3::zeros(), Vec3::new(3.0, 0.0, 0.0), 2.0);
        let v = check_trajectory(
            &through,
            &scene,
            0.0,
            2.0,
            &Limits::default(),
            &SafetyParams::default(),
        );
        assert!(!v.safe);
    }

    #[test]
    fn limits_and_bounds_are_checked() {
        let m = map(vec![]);
        let scene = Scene::new(&m, &[], 0.0).unwrap();
        let fast = line(0.0, Vec3::zeros(), Vec3::new(20.0, 0.0, 0.0), 1.0);
        let v = check_trajectory(
            &fast,
            &scene,
            0.0,
            1.0,
            &Limits::default(),
            &SafetyParams::default(),
        );
        assert!(!v.safe && v.over_limits && v.violation.is_none());
        let out = line(
            0.0,
            Vec3::new(45.0, 0.0, 0.0),
            Vec3::new(9.0, 0.0, 0.0),
            2.0,
        );
        let v = check_trajectory(
            &out,
            &scene,
            0.0,
            2.0,
            &Limits::default(),
            &SafetyParams::default(),
        );
        assert_eq!(v.violation.unwrap().with, Hit::Bounds);
    }

    #[test]
    fn degenerate_windows_do_not_loop() {
        let m = map(vec![]);
        let scene = Scene::new(&m, &[], 0.0).unwrap();
        let traj = line(0.0, Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0), 1.0);
        for (a, b) in [
            (f64::NAN, 1.0),
            (0.0, f64::INFINITY),
            (1.0, 0.0),
            (0.5, 0.5),
        ] {
            let v = check_trajectory(
                &traj,
                &scene,
                a,
                b,
                &Limits::default(),
                &SafetyParams::default(),
            );
            assert!(v.sample_count <= 1002, "{v:?}");
        }
    }
}

//! Post-solve verification: what a returned trajectory does that the request did not ask for.
//!
//! A backend minimizes soft penalties, so a trajectory it returns with `Ok` may still touch an
//! obstacle, leave the map or exceed a limit (a stalled solve, a budget that ran out, a warm start
//! far from anything feasible, extreme but accepted weights). [`verify_trajectory`] checks the
//! trajectory densely against the scene and the limits, and every [`crate::Solution`] carries its
//! result in [`crate::Solution::violations`]: an `Ok` never hides a violation.

use serde::{Deserialize, Serialize};
use trust_geometry::scale::Sci;

use crate::{Limits, Piece, PolyTraj, Scene, Vec3};

/// Largest spacing (s) between the instants [`verify_trajectory`] checks: 1 cm at 0.5 m/s,
/// 20 cm at the paper's 10 m/s (a penetration shorter than that can be missed by up to 10 cm of
/// depth; the manager's safety check proves its own steps).
pub const VERIFY_STEP_S: f64 = 0.02;

/// Most instants [`verify_trajectory`] checks on one trajectory (the step grows beyond
/// [`VERIFY_STEP_S`] for trajectories longer than `VERIFY_MAX_SAMPLES · VERIFY_STEP_S` = 82 s,
/// plus one instant per piece end).
pub const VERIFY_MAX_SAMPLES: usize = 4096;

/// Position, velocity and acceleration of a quintic piece at local time `s`, in one Horner pass.
#[inline]
fn position_velocity_acceleration(c: &Piece, s: f64) -> [Vec3; 3] {
    let mut p = c[5];
    let mut v = c[5] * 5.0;
    let mut a = c[5] * 20.0;
    for k in (0..5).rev() {
        p = p * s + c[k];
        if k >= 1 {
            v = v * s + c[k] * k as f64;
        }
        if k >= 2 {
            a = a * s + c[k] * (k * (k - 1)) as f64;
        }
    }
    [p, v, a]
}

/// Bound on the slope of [`crate::StaticMap::signed_distance`]: 1 for analytic shapes, `2√3`
/// for the trilinear interpolant of a voxel ESDF (the bound `trust_geometry` uses for its own
/// sphere tracing).
const MAP_SLOPE_BOUND: f64 = 2.0 * 1.732_050_807_568_877_3;

/// One way in which a returned trajectory violates what its request asked for. Each variant
/// reports the worst checked instant of its kind (per forecast for moving obstacles, per axis
/// for the bounds): how much, where and when.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Violation {
    /// The trajectory enters the static map (signed distance `< 0`; the clearance a backend keeps
    /// on top of that is a soft target and not reported).
    StaticPenetration {
        /// Depth of the deepest checked point (m, `> 0`).
        depth_m: f64,
        /// Its absolute time (s).
        t: f64,
        /// The point.
        point: [f64; 3],
    },
    /// The trajectory enters a moving obstacle as forecast (the forecast's avoidance radius
    /// `r_o + r_safe + μ·(t − t0)`; the backend's extra dynamic clearance is not counted).
    DynamicPenetration {
        /// Index of the forecast in [`Scene::forecasts`].
        forecast: usize,
        /// Depth of the deepest checked point (m, `> 0`).
        depth_m: f64,
        /// Its absolute time (s).
        t: f64,
        /// The point.
        point: [f64; 3],
    },
    /// The trajectory leaves the map bounds along one axis.
    LeavesBounds {
        /// `'x'`, `'y'` or `'z'`.
        axis: char,
        /// How far outside the bounds the farthest checked point lies (m, `> 0`).
        by_m: f64,
        /// Its absolute time (s).
        t: f64,
    },
    /// The speed exceeds [`Limits::v_max`].
    OverSpeed {
        /// The largest checked speed (m/s).
        v: f64,
        /// The limit (m/s).
        v_max: f64,
        /// Its absolute time (s).
        t: f64,
    },
    /// The acceleration norm exceeds [`Limits::a_max`].
    OverAccel {
        /// The largest checked acceleration norm (m/s²).
        a: f64,
        /// The limit (m/s²).
        a_max: f64,
        /// Its absolute time (s).
        t: f64,
    },
}

impl std::fmt::Display for Violation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Violation::StaticPenetration { depth_m, t, point } => write!(
                f,
                "enters the static map {} m deep at t = {} s, point ({}, {}, {})",
                Sci(depth_m),
                Sci(t),
                Sci(point[0]),
                Sci(point[1]),
                Sci(point[2])
            ),
            Violation::DynamicPenetration {
                forecast,
                depth_m,
                t,
                point,
            } => write!(
                f,
                "enters scene.forecasts[{forecast}] {} m deep at t = {} s, point ({}, {}, {})",
                Sci(depth_m),
                Sci(t),
                Sci(point[0]),
                Sci(point[1]),
                Sci(point[2])
            ),
            Violation::LeavesBounds { axis, by_m, t } => write!(
                f,
                "leaves the map bounds along {axis} by {} m at t = {} s",
                Sci(by_m),
                Sci(t)
            ),
            Violation::OverSpeed { v, v_max, t } => write!(
                f,
                "speed {} m/s exceeds limits.v_max = {} m/s at t = {} s",
                Sci(v),
                Sci(v_max),
                Sci(t)
            ),
            Violation::OverAccel { a, a_max, t } => write!(
                f,
                "acceleration {} m/s² exceeds limits.a_max = {} m/s² at t = {} s",
                Sci(a),
                Sci(a_max),
                Sci(t)
            ),
        }
    }
}

/// Checks `traj` densely against `scene` and `limits` and returns every kind of violation found
/// (empty when none), in a fixed order: static penetration, moving obstacles by index, bounds by
/// axis, speed, acceleration.
///
/// The instants checked are every piece's start and end plus a uniform grid inside each piece
/// with spacing at most [`VERIFY_STEP_S`] (coarser only for trajectories above 82 s, so that at
/// most about [`VERIFY_MAX_SAMPLES`] instants are checked). A violation shorter than the spacing
/// can fall between two instants; its depth is then at most about `v · spacing / 2`. A
/// violation is any strictly positive amount: depth `> 0`, speed `> v_max`, acceleration
/// `> a_max`, a coordinate outside the bounds.
pub fn verify_trajectory(traj: &PolyTraj, scene: &Scene<'_>, limits: &Limits) -> Vec<Violation> {
    let step = VERIFY_STEP_S.max(traj.duration() / VERIFY_MAX_SAMPLES as f64);
    let bounds = scene.map.bounds();
    let mut worst_static: Option<(f64, f64, [f64; 3])> = None;
    let mut worst_dynamic: Vec<Option<(f64, f64, [f64; 3])>> = vec![None; scene.forecasts.len()];
    let mut worst_bounds: [Option<(f64, f64)>; 3] = [None; 3];
    let mut worst_speed: Option<(f64, f64)> = None;
    let mut worst_accel: Option<(f64, f64)> = None;
    let keep = |slot: &mut Option<(f64, f64)>, amount: f64, t: f64| {
        if slot.is_none_or(|(a, _)| amount > a) {
            *slot = Some((amount, t));
        }
    };
    // Distance queries are skipped where they cannot find a penetration: after a query found
    // distance `d > 0` at `p`, a point `q` is outside the static map while `L·|q − p| < d`
    // (`L` bounds the map's distance slope), and outside forecast `o` while
    // `|q − p| + (|v0| + μ)·Δt < d` (centre speed plus growth rate). Exact, and it saves most
    // queries on a trajectory that keeps clear.
    let mut last_static: Option<(Vec3, f64)> = None;
    let mut last_dynamic: Vec<Option<(Vec3, f64, f64)>> = vec![None; scene.forecasts.len()];
    let mut t_piece = traj.t_start();
    for (piece, &d) in traj.pieces().iter().zip(traj.durations()) {
        // Saturating: `d / step` is at most 1e7 / 1e-2 here, far below usize::MAX.
        let m = ((d / step).ceil() as usize).clamp(1, VERIFY_MAX_SAMPLES);
        for j in 0..=m {
            let s = d * j as f64 / m as f64;
            let t = t_piece + s;
            let [p, vel, acc] = position_velocity_acceleration(piece, s);
            let point = [p.x, p.y, p.z];
            let skip_static =
                last_static.is_some_and(|(q, d)| MAP_SLOPE_BOUND * (p - q).norm() < d);
            if !skip_static {
                let d = scene.static_clearance(&p);
                last_static = Some((p, d));
                if -d > 0.0 && worst_static.is_none_or(|(w, _, _)| -d > w) {
                    worst_static = Some((-d, t, point));
                }
            }
            for (o, f) in scene.forecasts.iter().enumerate() {
                let rate = f.v0.norm() + f.mu;
                if last_dynamic[o]
                    .is_some_and(|(q, tq, d)| (p - q).norm() + rate * (t - tq).abs() < d)
                {
                    continue;
                }
                let d = f.signed_distance(&p, t);
                last_dynamic[o] = Some((p, t, d));
                if -d > 0.0 && worst_dynamic[o].is_none_or(|(w, _, _)| -d > w) {
                    worst_dynamic[o] = Some((-d, t, point));
                }
            }
            for axis in 0..3 {
                let by = (bounds.min[axis] - p[axis]).max(p[axis] - bounds.max[axis]);
                if by > 0.0 {
                    keep(&mut worst_bounds[axis], by, t);
                }
            }
            let v = vel.norm();
            if v > limits.v_max {
                keep(&mut worst_speed, v, t);
            }
            let a = acc.norm();
            if a > limits.a_max {
                keep(&mut worst_accel, a, t);
            }
        }
        t_piece += d;
    }
    let mut out = Vec::new();
    if let Some((depth_m, t, point)) = worst_static {
        out.push(Violation::StaticPenetration { depth_m, t, point });
    }
    for (forecast, w) in worst_dynamic.into_iter().enumerate() {
        if let Some((depth_m, t, point)) = w {
            out.push(Violation::DynamicPenetration {
                forecast,
                depth_m,
                t,
                point,
            });
        }
    }
    for (axis, w) in ['x', 'y', 'z'].into_iter().zip(worst_bounds) {
        if let Some((by_m, t)) = w {
            out.push(Violation::LeavesBounds { axis, by_m, t });
        }
    }
    if let Some((v, t)) = worst_speed {
        out.push(Violation::OverSpeed {
            v,
            v_max: limits.v_max,
            t,
        });
    }
    if let Some((a, t)) = worst_accel {
        out.push(Violation::OverAccel {
            a,
            a_max: limits.a_max,
            t,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Forecast, ObstacleShape, StaticMap};
    use trust_geometry::{Aabb, Shape, Sphere};

    /// A straight line along x at `speed` m/s from `x0` for `duration` s, at y = z = 1.
    fn line(x0: f64, speed: f64, duration: f64) -> PolyTraj {
        let mut piece = [Vec3::zeros(); 6];
        piece[0] = Vec3::new(x0, 1.0, 1.0);
        piece[1] = Vec3::new(speed, 0.0, 0.0);
        PolyTraj::new(0.0, vec![duration], vec![piece]).unwrap()
    }

    fn map() -> StaticMap {
        let bounds = Aabb::new(Vec3::zeros(), Vec3::new(10.0, 2.0, 2.0)).unwrap();
        let ball = Shape::Sphere(Sphere::new(Vec3::new(5.0, 1.0, 1.0), 0.5).unwrap());
        StaticMap::from_shapes(bounds, vec![ball]).unwrap()
    }

    #[test]
    fn a_clean_trajectory_has_no_violation() {
        let map = StaticMap::new(Aabb::new(Vec3::zeros(), Vec3::repeat(10.0)).unwrap()).unwrap();
        let scene = Scene::new(&map, &[], 0.0).unwrap();
        let v = verify_trajectory(&line(1.0, 1.0, 5.0), &scene, &Limits::default());
        assert!(v.is_empty(), "{v:?}");
    }

    #[test]
    fn every_kind_is_reported_with_its_worst_instant() {
        let map = map();
        // A ball moving along the line, overlapping it at t = 1.
        let forecasts = [Forecast::new(
            ObstacleShape::Sphere,
            Vec3::new(4.0, 1.0, 1.0),
            Vec3::zeros(),
            0.0,
            0.25,
            0.0,
            0.0,
        )
        .unwrap()];
        let scene = Scene::new(&map, &forecasts, 0.0).unwrap();
        let limits = Limits::new(3.0, 1.0).unwrap();
        // 4 m/s from x = 0 for 3 s: through the ball at x = 5 (t = 1.25), ends at x = 12.
        let v = verify_trajectory(&line(0.0, 4.0, 3.0), &scene, &limits);
        assert_eq!(v.len(), 4, "{v:?}");
        match v[0] {
            Violation::StaticPenetration { depth_m, t, .. } => {
                assert!((depth_m - 0.5).abs() < 0.05, "{depth_m}");
                assert!((t - 1.25).abs() < 0.02, "{t}");
            }
            other => panic!("{other:?}"),
        }
        assert!(matches!(
            v[1],
            Violation::DynamicPenetration { forecast: 0, .. }
        ));
        match v[2] {
            Violation::LeavesBounds { axis, by_m, t } => {
                assert_eq!(axis, 'x');
                assert!((by_m - 2.0).abs() < 1e-9 && (t - 3.0).abs() < 1e-9);
            }
            other => panic!("{other:?}"),
        }
        assert!(
            matches!(v[3], Violation::OverSpeed { v, v_max, .. } if (v - 4.0).abs() < 1e-12 && v_max == 3.0)
        );
        let text = v[3].to_string();
        assert!(
            text.contains("limits.v_max") && text.contains("m/s"),
            "{text}"
        );
    }

    #[test]
    fn the_fused_horner_pass_matches_eval_piece() {
        let piece: Piece = std::array::from_fn(|k| Vec3::new(k as f64 + 0.5, -(k as f64), 0.25));
        for s in [0.0, 0.3, 1.7] {
            let [p, v, a] = position_velocity_acceleration(&piece, s);
            for (order, x) in [p, v, a].into_iter().enumerate() {
                let want = crate::eval_piece(&piece, order, s);
                assert!(
                    (x - want).norm() <= 1e-12 * want.norm().max(1.0),
                    "{order} {s}"
                );
            }
        }
    }

    #[test]
    fn long_trajectories_are_checked_with_a_bounded_number_of_samples() {
        let map = StaticMap::new(Aabb::new(Vec3::zeros(), Vec3::repeat(1e6)).unwrap()).unwrap();
        let scene = Scene::new(&map, &[], 0.0).unwrap();
        // 1e6 s at 1e-3 m/s: fine, and checked in at most VERIFY_MAX_SAMPLES + 1 instants.
        let v = verify_trajectory(&line(1.0, 1e-3, 1e6), &scene, &Limits::default());
        assert!(v.is_empty(), "{v:?}");
    }
}

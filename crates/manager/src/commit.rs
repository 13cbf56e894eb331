//! What a plan must pass before it is committed, beyond the safety check: with a sensed map the
//! planner may plan through unknown space (it is free on the planner's map), but the part the
//! vehicle commits to fly — until the next plan takes effect — and the braking after it must lie
//! in space the sensors observed free (FASTER, Tordesillas et al., IEEE T-RO 2022: the safe
//! trajectory lies in the known free space, the exploratory one may not).
//!
//! The manager asks its [`CommitCheck`] ([`crate::Manager::set_commit_check`]) about the
//! polyline of [`committed_stretch`]; a main branch that fails is not committed
//! ([`crate::Event::NotKnownFree`]) and the fallback brakes instead. The fallback's options are
//! judged by the same check over their committed stretch: the first one clear of the forecasts and
//! in known free space wins (braking along the committed plan counts as known: it stays in the
//! stretch its check passed); with none, they are chosen as without a check. Without a check
//! (a known map) nothing changes.

use std::sync::Arc;

use trust_core::{PolyTraj, State, Vec3};
use trust_geometry::StaticMap;

use crate::brake::braking_tail;

/// Space a committed plan may fly through (the known free space of a sensed map, with the
/// vehicle's clearance).
pub trait CommitCheck: Send + Sync {
    /// A short name for reports.
    fn name(&self) -> &str;
    /// Whether the vehicle may fly the straight segment `[a, b]`.
    fn segment_free(&self, a: &Vec3, b: &Vec3) -> bool;
    /// The map a global route from `from` to `goal` is searched on, if not the planning map
    /// (e.g. a sensed map with the space its sensor cannot see from `from` blocked, so that
    /// the route leaves through space the vehicle will be able to commit to). Asked when a
    /// route search starts; `None` (the default) searches the planning map.
    fn route_map(&self, from: &Vec3, goal: &Vec3) -> Option<Arc<StaticMap>> {
        let _ = (from, goal);
        None
    }
    /// How far back along its path a vehicle stalled before space this check refuses backs
    /// off to look at it (m; [`crate::retreat`]); `None` (the default) never backs off.
    fn retreat_m(&self) -> Option<f64> {
        None
    }
}

/// Time between two points of [`committed_stretch`] (s): 20 ms, the safety check's densest
/// sampling (the polyline stays within `a_max · (0.01 s)² / 2`, under a millimetre at 15 m/s²,
/// of the curve).
pub const COMMIT_SAMPLE_S: f64 = 0.02;

/// Most points of one [`committed_stretch`] (the step grows beyond it).
const MAX_POINTS: usize = 10_000;

/// The stretch of `traj` a vehicle commits to when the plan takes effect at `from` and the next
/// one at `until`, as (time, position) points: the plan over `[from, until + v/(0.9 a_max)]`
/// (`v` the plan's speed at `until`: braking along the plan at `0.9 a_max` from there stops
/// within the plan's path over that time unless the plan slows down first, and then it stops
/// on it), and when that passes the plan's end in motion, the straight braking tail after the
/// end ([`braking_tail`], as the safety check brakes). Empty for a non-finite window.
pub fn committed_stretch(traj: &PolyTraj, from: f64, until: f64, a_max: f64) -> Vec<(f64, Vec3)> {
    if !(from.is_finite() && until.is_finite() && a_max.is_finite() && a_max > 0.0) {
        return Vec::new();
    }
    let from = from.clamp(traj.t_start(), traj.t_end());
    let until = until.clamp(from, traj.t_end());
    let stop_s = traj.velocity(until).norm() / (0.9 * a_max);
    let end = (until + stop_s).min(traj.t_end());
    let mut points = sample(traj, from, end);
    if until + stop_s > traj.t_end() {
        let last: State = traj.state(traj.t_end());
        if last.v.norm() > 1e-6
            && let Ok(tail) = braking_tail(&last, a_max, COMMIT_SAMPLE_S)
        {
            points.extend(
                sample(&tail, tail.t_start(), tail.t_end())
                    .into_iter()
                    .skip(1),
            );
        }
    }
    points
}

/// `traj` at `from`, every [`COMMIT_SAMPLE_S`] (or coarser, at most `MAX_POINTS`), and `to`.
fn sample(traj: &PolyTraj, from: f64, to: f64) -> Vec<(f64, Vec3)> {
    let span = (to - from).max(0.0);
    let n = ((span / COMMIT_SAMPLE_S).ceil() as usize).clamp(1, MAX_POINTS);
    (0..=n)
        .map(|k| {
            let t = if k == n {
                to
            } else {
                from + span * k as f64 / n as f64
            };
            (t, traj.position(t))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use trust_core::Vec3;

    fn line(v: f64, duration: f64) -> PolyTraj {
        let piece = [
            Vec3::zeros(),
            Vec3::new(v, 0.0, 0.0),
            Vec3::zeros(),
            Vec3::zeros(),
            Vec3::zeros(),
            Vec3::zeros(),
        ];
        PolyTraj::new(0.0, vec![duration], vec![piece]).unwrap()
    }

    #[test]
    fn the_stretch_covers_the_committed_part_and_the_stop() {
        // 2 m/s for 5 s, committed for 0.2 s, a_max 3: stop within 2/2.7 s ≈ 0.74 s more.
        let pts = committed_stretch(&line(2.0, 5.0), 0.0, 0.2, 3.0);
        let last = pts.last().unwrap();
        assert!((last.0 - (0.2 + 2.0 / 2.7)).abs() < 1e-9, "{last:?}");
        assert!(
            pts.windows(2)
                .all(|w| w[1].0 - w[0].0 <= COMMIT_SAMPLE_S + 1e-12)
        );
    }

    #[test]
    fn a_plan_ending_in_motion_gets_its_braking_tail() {
        let pts = committed_stretch(&line(2.0, 0.5), 0.0, 0.2, 3.0);
        let last = pts.last().unwrap();
        // 1 m of plan, then 2²/(2·2.7) ≈ 0.74 m of straight braking.
        assert!(last.1.x > 1.0 + 0.7, "{last:?}");
        assert!(committed_stretch(&line(2.0, 0.5), f64::NAN, 0.2, 3.0).is_empty());
    }
}

//! The progress monitor (issue 19, "progress, not hovering"; beyond the paper).
//!
//! The paper's ranking cost `J` has no notion of progress: a branch that stops has a small `H_t`
//! and can be kept for ever. The monitor watches the vehicle's progress toward the goal — the
//! reduction of its distance to the goal — per second over a sliding window, and declares the
//! flight **stalled** when that rate stays below a threshold away from the goal, and **escaped**
//! when the vehicle has moved on again. While stalled the manager escalates
//! ([`crate::Manager::step`]): it explores every cycle with twice the paths and ranks branches
//! by how close to the goal they end before `J`.
//!
//! The rule, scaled by the vehicle and the planning horizon `T_h` (no absolute length or time):
//! - window `W = window_horizon_fraction · T_h` (default ½: 2 s at `T_h = 4 s`);
//! - stalled when the progress over the last `W` is below `stall_speed_fraction · v_max · W`
//!   (default 5 %: 0.5 m/s at E4's 10 m/s, 0.05 m/s at a Crazyflie's 1 m/s) while the vehicle is
//!   farther from the goal than that same distance (1 m at E4, 0.1 m at a Crazyflie's 1 m/s);
//! - escaped when the vehicle has progressed that distance beyond where it stalled, or is that
//!   close to the goal.

use std::collections::VecDeque;

use crate::Event;
use crate::params::StallRule;

/// Watches the progress toward the goal from cycle to cycle ([`ProgressMonitor::update`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ProgressMonitor {
    /// `(t, progress)` samples covering the last window, oldest first.
    samples: VecDeque<(f64, f64)>,
    /// When and at which progress (m) the current stall began.
    stalled_at: Option<(f64, f64)>,
}

impl ProgressMonitor {
    /// Whether the flight is stalled.
    pub fn stalled(&self) -> bool {
        self.stalled_at.is_some()
    }

    /// Forgets everything (a new flight).
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// Shifts every recorded progress by `offset_m` (m): the progress coordinate changed (a new
    /// route, whose arc length at the vehicle differs from the old one's by `offset_m`), the
    /// vehicle did not move. A stall stays a stall.
    pub fn rebase(&mut self, offset_m: f64) {
        if !offset_m.is_finite() {
            self.reset();
            return;
        }
        for (_, p) in &mut self.samples {
            *p += offset_m;
        }
        if let Some((_, at)) = &mut self.stalled_at {
            *at += offset_m;
        }
    }

    /// Records the progress `progress_m` (m; larger is nearer the goal, e.g. minus the distance
    /// to it) at time `t` with the vehicle `distance_to_goal_m` from the goal, and returns
    /// [`Event::Stalled`] or [`Event::Escaped`] when the state changes. Non-finite input is
    /// ignored; time going backwards restarts the window.
    pub fn update(
        &mut self,
        t: f64,
        progress_m: f64,
        distance_to_goal_m: f64,
        rule: &StallRule,
    ) -> Option<Event> {
        if !(t.is_finite() && progress_m.is_finite() && distance_to_goal_m.is_finite()) {
            return None;
        }
        if self.samples.back().is_some_and(|&(last, _)| t < last) {
            self.reset();
        }
        self.samples.push_back((t, progress_m));
        // Keep one sample at or before the window's start, so the window is spanned.
        while self.samples.len() > 2 && self.samples[1].0 <= t - rule.window_s {
            self.samples.pop_front();
        }
        let near_goal = distance_to_goal_m <= rule.min_progress_m;
        if let Some((since, at)) = self.stalled_at {
            if near_goal || progress_m - at >= rule.min_progress_m {
                self.stalled_at = None;
                return Some(Event::Escaped {
                    stalled_s: t - since,
                    distance_to_goal_m,
                });
            }
            return None;
        }
        let &(t0, p0) = self.samples.front()?;
        let span = t - t0;
        if near_goal || span < rule.window_s - 1e-9 || span <= 0.0 {
            return None;
        }
        let rate = (progress_m - p0) / span;
        (rate < rule.min_rate_mps).then(|| {
            self.stalled_at = Some((t, progress_m));
            Event::Stalled {
                progress_mps: rate,
                window_s: span,
                distance_to_goal_m,
            }
        })
    }
}

impl ProgressMonitor {
    /// Declares the flight stalled at time `t` with progress `progress_m` (m), whatever the
    /// rate (the manager knows the vehicle cannot go on: its every plan is refused), and
    /// returns [`Event::Stalled`] with the rate over the samples held; `None` if it already is
    /// or the input is not finite.
    pub fn declare_stalled(
        &mut self,
        t: f64,
        progress_m: f64,
        distance_to_goal_m: f64,
    ) -> Option<Event> {
        if self.stalled()
            || !(t.is_finite() && progress_m.is_finite() && distance_to_goal_m.is_finite())
        {
            return None;
        }
        let (t0, p0) = self.samples.front().copied().unwrap_or((t, progress_m));
        let span = t - t0;
        self.stalled_at = Some((t, progress_m));
        Some(Event::Stalled {
            progress_mps: if span > 0.0 {
                (progress_m - p0) / span
            } else {
                0.0
            },
            window_s: span.max(0.0),
            distance_to_goal_m,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ProgressParams;
    use trust_core::Limits;

    fn rule() -> StallRule {
        ProgressParams::default().rule(&Limits::default(), 4.0)
    }

    #[test]
    fn the_rule_scales_with_the_vehicle_and_the_horizon() {
        let r = rule();
        assert!((r.window_s - 2.0).abs() < 1e-12);
        assert!((r.min_rate_mps - 0.5).abs() < 1e-12);
        assert!((r.min_progress_m - 1.0).abs() < 1e-12);
        let slow = ProgressParams::default().rule(&Limits::new(1.0, 3.0).unwrap(), 4.0);
        assert!((slow.min_progress_m - 0.1).abs() < 1e-12);
    }

    #[test]
    fn standing_still_away_from_the_goal_stalls_once_then_escapes() {
        let (r, mut m) = (rule(), ProgressMonitor::default());
        let mut events = Vec::new();
        // 3 s at rest 12.8 m from the goal, then 1 m/s... 2 m/s toward it.
        for k in 0..60 {
            let t = 0.1 * k as f64;
            let d = if t < 3.0 {
                12.8
            } else {
                12.8 - 2.0 * (t - 3.0)
            };
            if let Some(e) = m.update(t, -d, d, &r) {
                events.push((t, e));
            }
        }
        assert_eq!(events.len(), 2, "{events:?}");
        assert!(matches!(events[0].1, Event::Stalled { progress_mps, .. } if progress_mps == 0.0));
        assert!((events[0].0 - 2.0).abs() < 1e-9);
        assert!(matches!(events[1].1, Event::Escaped { .. }));
        assert!(events[1].0 > 3.0 && events[1].0 < 3.6);
    }

    #[test]
    fn steady_progress_and_hovering_at_the_goal_are_no_stall() {
        let (r, mut m) = (rule(), ProgressMonitor::default());
        for k in 0..100 {
            let t = 0.1 * k as f64;
            let d = (20.0 - 3.0 * t).max(0.3);
            assert_eq!(m.update(t, -d, d, &r), None, "at {t}");
        }
        assert!(!m.stalled());
    }

    #[test]
    fn non_finite_input_is_ignored() {
        let (r, mut m) = (rule(), ProgressMonitor::default());
        assert_eq!(m.update(f64::NAN, 0.0, 5.0, &r), None);
        assert_eq!(m.update(0.0, f64::INFINITY, 5.0, &r), None);
        assert!(m.samples.is_empty());
    }

    #[test]
    fn bad_params_name_the_field() {
        let p = ProgressParams {
            stall_speed_fraction: 0.0,
            ..ProgressParams::default()
        };
        let e = p.validate().unwrap_err().to_string();
        assert!(e.contains("manager.progress.stall_speed_fraction"), "{e}");
    }

    #[test]
    fn a_declared_stall_lasts_until_the_vehicle_progresses() {
        let r = rule();
        let mut m = ProgressMonitor::default();
        assert!(m.update(0.0, 0.0, 50.0, &r).is_none());
        assert!(m.update(0.3, 0.3, 49.7, &r).is_none());
        assert!(matches!(
            m.declare_stalled(0.5, 0.4, 49.6),
            Some(Event::Stalled { progress_mps, .. }) if (progress_mps - 0.8).abs() < 1e-9
        ));
        assert!(m.stalled());
        assert!(m.declare_stalled(0.6, 0.4, 49.6).is_none(), "once");
        assert!(m.update(1.0, 1.0, 49.0, &r).is_none());
        assert!(matches!(
            m.update(1.5, 1.5, 48.5, &r),
            Some(Event::Escaped { .. })
        ));
        assert!(m.declare_stalled(f64::NAN, 0.0, 1.0).is_none());
    }
}

//! The braking fallback: decelerate along a trajectory the vehicle is already flying, then hold.
//!
//! [`brake_along`] keeps the *path* of a trajectory `q(u)` and slows down the progress along it:
//! `p(t) = q(u(t))` with `u̇ = λ(t)` falling from 1 to 0, so `v = q′λ` and `a = q″λ² + q′λ̇`. The
//! deceleration `−λ̇` is chosen at each instant so that `|q″|λ² + |q′||λ̇| ≤ 0.9·a_max` (with a floor
//! that guarantees a stop when the trajectory itself is at the acceleration limit), ramped in and out
//! so that acceleration is continuous at both ends. The result is sampled every 50 ms and
//! represented exactly at those knots by quintic Hermite pieces (position, velocity and acceleration
//! match), followed by a hold. Because the braking vehicle stays on a path that was checked clear of
//! the static map, it stays clear of it; moving obstacles are another matter (it arrives later than
//! planned), which is why the manager re-checks the fallback against the current forecasts and says
//! whether it is clear.
//!
//! [`brake_straight`] does the same along the current velocity direction, for when there is no
//! trajectory to follow.

use trust_core::{Piece, PlanError, PolyTraj, State, Vec3, check_positive};

/// Integration step of the time scaling (s).
const STEP_S: f64 = 1e-3;
/// Spacing of the Hermite knots (s).
const KNOT_S: f64 = 0.05;
/// Time over which the deceleration ramps in and out (s).
pub(crate) const RAMP_S: f64 = 0.2;
/// Fraction of `a_max` the braking aims for.
const TARGET_FRACTION: f64 = 0.9;
/// Longest braking manoeuvre simulated (s); beyond it the vehicle is stopped where it is.
const MAX_BRAKE_S: f64 = 60.0;

/// The quintic piece of duration `duration` with position, velocity and acceleration `start` at
/// local time 0 and `end` at `duration` (quintic Hermite interpolation).
pub fn hermite_quintic(start: [Vec3; 3], end: [Vec3; 3], duration: f64) -> Piece {
    let [p0, v0, a0] = start;
    let [p1, v1, a1] = end;
    let t = duration;
    let (t2, t3) = (t * t, t * t * t);
    let (t4, t5) = (t3 * t, t3 * t2);
    let dp = p1 - p0;
    [
        p0,
        v0,
        a0 * 0.5,
        (dp * 20.0 - (v1 * 8.0 + v0 * 12.0) * t - (a0 * 3.0 - a1) * t2) / (2.0 * t3),
        (dp * -30.0 + (v1 * 14.0 + v0 * 16.0) * t + (a0 * 3.0 - a1 * 2.0) * t2) / (2.0 * t4),
        (dp * 12.0 - (v1 + v0) * 6.0 * t - (a0 - a1) * t2) / (2.0 * t5),
    ]
}

/// The path being braked along: `q(u)` and its first two derivatives.
trait BrakePath {
    fn eval(&self, u: f64) -> [Vec3; 3];
}

/// A trajectory, extended beyond its end along its final velocity.
struct Along<'a>(&'a PolyTraj);

impl BrakePath for Along<'_> {
    fn eval(&self, u: f64) -> [Vec3; 3] {
        let traj = self.0;
        if u <= traj.t_end() {
            [traj.position(u), traj.velocity(u), traj.acceleration(u)]
        } else {
            let (p, v) = (traj.position(traj.t_end()), traj.velocity(traj.t_end()));
            [p + v * (u - traj.t_end()), v, Vec3::zeros()]
        }
    }
}

/// A straight line through `p` along `v`, parameterized by time since `t0`.
struct Straight {
    t0: f64,
    p: Vec3,
    v: Vec3,
}

impl BrakePath for Straight {
    fn eval(&self, u: f64) -> [Vec3; 3] {
        [self.p + self.v * (u - self.t0), self.v, Vec3::zeros()]
    }
}

/// Brakes along `traj` from its state at time `from` (clamped to its span) and then holds still for
/// `hold_s` seconds. The result starts at `from` with the trajectory's position, velocity and
/// acceleration there.
///
/// # Errors
/// [`PlanError::InvalidInput`] for a non-positive or non-finite `a_max` or `hold_s`.
pub fn brake_along(
    traj: &PolyTraj,
    from: f64,
    a_max: f64,
    hold_s: f64,
) -> Result<PolyTraj, PlanError> {
    let from = if from.is_finite() {
        from.clamp(traj.t_start(), traj.t_end())
    } else {
        traj.t_start()
    };
    brake(&Along(traj), from, None, a_max, hold_s)
}

/// Brakes along a straight line from `state` (its velocity direction) and then holds for `hold_s`
/// seconds. The result starts with `state`'s position, velocity and acceleration.
///
/// # Errors
/// As [`brake_along`], and for a non-finite state.
pub fn brake_straight(state: &State, a_max: f64, hold_s: f64) -> Result<PolyTraj, PlanError> {
    state.validate("state")?;
    let line = Straight {
        t0: state.t,
        p: state.p,
        v: state.v,
    };
    brake(&line, state.t, Some(state.a), a_max, hold_s)
}

/// Escape manoeuvres from `state` (beyond the paper): in each of `directions` (normalized; zero
/// vectors skipped), a single quintic from `state` to rest `distance_m` away, then a hold of
/// `hold_s` seconds. Its duration is the least of a geometric sequence (×1.25) whose speed and
/// acceleration stay within `limits` (checked on a dense sampling), starting from the
/// minimum-jerk rest-to-rest time of the distance. For the braking fallback: when a moving
/// obstacle comes at a vehicle that brakes in place, moving out of its way is the only safe
/// answer.
///
/// # Errors
/// [`PlanError::InvalidInput`] for a non-finite state, a non-positive distance or hold, or
/// invalid limits.
pub fn escape_maneuvers(
    state: &State,
    directions: &[Vec3],
    distance_m: f64,
    limits: &trust_core::Limits,
    hold_s: f64,
) -> Result<Vec<PolyTraj>, PlanError> {
    state.validate("state")?;
    limits.validate()?;
    check_positive("escape.distance_m", distance_m)?;
    check_positive("escape.hold_s", hold_s)?;
    let (v_max, a_max) = (limits.v_max, limits.a_max);
    // Minimum-jerk rest to rest: peak speed 1.875 d/T, peak acceleration 5.77 d/T².
    let base = (1.875 * distance_m / v_max)
        .max((5.77 * distance_m / a_max).sqrt())
        .max(state.v.norm() / a_max);
    let mut out = Vec::new();
    for u in directions {
        let n = u.norm();
        if !(n.is_finite() && n > 1e-9) {
            continue;
        }
        let end = [state.p + u * (distance_m / n), Vec3::zeros(), Vec3::zeros()];
        let mut duration = base;
        for _ in 0..12 {
            let piece = hermite_quintic([state.p, state.v, state.a], end, duration);
            let hold = hermite_quintic(end, end, hold_s);
            let traj = PolyTraj::new(state.t, vec![duration, hold_s], vec![piece, hold])?;
            let within = (0..=64).all(|k| {
                let t = state.t + duration * k as f64 / 64.0;
                traj.velocity(t).norm() <= v_max * 1.001
                    && traj.acceleration(t).norm() <= a_max * 1.001
            });
            if within {
                out.push(traj);
                break;
            }
            duration *= 1.25;
        }
    }
    Ok(out)
}

/// Fraction of `v_max` a dash ([`dash_maneuvers`]) cruises at.
const DASH_SPEED_FRACTION: f64 = 0.9;

/// Dash manoeuvres from `state` (beyond the paper): in each of `directions` (normalized; zero
/// vectors skipped), a quintic that reaches `0.9·v_max` along the direction with zero
/// acceleration, a cruise at that velocity for `cruise_s` seconds, then straight braking
/// ([`brake_straight`]) and a hold of `hold_s` seconds. The quintic's duration is the least of a
/// geometric sequence (×1.25, from the velocity change over `a_max`) whose speed and acceleration
/// stay within `limits` and whose jerk stays below `a_max` per 0.2 s, the braking's own ramp
/// (dense sampling; without the jerk bound the controller overshot `a_max` by 47 %).
///
/// For the braking fallback: an escape to rest ([`escape_maneuvers`]) starts slowly (a minimum-jerk
/// rest-to-rest move), and a person walking at the vehicle's own speed reaches it first; a dash
/// across the person's way is out of it in a fraction of a second.
///
/// # Errors
/// [`PlanError::InvalidInput`] for a non-finite state, a non-positive cruise or hold, or invalid
/// limits.
pub fn dash_maneuvers(
    state: &State,
    directions: &[Vec3],
    cruise_s: f64,
    limits: &trust_core::Limits,
    hold_s: f64,
) -> Result<Vec<PolyTraj>, PlanError> {
    state.validate("state")?;
    limits.validate()?;
    check_positive("dash.cruise_s", cruise_s)?;
    check_positive("dash.hold_s", hold_s)?;
    let (v_max, a_max) = (limits.v_max, limits.a_max);
    let speed = DASH_SPEED_FRACTION * v_max;
    let mut out = Vec::new();
    for u in directions {
        let n = u.norm();
        if !(n.is_finite() && n > 1e-9) {
            continue;
        }
        let u = u / n;
        let v_end = u * speed;
        let mut duration = ((v_end - state.v).norm() / a_max).max(0.05);
        for _ in 0..16 {
            // Position change of a quintic from (v0, a0) to (v1, 0): the average velocity
            // (trapezoid) plus the initial acceleration's contribution.
            let end_p = state.p
                + (state.v + v_end) * (0.5 * duration)
                + state.a * (duration * duration / 12.0);
            let dash = hermite_quintic(
                [state.p, state.v, state.a],
                [end_p, v_end, Vec3::zeros()],
                duration,
            );
            let within = (0..=64).all(|k| {
                let s = duration * k as f64 / 64.0;
                let v = trust_core::eval_piece(&dash, 1, s);
                let a = trust_core::eval_piece(&dash, 2, s);
                let j = trust_core::eval_piece(&dash, 3, s);
                v.norm() <= v_max * 1.001 && a.norm() <= a_max * 1.001 && j.norm() <= a_max / RAMP_S
            });
            if within {
                let cruise_end = end_p + v_end * cruise_s;
                let cruise = hermite_quintic(
                    [end_p, v_end, Vec3::zeros()],
                    [cruise_end, v_end, Vec3::zeros()],
                    cruise_s,
                );
                let t_brake = state.t + duration + cruise_s;
                let brake = brake_straight(
                    &State {
                        t: t_brake,
                        p: cruise_end,
                        v: v_end,
                        a: Vec3::zeros(),
                    },
                    a_max,
                    hold_s,
                )?;
                let mut durations = vec![duration, cruise_s];
                durations.extend_from_slice(brake.durations());
                let mut pieces = vec![dash, cruise];
                pieces.extend_from_slice(brake.pieces());
                out.push(PolyTraj::new(state.t, durations, pieces)?);
                break;
            }
            duration *= 1.25;
        }
    }
    Ok(out)
}

fn brake(
    path: &dyn BrakePath,
    t0: f64,
    initial_accel: Option<Vec3>,
    a_max: f64,
    hold_s: f64,
) -> Result<PolyTraj, PlanError> {
    check_positive("brake.a_max", a_max)?;
    check_positive("brake.hold_s", hold_s)?;
    let target = TARGET_FRACTION * a_max;
    let [p_start, v_start, a_start] = path.eval(t0);
    let v0 = v_start.norm().max(1e-3);
    // Floor of the deceleration rate of λ: stop within v0 / (a_max/10) even along a path at the
    // limit; the braking then asks for at most (0.9 + 0.1)·a_max (with a floor of a_max/4 it
    // asked for 1.15 a_max along a rejected trajectory that turned at the limit, and the
    // vehicle reached 1.13 a_max in a room with people).
    let beta_min = 0.1 * a_max / v0;
    let beta_max = target / v0;
    let ramp = beta_max / RAMP_S;

    let mut knots: Vec<(f64, [Vec3; 3])> =
        vec![(0.0, [p_start, v_start, initial_accel.unwrap_or(a_start)])];
    let (mut u, mut lambda, mut lambda_dot) = (t0, 1.0f64, 0.0f64);
    let steps_per_knot = (KNOT_S / STEP_S).round() as usize;
    let max_steps = (MAX_BRAKE_S / STEP_S) as usize;
    let mut stopped = v_start.norm() < 1e-6;
    let mut step = 0;
    while !stopped && step < max_steps {
        let [_, dq, ddq] = path.eval(u);
        let speed = dq.norm().max(1e-9);
        let beta = ((target - ddq.norm() * lambda * lambda) / speed).clamp(beta_min, beta_max);
        // Slow enough to bring λ̇ back to 0 exactly when λ reaches 0 at the ramp rate.
        let wanted = -beta.min((2.0 * ramp * lambda).sqrt());
        lambda_dot += (wanted - lambda_dot).clamp(-ramp * STEP_S, ramp * STEP_S);
        u += lambda * STEP_S + 0.5 * lambda_dot * STEP_S * STEP_S;
        lambda = (lambda + lambda_dot * STEP_S).max(0.0);
        step += 1;
        if lambda <= 1e-4 {
            stopped = true;
        }
        if stopped || step % steps_per_knot == 0 {
            let [q, dq, ddq] = path.eval(u);
            let state = if stopped {
                [q, Vec3::zeros(), Vec3::zeros()]
            } else {
                [q, dq * lambda, ddq * (lambda * lambda) + dq * lambda_dot]
            };
            knots.push((step as f64 * STEP_S, state));
        }
    }
    if !stopped {
        // Out of time: stop where the vehicle is (a last, harder piece).
        let (t_last, [q, _, _]) = knots[knots.len() - 1];
        knots.push((t_last + KNOT_S, [q, Vec3::zeros(), Vec3::zeros()]));
    }
    let mut durations = Vec::with_capacity(knots.len());
    let mut pieces = Vec::with_capacity(knots.len());
    for w in knots.windows(2) {
        let (ta, sa) = w[0];
        let (tb, sb) = w[1];
        let d = tb - ta;
        if d > 0.0 {
            durations.push(d);
            pieces.push(hermite_quintic(sa, sb, d));
        }
    }
    let end = knots[knots.len() - 1].1[0];
    let mut hold = [Vec3::zeros(); 6];
    hold[0] = end;
    durations.push(hold_s);
    pieces.push(hold);
    PolyTraj::new(t0, durations, pieces)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use trust_core::eval_piece;

    fn arc(t0: f64) -> PolyTraj {
        // A curving, accelerating quintic over 3 s.
        let piece: Piece = [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(6.0, 0.0, 0.0),
            Vec3::new(0.5, 1.5, 0.0),
            Vec3::new(0.0, -0.2, 0.0),
            Vec3::zeros(),
            Vec3::zeros(),
        ];
        PolyTraj::new(t0, vec![3.0], vec![piece]).unwrap()
    }

    #[test]
    fn hermite_matches_both_ends() {
        let s = [
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(-1.0, 0.5, 0.0),
            Vec3::new(0.2, 0.0, -3.0),
        ];
        let e = [
            Vec3::new(4.0, -2.0, 3.5),
            Vec3::new(2.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let piece = hermite_quintic(s, e, 0.7);
        for k in 0..3 {
            assert_relative_eq!(eval_piece(&piece, k, 0.0), s[k], epsilon = 1e-9);
            assert_relative_eq!(eval_piece(&piece, k, 0.7), e[k], epsilon = 1e-9);
        }
    }

    #[test]
    fn braking_along_starts_on_the_trajectory_and_stops_within_the_limit() {
        let traj = arc(10.0);
        let a_max = 15.0;
        let brake = brake_along(&traj, 10.5, a_max, 1.0).unwrap();
        let s = brake.state(10.5);
        let q = traj.state(10.5);
        assert_relative_eq!(s.p, q.p, epsilon = 1e-9);
        assert_relative_eq!(s.v, q.v, epsilon = 1e-9);
        assert_relative_eq!(s.a, q.a, epsilon = 1e-9);
        let end = brake.state(brake.t_end());
        assert!(end.v.norm() < 1e-9 && end.a.norm() < 1e-9);
        let (_, a) = brake.max_speed_and_acceleration(32);
        assert!(a <= a_max, "max accel {a}");
        // Stays on the path: every braking position is near the original trajectory.
        for k in 0..=100 {
            let t = brake.t_start() + brake.duration() * k as f64 / 100.0;
            let p = brake.position(t);
            let nearest = (0..=3000)
                .map(|j| (traj.position(10.0 + 3.0 * j as f64 / 3000.0) - p).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(nearest < 0.01, "off the path by {nearest} at {t}");
        }
        // It stops sooner than the trajectory would have gone on: about v²/(2·0.9·a_max) + ramps.
        let v = q.v.norm();
        let travelled = (end.p - q.p).norm();
        assert!(travelled < v * v / (2.0 * 0.5 * a_max), "{travelled}");
    }

    #[test]
    fn braking_past_the_end_continues_straight() {
        let traj = arc(0.0);
        let brake = brake_along(&traj, 2.95, 15.0, 1.0).unwrap();
        assert!(brake.state(brake.t_end()).v.norm() < 1e-9);
        assert!(brake.position(brake.t_end()).x > traj.position(3.0).x);
    }

    #[test]
    fn straight_braking_from_rest_holds() {
        let s = State::at_rest(2.0, Vec3::new(1.0, 1.0, 1.0));
        let b = brake_straight(&s, 15.0, 2.0).unwrap();
        assert_eq!(b.t_start(), 2.0);
        assert_relative_eq!(b.position(3.0), s.p);
        assert!(b.duration() >= 2.0);
    }

    #[test]
    fn straight_braking_matches_the_state_and_stops() {
        let s = State {
            t: 0.0,
            p: Vec3::zeros(),
            v: Vec3::new(0.0, 10.0, 0.0),
            a: Vec3::new(1.0, 0.0, 0.0),
        };
        let b = brake_straight(&s, 15.0, 1.0).unwrap();
        assert_relative_eq!(b.acceleration(0.0), s.a, epsilon = 1e-9);
        assert_relative_eq!(b.velocity(0.0), s.v, epsilon = 1e-9);
        let end = b.position(b.t_end());
        assert!(end.y > 3.0 && end.y < 8.0, "{end:?}");
        assert!(b.velocity(b.t_end()).norm() < 1e-9);
    }

    #[test]
    fn bad_input_is_an_error() {
        let traj = arc(0.0);
        assert!(brake_along(&traj, 1.0, 0.0, 1.0).is_err());
        assert!(brake_along(&traj, 1.0, 15.0, f64::NAN).is_err());
        let mut s = State::at_rest(0.0, Vec3::zeros());
        s.v.x = f64::NAN;
        assert!(brake_straight(&s, 15.0, 1.0).is_err());
        // A non-finite start time is clamped, not propagated.
        assert!(brake_along(&traj, f64::NAN, 15.0, 1.0).is_ok());
    }
}

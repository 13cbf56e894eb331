//! The braking fallback: decelerate along a trajectory the vehicle is already flying, then hold.
//!
//! [`brake_along`] keeps the *path* of a trajectory `q(u)` and slows down the progress along it:
//! `p(t) = q(u(t))` with `u̇ = λ(t)` falling from 1 to 0, so `v = q′λ` and `a = q″λ² + q′λ̇`. The
//! deceleration `−λ̇` is chosen at each instant so that `|q″λ² + q′λ̇| ≤ 0.9·a_max` (the path's
//! own acceleration along `q′` counts with its sign; with a floor that guarantees a stop when the
//! trajectory itself is at the acceleration limit), and the acceleration changes by at most
//! `a_max` per 0.2 s: braking a trajectory that still accelerates first turns its acceleration
//! round, as the vehicle must. The result is sampled every 50 ms and represented exactly at those
//! knots by quintic Hermite pieces (position, velocity and acceleration match), followed by a
//! hold. Because the braking vehicle stays on a path that was checked clear of the static map, it
//! stays clear of it; moving obstacles are another matter (it arrives later than planned), which
//! is why the manager re-checks the fallback against the current forecasts and says whether it is
//! clear.
//!
//! [`brake_straight`] does the same along the current velocity direction, for when there is no
//! trajectory to follow; the vehicle's acceleration across that direction ramps out within the
//! same jerk limit.

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

/// A line through `p` along `v`, parameterized by time since `t0`, bent at first by the part
/// `a_normal` of the vehicle's acceleration across `v`, which ramps down to zero over `ramp_s`
/// (`q″ = a_normal·(1 − s/ramp_s)`): a vehicle turning cannot stop turning at once. The part
/// along `v` is the braking's initial `λ̇`.
struct Straight {
    t0: f64,
    p: Vec3,
    v: Vec3,
    a_normal: Vec3,
    ramp_s: f64,
}

impl BrakePath for Straight {
    fn eval(&self, u: f64) -> [Vec3; 3] {
        let s = (u - self.t0).max(0.0);
        let r = self.ramp_s;
        // f″ = 1 − s/r on [0, r], 0 after; f(0) = f′(0) = 0.
        let (f, df, ddf) = if s < r {
            (
                s * s / 2.0 - s * s * s / (6.0 * r),
                s - s * s / (2.0 * r),
                1.0 - s / r,
            )
        } else {
            (r * r / 3.0 + r / 2.0 * (s - r), r / 2.0, 0.0)
        };
        [
            self.p + self.v * s + self.a_normal * f,
            self.v + self.a_normal * df,
            self.a_normal * ddf,
        ]
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
    brake(&Along(traj), from, 0.0, a_max, hold_s)
}

/// Brakes along a straight line from `state` (its velocity direction) and then holds for `hold_s`
/// seconds. The result starts with `state`'s position, velocity and acceleration.
///
/// # Errors
/// As [`brake_along`], and for a non-finite state.
pub fn brake_straight(state: &State, a_max: f64, hold_s: f64) -> Result<PolyTraj, PlanError> {
    state.validate("state")?;
    check_positive("brake.a_max", a_max)?;
    let speed2 = state.v.norm_squared();
    let (a_along, a_normal) = if speed2 > 1e-12 {
        let along = state.v * (state.a.dot(&state.v) / speed2);
        (along, state.a - along)
    } else {
        (state.a, Vec3::zeros())
    };
    let line = Straight {
        t0: state.t,
        p: state.p,
        v: state.v,
        a_normal,
        ramp_s: (a_normal.norm() / (a_max / RAMP_S)).max(1e-3),
    };
    // The acceleration along the line enters as λ̇ (a = v·λ̇ at λ = 1).
    let lambda_dot = if speed2 > 1e-12 {
        a_along.dot(&state.v) / speed2
    } else {
        0.0
    };
    brake(&line, state.t, lambda_dot, a_max, hold_s)
}

/// The braking tail of a trajectory that ends at `end` ([`crate::SafetyParams::braking_tail`],
/// [`crate::SafetyParams::rest_hold_s`]): straight braking ([`brake_straight`]) from the end's
/// position and velocity, then a hold of `hold_s` seconds. The end's acceleration is not
/// counted: the tail is the model the backend's braking-tail penalty optimizes against
/// (`trust_minco::PenaltyParams::braking_tail_delay_s`), which sees only the end's position and
/// velocity — were the two to differ, candidates the optimizer cleared would be dropped by
/// millimetres. Whatever the plan that follows does is checked when it is planned.
///
/// # Errors
/// As [`brake_straight`].
pub fn braking_tail(end: &State, a_max: f64, hold_s: f64) -> Result<PolyTraj, PlanError> {
    brake_straight(
        &State {
            a: Vec3::zeros(),
            ..*end
        },
        a_max,
        hold_s,
    )
}

/// Escape manoeuvres from `state` (beyond the paper): in each of `directions` (normalized; zero
/// vectors skipped), a single quintic from `state` to rest `distance_m` away, then a hold of
/// `hold_s` seconds. Its duration is the least of a geometric sequence (×1.25) whose speed and
/// acceleration stay within `limits` and whose jerk stays below `a_max` per 0.2 s, the braking's
/// own ramp (checked on a dense sampling), starting from the
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
                    && traj.jerk(t).norm() <= a_max / RAMP_S
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

/// From position `p`, velocity `v` and acceleration `a` at `t0`: the acceleration ramps down to
/// zero within the jerk limit (`a_max` per [`RAMP_S`], with half as much again to spare), then
/// the vehicle brakes along its velocity as [`brake_straight`] does and holds for `hold_s`.
fn settle(
    p: Vec3,
    v: Vec3,
    a: Vec3,
    t0: f64,
    a_max: f64,
    hold_s: f64,
) -> Result<PolyTraj, PlanError> {
    // (At most 1.5 RAMP_S: a rejected plan braked along may accelerate beyond a_max.)
    let ramp_s = (1.5 * a.norm() * RAMP_S / a_max).clamp(KNOT_S, 1.5 * RAMP_S);
    // A linear ramp of the acceleration to zero: Δv = a·τ/2, Δp = v·τ + a·τ²/3.
    let v1 = v + a * (0.5 * ramp_s);
    let p1 = p + v * ramp_s + a * (ramp_s * ramp_s / 3.0);
    let first = hermite_quintic([p, v, a], [p1, v1, Vec3::zeros()], ramp_s);
    let line = Straight {
        t0: t0 + ramp_s,
        p: p1,
        v: v1,
        a_normal: Vec3::zeros(),
        ramp_s: RAMP_S,
    };
    let rest = brake(&line, t0 + ramp_s, 0.0, a_max, hold_s)?;
    let mut durations = vec![ramp_s];
    durations.extend_from_slice(rest.durations());
    let mut pieces = vec![first];
    pieces.extend_from_slice(rest.pieces());
    PolyTraj::new(t0, durations, pieces)
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
    initial_lambda_dot: f64,
    a_max: f64,
    hold_s: f64,
) -> Result<PolyTraj, PlanError> {
    check_positive("brake.a_max", a_max)?;
    check_positive("brake.hold_s", hold_s)?;
    let target = TARGET_FRACTION * a_max;
    let [p_start, v_start, a_path] = path.eval(t0);
    let v0 = v_start.norm().max(1e-3);
    // Floor of the deceleration rate of λ: stop within v0 / (a_max/10) even along a path at the
    // limit; the braking then asks for at most (0.9 + 0.1)·a_max (with a floor of a_max/4 it
    // asked for 1.15 a_max along a rejected trajectory that turned at the limit, and the
    // vehicle reached 1.13 a_max in a room with people).
    let beta_min = 0.1 * a_max / v0;
    let beta_max = target / v0;
    let ramp = beta_max / RAMP_S;
    // The acceleration changes by at most a_max per RAMP_S: braking an accelerating trajectory
    // swung the command from +0.9 to −0.9 a_max within 0.1 s (the path's own jerk and the
    // ramp of λ̇ added up) and the quadrotor overshot a_max by 10 %.
    let jerk_max = a_max / RAMP_S;
    let rates = LambdaRates {
        target,
        beta_min,
        ramp,
        jerk_max,
    };

    let mut accel = a_path + v_start * initial_lambda_dot;
    if v_start.norm() < accel.norm() * RAMP_S {
        // Nearly at rest, still accelerating: it would stop within a ramp, dropping its
        // acceleration at once (a vehicle at 0.04 m/s decelerating at 2.9 m/s² was told to stop
        // within 14 ms; its attitude swung and it reached 1.8 a_max). Settle instead.
        return settle(p_start, v_start, accel, t0, a_max, hold_s);
    }
    let mut knots: Vec<(f64, [Vec3; 3])> = vec![(0.0, [p_start, v_start, accel])];
    let (mut u, mut lambda, mut lambda_dot) = (t0, 1.0f64, initial_lambda_dot);
    let steps_per_knot = (KNOT_S / STEP_S).round() as usize;
    let max_steps = (MAX_BRAKE_S / STEP_S) as usize;
    let mut stopped = v_start.norm() < 1e-6;
    let mut step = 0;
    while !stopped && step < max_steps {
        u += lambda * STEP_S + 0.5 * lambda_dot * STEP_S * STEP_S;
        lambda = (lambda + lambda_dot * STEP_S).max(0.0);
        let [_, dq, ddq] = path.eval(u);
        lambda_dot = next_lambda_dot(&dq, &ddq, lambda, lambda_dot, &accel, &rates);
        accel = ddq * (lambda * lambda) + dq * lambda_dot;
        step += 1;
        if lambda <= 1e-6 {
            stopped = true;
        }
        if stopped || step % steps_per_knot == 0 {
            let q = path.eval(u)[0];
            // The stop replaces a knot less than half a spacing before it: a 1 ms last piece
            // from 0.02 a_max to rest is a jerk of 20 a_max/s.
            if stopped
                && knots.len() > 1
                && step as f64 * STEP_S - knots[knots.len() - 1].0 < 0.5 * KNOT_S
            {
                knots.pop();
            }
            let state = if stopped {
                [q, Vec3::zeros(), Vec3::zeros()]
            } else {
                [q, dq * lambda, accel]
            };
            knots.push((step as f64 * STEP_S, state));
        }
    }
    if !stopped {
        // Out of time: stop where the vehicle is (a last, harder piece).
        let (t_last, [q, _, _]) = knots[knots.len() - 1];
        knots.push((t_last + KNOT_S, [q, Vec3::zeros(), Vec3::zeros()]));
    }
    knots_to_trajectory(&knots, t0, hold_s)
}

/// The rates that bound λ̇ in [`brake`]: the target deceleration (m/s²), the floor of λ's
/// deceleration rate (1/s), the ramp of λ̇ (1/s²) and the jerk limit (m/s³).
struct LambdaRates {
    target: f64,
    beta_min: f64,
    ramp: f64,
    jerk_max: f64,
}

/// One step of [`brake`]'s time scaling: the next λ̇ at path velocity `dq` and acceleration
/// `ddq` (at `u`), with `λ`, the current `λ̇` and the last commanded acceleration `accel`.
fn next_lambda_dot(
    dq: &Vec3,
    ddq: &Vec3,
    lambda: f64,
    lambda_dot: f64,
    accel: &Vec3,
    rates: &LambdaRates,
) -> f64 {
    let LambdaRates {
        target,
        beta_min,
        ramp,
        jerk_max,
    } = *rates;
    let speed = dq.norm().max(1e-9);
    // The largest deceleration rate with |q″λ² + q′λ̇| ≤ target: the path's own
    // acceleration along q′ helps or hinders, the part across it only uses up the budget.
    let tangent = dq / speed;
    let a_along = ddq.dot(&tangent) * lambda * lambda;
    let a_across = (ddq * (lambda * lambda) - tangent * a_along).norm();
    let exact = (a_along + (target * target - a_across * a_across).max(0.0).sqrt()) / speed;
    let beta = exact.max(beta_min);
    // The rate of λ̇ is bounded by the ramp and, where the path is fast, by the jerk limit
    // (q′λ̈ is the acceleration's change along the path).
    let ramp_here = ramp.min(TARGET_FRACTION * jerk_max / speed);
    // Slow enough to bring λ̇ back to 0 exactly when λ reaches 0 at that rate; on the way
    // back λ̇ may change up to a quarter faster (within the jerk limit), so that it keeps to
    // that curve (without the slack, where the path sped up, the curve outran λ̇ and the
    // vehicle stopped dead from 0.2 a_max).
    let wanted = -beta.min((2.0 * ramp_here * lambda).sqrt());
    let mut next =
        lambda_dot + (wanted - lambda_dot).clamp(-ramp_here * STEP_S, 1.25 * ramp_here * STEP_S);
    // Keep |Δa| ≤ jerk_max·dt where λ̇ can: the λ̇ for which q″λ² + q′λ̇ stays that close
    // to the last acceleration form an interval (a line through a ball). Never faster along
    // the path than before or than the ramp asks: where the path's own acceleration falls,
    // matching it means speeding up along the path — chased, that ran away to 3× the
    // path's speed. Where no λ̇ matches (the path turns faster), the ramp alone.
    let free = ddq * (lambda * lambda) - accel;
    let (g2, cg) = (dq.norm_squared(), free.dot(dq));
    let radius = jerk_max * STEP_S;
    let disc = cg * cg - g2 * (free.norm_squared() - radius * radius);
    if g2 > 1e-12 && disc >= 0.0 {
        let half = disc.sqrt();
        next = next
            .clamp((-cg - half) / g2, (-cg + half) / g2)
            .min(lambda_dot.max(next));
    }
    next
}

/// [`brake`]'s knots (time since the start, `[p, v, a]`) as quintic pieces from `t0`, then the
/// hold at the last knot's position for `hold_s`.
fn knots_to_trajectory(
    knots: &[(f64, [Vec3; 3])],
    t0: f64,
    hold_s: f64,
) -> Result<PolyTraj, PlanError> {
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

    /// Largest jerk norm over `[t0, t1]`, 2 ms apart.
    fn max_jerk_between(traj: &PolyTraj, t0: f64, t1: f64) -> f64 {
        let n = ((t1 - t0) / 2e-3).ceil() as usize;
        (0..=n)
            .map(|k| traj.jerk(t0 + (t1 - t0) * k as f64 / n as f64).norm())
            .fold(0.0, f64::max)
    }

    /// A dash: from rest to 9 m/s along +x in 1.2 s (a quintic, 14 m/s² at its peak), then
    /// straight on.
    fn dash() -> PolyTraj {
        let start = [Vec3::zeros(), Vec3::zeros(), Vec3::zeros()];
        let end = [
            Vec3::new(5.4, 0.0, 0.0),
            Vec3::new(9.0, 0.0, 0.0),
            Vec3::zeros(),
        ];
        let on = [
            Vec3::new(14.4, 0.0, 0.0),
            Vec3::new(9.0, 0.0, 0.0),
            Vec3::zeros(),
        ];
        PolyTraj::new(
            0.0,
            vec![1.2, 1.0],
            vec![
                hermite_quintic(start, end, 1.2),
                hermite_quintic(end, on, 1.0),
            ],
        )
        .unwrap()
    }

    #[test]
    fn braking_an_accelerating_trajectory_turns_the_acceleration_round_within_the_jerk_limit() {
        // Regression: braking a dash while it still accelerated swung the command from +0.9 to
        // −0.9 a_max within 0.1 s and the quadrotor overshot a_max by 10 %.
        let a_max = 15.0;
        let traj = dash();
        for from in [0.3, 0.5, 0.6, 0.8, 1.0] {
            let b = brake_along(&traj, from, a_max, 0.5).unwrap();
            let stop = b.t_end() - 0.5;
            let jerk = max_jerk_between(&b, from, stop);
            let (_, a) = b.max_speed_and_acceleration(64);
            // The knots follow the profile's jerk limit exactly; the quintics between them
            // overshoot it by up to 60 % (the old braking: 140 a_max/s and more).
            assert!(jerk <= 2.0 * a_max / RAMP_S, "from {from}: jerk {jerk}");
            assert!(a <= a_max, "from {from}: accel {a}");
            assert!(b.velocity(b.t_end()).norm() < 1e-9);
        }
    }

    #[test]
    fn straight_braking_from_a_turn_keeps_the_acceleration_continuous() {
        let a_max = 3.0;
        let s = State {
            t: 1.0,
            p: Vec3::zeros(),
            v: Vec3::new(1.0, 0.0, 0.0),
            a: Vec3::new(2.0, 1.6, 0.0),
        };
        let b = brake_straight(&s, a_max, 0.5).unwrap();
        assert_relative_eq!(b.acceleration(1.0), s.a, epsilon = 1e-9);
        assert_relative_eq!(b.velocity(1.0), s.v, epsilon = 1e-9);
        let stop = b.t_end() - 0.5;
        let jerk = max_jerk_between(&b, 1.0, stop);
        let (_, a) = b.max_speed_and_acceleration(64);
        assert!(jerk <= 2.0 * a_max / RAMP_S, "jerk {jerk}");
        assert!(a <= a_max * 1.001, "accel {a}");
        assert!(b.velocity(b.t_end()).norm() < 1e-9);
    }

    #[test]
    fn braking_never_runs_ahead_of_the_path() {
        // Regression: keeping the acceleration continuous along a path whose own acceleration
        // fell meant speeding up along it; chased every step, the braking ran away to 3× the
        // path's speed (a room with people: the vehicle reached 1.8 m/s at v_max 1 m/s).
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let a_max = 2.7;
        let mut v3 = |scale: f64| {
            Vec3::new(
                rng.random_range(-scale..scale),
                rng.random_range(-scale..scale),
                rng.random_range(-scale..scale) * 0.2,
            )
        };
        for _ in 0..200 {
            let start = [Vec3::zeros(), v3(0.7), v3(1.5)];
            let end = [v3(1.5), v3(0.7), v3(1.5)];
            let traj =
                PolyTraj::new(0.0, vec![1.0], vec![hermite_quintic(start, end, 1.0)]).unwrap();
            let fastest = (0..=200)
                .map(|k| traj.velocity(k as f64 / 200.0).norm())
                .fold(0.0, f64::max);
            for from in [0.0, 0.3, 0.6] {
                let b = brake_along(&traj, from, a_max, 0.5).unwrap();
                let (v, _) = b.max_speed_and_acceleration(64);
                let reach = fastest + a_max * RAMP_S;
                assert!(
                    v <= reach,
                    "from {from}: {v} m/s on a path of at most {fastest}"
                );
                assert!(b.velocity(b.t_end()).norm() < 1e-9);
            }
        }
    }

    #[test]
    fn braking_nearly_at_rest_settles_within_the_jerk_limit() {
        // Regression: 0.04 m/s while decelerating at 2.9 m/s² was a 14 ms stop.
        let a_max = 2.7;
        let s = State {
            t: 2.3,
            p: Vec3::new(1.0, 2.0, 1.0),
            v: Vec3::new(0.04, 0.0, 0.0),
            a: Vec3::new(-2.6, 0.6, 0.0),
        };
        let b = brake_straight(&s, a_max, 0.5).unwrap();
        assert_relative_eq!(b.acceleration(2.3), s.a, epsilon = 1e-9);
        let stop = b.t_end() - 0.5;
        // (Within the limit at the knots; the quintics between overshoot it by up to 60 %.)
        assert!(max_jerk_between(&b, 2.3, stop) <= 2.0 * a_max / RAMP_S);
        let (_, a) = b.max_speed_and_acceleration(64);
        assert!(a <= a_max * 1.001, "{a}");
        assert!(b.velocity(b.t_end()).norm() < 1e-12);
        // Along a trajectory that turns round there, the same.
        let turn = PolyTraj::new(
            2.3,
            vec![1.0],
            vec![hermite_quintic(
                [s.p, s.v, s.a],
                [
                    s.p + Vec3::new(-1.0, 0.3, 0.0),
                    Vec3::new(-1.0, 0.3, 0.0),
                    Vec3::zeros(),
                ],
                1.0,
            )],
        )
        .unwrap();
        let b = brake_along(&turn, 2.3, a_max, 0.5).unwrap();
        assert!(max_jerk_between(&b, 2.3, b.t_end() - 0.5) <= 2.0 * a_max / RAMP_S);
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

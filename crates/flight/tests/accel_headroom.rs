//! Regression test (issue 19, "max acceleration ≤ a_max + 5 %"): how far the default quadrotor's
//! true acceleration overshoots a planned swing of the acceleration, and that the planner's
//! defaults keep it within 5 % of `a_max`.
//!
//! The reference cruises at `a_from`, swings linearly (a quintic with matched ends) to `a_to`
//! within `swing_s`, and holds. The planner plans with `a_max·(1 − h)`
//! (`trust_world::planner::DEFAULT_ACCEL_HEADROOM`) and penalizes jerk above `a_max / ramp`
//! (`PRESET_JERK_RAMP_S`): the worst swing it plans is a full reversal of `0.9 a_max` at that
//! jerk, which must stay within `1.05 a_max` on the true vehicle — at a Crazyflie's 3 m/s² and at
//! E4's 15 m/s². A swing five times faster (what MINCO planned before the jerk limit) does not at
//! 3 m/s² (1.21 `a_max`; 1.01 at 15 m/s²).

use trust_core::{PolyTraj, Vec3};
use trust_manager::hermite_quintic;
use trust_vehicle::{ControlledQuadrotor, QuadrotorParams, Reference, Se3Gains, Vehicle};
use trust_world::planner::{DEFAULT_ACCEL_HEADROOM, PRESET_JERK_RAMP_S};

/// Peak true acceleration (m/s²) of the default quadrotor, with the controller capped at
/// `a_max`, on a reference whose acceleration swings from `a_from` to `a_to` (along x) in
/// `swing_s` seconds.
fn peak_true_acceleration(a_from: f64, a_to: f64, swing_s: f64, a_max: f64) -> f64 {
    let dt = 0.002;
    let hold = 1.0;
    let x = Vec3::x();
    let s0 = [Vec3::new(0.0, 0.0, 2.0), Vec3::zeros(), x * a_from];
    let s1 = [
        s0[0] + x * (0.5 * a_from * hold * hold),
        x * (a_from * hold),
        x * a_from,
    ];
    let s2 = [
        s1[0] + s1[1] * swing_s + x * ((a_from / 3.0 + a_to / 6.0) * swing_s * swing_s),
        s1[1] + x * (0.5 * (a_from + a_to) * swing_s),
        x * a_to,
    ];
    let s3 = [
        s2[0] + s2[1] * hold + s2[2] * (0.5 * hold * hold),
        s2[1] + s2[2] * hold,
        s2[2],
    ];
    let traj = PolyTraj::new(
        0.0,
        vec![hold, swing_s, hold],
        vec![
            hermite_quintic(s0, s1, hold),
            hermite_quintic(s1, s2, swing_s),
            hermite_quintic(s2, s3, hold),
        ],
    )
    .expect("reference");
    let plan = |t: f64| Reference::from_traj(&traj, t, 0.0);
    let gains = Se3Gains {
        max_accel_m_s2: Some(a_max),
        ..Se3Gains::default()
    };
    let mut vehicle =
        ControlledQuadrotor::starting_on(QuadrotorParams::default(), gains, 0.0, &plan(0.0))
            .expect("vehicle");
    let mut peak = 0.0_f64;
    for _ in 0..(traj.t_end() / dt).round() as usize {
        vehicle.step(dt, &plan).expect("step");
        let s = vehicle.state();
        if s.t > 0.5 * hold {
            peak = peak.max(s.a.norm());
        }
    }
    peak
}

#[test]
fn a_planned_reversal_at_the_jerk_limit_stays_within_five_percent_of_a_max() {
    for a_max in [3.0, 15.0] {
        let a_plan = a_max * (1.0 - DEFAULT_ACCEL_HEADROOM);
        // A full reversal at the jerk limit a_max / ramp takes 2·a_plan / (a_max / ramp).
        let swing_s = 2.0 * a_plan * PRESET_JERK_RAMP_S / a_max;
        let limited = peak_true_acceleration(a_plan, -a_plan, swing_s, a_max) / a_max;
        let fast = peak_true_acceleration(a_plan, -a_plan, swing_s / 5.0, a_max) / a_max;
        eprintln!(
            "a_max {a_max}: reversal of ±{a_plan:.2} m/s² in {swing_s:.2} s peaks at \
             {limited:.3} a_max, in {:.2} s at {fast:.3} a_max",
            swing_s / 5.0
        );
        assert!(limited <= 1.05, "a_max {a_max}: {limited} a_max");
        assert!(fast > limited, "a_max {a_max}: {fast} vs {limited}");
        if a_max < 5.0 {
            // At a Crazyflie's limits the fast swing breaks the bound (1.21 a_max measured).
            assert!(
                fast > 1.05,
                "a_max {a_max}: the fast swing must overshoot, {fast}"
            );
        }
    }
}

/// The overshoot depends on how fast the acceleration swings, and less at larger scales: a
/// reversal of `±0.9 a_max` peaks (in units of `a_max`) at
///
/// | `a_max` | ramp 0.05 s | 0.1 s | 0.15 s | 0.2 s | 0.3 s |
/// |---|---|---|---|---|---|
/// | 2 | 1.193 (1.221) | 1.149 (1.174) | 1.078 (1.099) | 1.016 (1.034) | 0.961 |
/// | 3 | 1.156 (1.215) | 1.115 (1.169) | 1.050 (1.095) | 1.005 (1.032) | 0.960 |
/// | 8 | 1.012 (1.126) | 1.013 (1.130) | 1.008 (1.067) | 1.003 (1.013) | 0.948 |
/// | 15 | 1.000 (1.007) | 1.009 (1.074) | 1.005 (1.030) | 0.989 | 0.933 |
///
/// (the ramp is the time to swing by `a_max`; in brackets without the controller's thrust cap,
/// `Se3Gains::max_accel_m_s2` applied to the thrust along the actual body axis; faster swings
/// than 0.05 s at 15 m/s² are beyond the body-rate limit and are not followed at all). What is
/// left at small `a_max` is the attitude's own overshoot: tilted past `asin(a_max/g)` no thrust
/// keeps the acceleration within `a_max`. At the presets' 0.3 s every scale stays below
/// `a_max`; at the braking's 0.2 s within 1.6 % (the presets keep 0.3 s: at 0.2 s the rooms with
/// people had more failures, 19 vs 13 in 120 flights).
#[test]
fn the_overshoot_depends_on_the_ramp_at_every_scale() {
    for a_max in [2.0, 3.0, 8.0, 15.0] {
        let a_plan = 0.9 * a_max;
        let peak = |ramp: f64| {
            let swing_s = 2.0 * a_plan * ramp / a_max;
            peak_true_acceleration(a_plan, -a_plan, swing_s, a_max) / a_max
        };
        let (slow, medium, fast) = (peak(0.3), peak(0.2), peak(0.1));
        eprintln!("a_max {a_max}: ramp 0.3 s {slow:.3}, 0.2 s {medium:.3}, 0.1 s {fast:.3}");
        assert!(
            slow < 1.0 && medium < 1.02,
            "a_max {a_max}: {slow}, {medium}"
        );
        assert!(
            fast > medium && medium > slow,
            "a_max {a_max}: {fast}, {medium}, {slow}"
        );
    }
}

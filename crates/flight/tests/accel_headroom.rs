//! Regression test (issue 19, "max acceleration ≤ a_max + 5 %"): how far the default quadrotor's
//! true acceleration overshoots a planned swing of the acceleration, and that the planner's
//! defaults keep it within 5 % of `a_max`.
//!
//! The reference cruises at `a_from`, swings linearly (a quintic with matched ends) to `a_to`
//! within `swing_s`, and holds. The planner plans with `a_max·(1 − h)`
//! (`trust_planner::DEFAULT_ACCEL_HEADROOM`) and penalizes jerk above `a_max / ramp`
//! (`PRESET_JERK_RAMP_S`): the worst swing it plans is a full reversal of `0.9 a_max` at that
//! jerk, which must stay within `1.05 a_max` on the true vehicle — at a Crazyflie's 3 m/s² and at
//! E4's 15 m/s². The fallbacks and the feedback are not as gentle: a swing to the full `a_max`
//! within 0.02–0.2 s must stay within the bound too, which the controller's cap only keeps
//! because it leaves room for the attitude's overshoot (`Se3Gains::max_accel_m_s2`; without it
//! 1.10–1.15 `a_max` below 3 m/s², the rooms' 1.15 at `a_max` 0.8).

use trust_core::{PolyTraj, Vec3};
use trust_manager::hermite_quintic;
use trust_planner::{DEFAULT_ACCEL_HEADROOM, PRESET_JERK_RAMP_S};
use trust_vehicle::{ControlledQuadrotor, QuadrotorParams, Reference, Se3Gains, Vehicle};

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

/// Peaks (in units of `a_max`) of a reversal of `±0.9 a_max` within `2·0.9·ramp` and of a swing
/// from 0 to the full `a_max` within `ramp`, at every scale:
///
/// | `a_max` | reversal, ramp 0.05 s | 0.1 s | 0.2 s | 0.3 s | swing to `a_max` in 0.02 s | 0.1 s | 0.2 s |
/// |---|---|---|---|---|---|---|---|
/// | 0.5 | 1.000 (1.223) | 1.001 (1.176) | 1.020 (1.035) | 0.962 | 1.000 (1.153) | 1.000 (1.152) | 1.001 (1.126) |
/// | 0.8 | 1.000 (1.220) | 1.000 (1.173) | 1.018 (1.033) | 0.962 | 1.000 (1.150) | 1.000 (1.149) | 1.000 (1.124) |
/// | 2 | 1.000 (1.193) | 1.000 (1.149) | 1.003 (1.016) | 0.961 | 1.000 (1.129) | 1.000 (1.127) | 1.000 (1.101) |
/// | 3 | 1.000 (1.156) | 1.001 (1.115) | 1.004 (1.005) | 0.960 | 1.000 | 1.000 | 1.000 |
/// | 8 | 1.000 | 1.003 | 1.003 | 0.948 | 1.000 | 1.000 | 1.002 |
/// | 15 | 1.000 | 1.003 | 0.989 | 0.933 | 1.000 | 1.002 | 1.003 |
///
/// (in brackets, where measured, before the controller left room for the attitude's overshoot:
/// tilted past `asin(a_max/g)` no thrust keeps the acceleration within `a_max`, and the attitude
/// swinging towards a capped command at `w` rad/s overshoots it by about `w·lead`, see
/// `trust_vehicle::Se3Gains::max_accel_m_s2`). The presets plan at 0.3 s, where every scale stays
/// below `a_max`.
#[test]
fn swings_of_the_acceleration_stay_within_two_and_a_half_percent_at_every_scale() {
    for a_max in [0.5, 0.8, 2.0, 3.0, 8.0, 15.0] {
        let a_plan = 0.9 * a_max;
        let reversal =
            |ramp: f64| peak_true_acceleration(a_plan, -a_plan, 2.0 * 0.9 * ramp, a_max) / a_max;
        let swing = |ramp: f64| peak_true_acceleration(0.0, a_max, ramp, a_max) / a_max;
        let reversals = [0.05, 0.1, 0.2, 0.3].map(reversal);
        let swings = [0.02, 0.1, 0.2].map(swing);
        eprintln!("a_max {a_max}: reversals {reversals:.3?}, swings to a_max {swings:.3?}");
        for peak in reversals.iter().chain(&swings) {
            assert!(*peak <= 1.025, "a_max {a_max}: {reversals:?} {swings:?}");
        }
        // The worst swing the presets plan, a full reversal of `a_max·(1 − headroom)` at their
        // jerk limit, keeps below a_max.
        let a_planned = a_max * (1.0 - DEFAULT_ACCEL_HEADROOM);
        let swing_s = 2.0 * a_planned * PRESET_JERK_RAMP_S / a_max;
        let planned = peak_true_acceleration(a_planned, -a_planned, swing_s, a_max) / a_max;
        assert!(planned < 1.0, "a_max {a_max}: {planned}");
    }
}

/// Without the cap the controller follows the reference: a swing the vehicle can fly is flown
/// (the cap changes nothing below it), and one beyond the cap is the cap's to bound.
#[test]
fn the_cap_only_bounds_what_exceeds_it() {
    let a_max = 3.0;
    let planned = peak_true_acceleration(0.9 * a_max, -0.9 * a_max, 0.54, a_max);
    let uncapped = peak_true_acceleration(0.9 * a_max, -0.9 * a_max, 0.54, 100.0);
    assert!(
        (planned - uncapped).abs() < 1e-3 * a_max,
        "{planned} vs {uncapped}"
    );
    // A fast swing to 1.2 a_max is held at the cap.
    let beyond = peak_true_acceleration(0.0, 1.2 * a_max, 0.1, a_max) / a_max;
    assert!((0.98..=1.025).contains(&beyond), "{beyond}");
}

//! The backend's braking-tail penalty models the manoeuvre the safety check requires to be clear
//! (`braking_tail`); if the two drift apart, the optimizer clears a tail the check does not
//! accept (or the reverse), and candidates are dropped by millimetres.

use trust_core::{State, Vec3};
use trust_manager::braking_tail;
use trust_minco::PenaltyParams;

/// Distance travelled by the penalty's model at `t` after the end: coasting for the delay, then
/// decelerating at the fraction of `a_max` to rest.
fn model_distance(p: &PenaltyParams, v: f64, a_max: f64, t: f64) -> f64 {
    let decel = p.braking_tail_decel_fraction * a_max;
    let delay = p.braking_tail_delay_s;
    if t <= delay {
        return v * t;
    }
    let s = (t - delay).min(v / decel);
    v * delay + v * s - 0.5 * decel * s * s
}

#[test]
fn the_backends_braking_tail_model_matches_the_braking_manoeuvre() {
    let params = PenaltyParams::default();
    let a_max = 15.0;
    for v in [1.0, 2.0, 5.0, 10.0] {
        for a in [0.0, 7.5, -7.5] {
            let start = State {
                t: 0.0,
                p: Vec3::zeros(),
                v: Vec3::new(v, 0.0, 0.0),
                a: Vec3::new(a, 0.0, 0.0),
            };
            let brake = braking_tail(&start, a_max, 0.5).expect("brake");
            let mut worst: f64 = 0.0;
            let mut t = 0.0;
            while t <= brake.t_end() {
                let x = brake.position(t).x;
                worst = worst.max((x - model_distance(&params, v, a_max, t)).abs());
                t += 1e-3;
            }
            let stop = brake.position(brake.t_end()).x;
            let model_stop = model_distance(&params, v, a_max, f64::INFINITY);
            // Where the vehicle is at each instant (what the moving obstacles see) within 10 cm,
            // where it stops within 2 cm + 1 %.
            assert!(
                worst < 0.1,
                "v = {v}, a = {a}: positions differ by up to {worst} m"
            );
            assert!(
                (stop - model_stop).abs() < 0.02 + 0.01 * model_stop,
                "v = {v}, a = {a}: stops at {stop} m, the model at {model_stop} m"
            );
        }
    }
}

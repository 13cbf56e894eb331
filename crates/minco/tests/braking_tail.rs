//! The braking-tail penalty is continuous where the terminal comes to rest, and its gradient
//! matches finite differences inside and outside the low-speed ramp.

use trust_core::{Aabb, Forecast, Limits, ObstacleShape, StaticMap, Vec3};
use trust_minco::costs::{PenaltyIntegrand, TAIL_RAMP_MPS};
use trust_minco::{CostWeights, PenaltyParams};

fn map() -> StaticMap {
    StaticMap::new(Aabb::new(Vec3::repeat(-50.0), Vec3::repeat(50.0)).unwrap()).unwrap()
}

/// A sphere whose margin holds the terminal `p_f = 0` and the first metres ahead of it.
fn forecasts() -> Vec<Forecast> {
    vec![
        Forecast::new(
            ObstacleShape::Sphere,
            Vec3::new(0.8, 0.3, 0.0),
            Vec3::new(-0.5, 0.2, 0.0),
            0.0,
            0.6,
            0.3,
            0.2,
        )
        .unwrap(),
    ]
}

fn tail(p_f: Vec3, v_f: Vec3, t_end: f64) -> trust_minco::costs::BrakingTail {
    let (map, forecasts) = (map(), forecasts());
    let params = PenaltyParams::default();
    let limits = Limits::new(10.0, 15.0).unwrap();
    let mut pen = PenaltyIntegrand::new(&forecasts, &map, limits, &CostWeights::default(), &params);
    pen.braking_tail(
        &p_f,
        &v_f,
        t_end,
        params.braking_tail_decel_fraction * limits.a_max,
        params.braking_tail_delay_s,
        params.braking_tail_samples,
        0.1,
    )
}

#[test]
fn the_tail_vanishes_continuously_as_the_terminal_comes_to_rest() {
    let p = Vec3::zeros();
    let full = tail(p, Vec3::new(2.0, 0.0, 0.0), 1.0).cost;
    assert!(full > 0.0, "the obstacle must be on the tail");
    let mut last = f64::INFINITY;
    for speed in [0.9, 0.3, 1e-2, 1e-4, 1e-7] {
        let c = tail(p, Vec3::new(speed, 0.0, 0.0), 1.0).cost;
        assert!(c <= last, "decreasing toward rest: {c} after {last}");
        last = c;
    }
    assert!(
        last < 1e-9 * full,
        "at 1e-7 m/s the tail costs {last} (full {full})"
    );
    assert_eq!(tail(p, Vec3::zeros(), 1.0).cost, 0.0);
}

#[test]
fn tail_gradients_match_finite_differences_inside_and_outside_the_ramp() {
    let p = Vec3::new(0.1, -0.05, 0.02);
    for v in [
        Vec3::new(0.4, 0.2, 0.0),
        Vec3::new(0.9 * TAIL_RAMP_MPS, -0.1, 0.05),
        Vec3::new(2.5, 0.4, -0.1),
    ] {
        let t = 0.7;
        let base = tail(p, v, t);
        assert!(base.cost > 0.0);
        let h = 1e-6;
        for axis in 0..3 {
            let e = |s: f64| Vec3::ith(axis, s);
            let fd_v = trust_numdiff::central_difference(|s| tail(p, v + e(s), t).cost, 0.0, h);
            let fd_p = trust_numdiff::central_difference(|s| tail(p + e(s), v, t).cost, 0.0, h);
            let tol = |fd: f64| 1e-5 * (1.0 + fd.abs());
            assert!(
                (fd_v - base.grad_v[axis]).abs() < tol(fd_v),
                "v = {v:?}, ∂/∂v[{axis}]: fd {fd_v} vs {}",
                base.grad_v[axis]
            );
            assert!(
                (fd_p - base.grad_p[axis]).abs() < tol(fd_p),
                "v = {v:?}, ∂/∂p[{axis}]: fd {fd_p} vs {}",
                base.grad_p[axis]
            );
        }
        let fd_t = trust_numdiff::central_difference(|s| tail(p, v, s).cost, t, h);
        assert!(
            (fd_t - base.grad_t).abs() < 1e-5 * (1.0 + fd_t.abs()),
            "∂/∂t: fd {fd_t} vs {}",
            base.grad_t
        );
    }
}

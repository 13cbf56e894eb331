//! Public-API tests of trust-predict: a tracker feeding forecasts, cones built from them, and the
//! queries the planner's front end (DEV-PRM) and back end (DDF cost) make.

use approx::assert_relative_eq;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use trust_predict::convex::{
    NormMinusAffine2d, Vec2, min_norm_minus_affine, min_over_convex_polygon,
};
use trust_predict::{
    Aabb, CLEAR_TOLERANCE, CvEkf, EkfParams, Forecast, ObstacleShape, Pdc, PredictError, Vec3,
};

/// Tracks a pedestrian-like cylinder walking at constant velocity and checks that its forecast
/// cone contains the true future positions over the horizon.
#[test]
fn tracked_forecast_cone_contains_the_true_motion() {
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let noise = Normal::new(0.0, 0.1).unwrap();
    let (p0, v) = (Vec3::new(5.0, 0.0, 1.0), Vec3::new(-1.0, 0.5, 0.0));
    let truth = |t: f64| p0 + v * t;
    let mut measure = |t: f64| {
        truth(t)
            + Vec3::new(
                noise.sample(&mut rng),
                noise.sample(&mut rng),
                noise.sample(&mut rng),
            )
    };
    let mut ekf = CvEkf::new(0.0, measure(0.0), EkfParams::default()).unwrap();
    for k in 1..=60 {
        let t = k as f64 * 0.05;
        let z = measure(t);
        ekf.step(t, (k % 4 != 0).then_some(z)).unwrap();
    }
    let shape = ObstacleShape::Cylinder { half_height: 0.9 };
    let forecast = ekf.forecast(shape, 0.3, 0.0).unwrap();
    let horizon = 2.0;
    let pdc = forecast.pdc(horizon).unwrap();
    for i in 0..=20 {
        let t = forecast.t0 + horizon * i as f64 / 20.0;
        // The true centre stays inside the predicted (inflated) obstacle at every time…
        assert!(forecast.signed_distance(&truth(t), t) < -0.3, "t = {t}");
        // …and hence inside the cone.
        assert!(pdc.contains(&truth(t)));
    }
}

#[test]
fn ddf_gradient_includes_obstacle_motion() {
    // Paper eq. gradients-of-Io (b): for a fixed point, an approaching obstacle makes d decrease.
    let f = Forecast::sphere(Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0), 0.0, 0.5, 0.1, 0.2).unwrap();
    let p = Vec3::new(3.0, 0.0, 0.0);
    let (d, d_p, d_t) = f.distance_and_gradients(&p, 1.0);
    assert_relative_eq!(d, 2.0 - 0.8, epsilon = 1e-12);
    assert_relative_eq!(d_p, Vec3::x(), epsilon = 1e-12);
    assert_relative_eq!(d_t, -1.0 - 0.2, epsilon = 1e-12);
    let b = f.aabb_over(0.0, 1.0).unwrap();
    assert_relative_eq!(b.min.x, -0.8); // the largest radius in the window is used throughout
    assert_relative_eq!(b.max.x, 1.8);
}

#[test]
fn cone_blocks_what_the_obstacle_will_sweep() {
    let f = Forecast::sphere(
        Vec3::new(0.0, -3.0, 1.0),
        Vec3::new(0.0, 2.0, 0.0),
        0.0,
        0.4,
        0.1,
        0.1,
    )
    .unwrap();
    let pdc = Pdc::new(&f, 2.0).unwrap();
    // Its path crosses y = 0 at t = 1.5 s; a wall of segments along x at y = 0 is blocked…
    assert!(!pdc.segment_clear(&Vec3::new(-4.0, 0.0, 1.0), &Vec3::new(4.0, 0.0, 1.0), 0.2));
    // …but with a 1 s horizon the obstacle has not arrived yet (it is at y = -1, radius 0.6).
    let short = Pdc::new(&f, 1.0).unwrap();
    assert!(short.segment_clear(&Vec3::new(-4.0, 0.0, 1.0), &Vec3::new(4.0, 0.0, 1.0), 0.2));
    assert!(pdc.aabb().contains(&Vec3::new(0.0, 1.0, 1.0)));
    // Samples around the cone are obstacle-aware roadmap seeds: on the surface, 0.1 m out.
    let region = Aabb {
        min: Vec3::repeat(-10.0),
        max: Vec3::repeat(10.0),
    };
    let mut out = Vec::new();
    pdc.surface_samples_into(3, 6, 0.1, &region, &mut out)
        .unwrap();
    assert_eq!(out.len(), 20); // 3 rings of 6 and one point beyond each end
    for s in &out {
        assert_relative_eq!(pdc.signed_distance(s), 0.1, epsilon = 1e-9);
        assert!(pdc.point_clear(s, 0.05) && !pdc.point_clear(s, 0.15));
    }
}

#[test]
fn errors_name_the_field_and_value() {
    let e = Forecast::new(
        ObstacleShape::Sphere,
        Vec3::zeros(),
        Vec3::zeros(),
        0.0,
        0.5,
        0.1,
        -1.0,
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "forecast.mu = -1 is out of range: expected a finite number >= 0"
    );
    let f = Forecast::sphere(Vec3::zeros(), Vec3::zeros(), 2.0, 0.5, 0.1, 0.0).unwrap();
    let e = Pdc::over_window(&f, 3.0, 1.0).unwrap_err();
    assert!(matches!(e, PredictError::InvalidWindow { .. }));
    assert_eq!(
        e.to_string(),
        "invalid time window [3, 1]: expected finite t_start <= t_end"
    );
    let mut ekf = CvEkf::new(0.0, Vec3::zeros(), EkfParams::default()).unwrap();
    let e = ekf
        .step(1.0, Some(Vec3::new(0.0, f64::NAN, 0.0)))
        .unwrap_err();
    assert_eq!(e.to_string(), "measurement.y must be finite, got NaN");
}

#[test]
fn convex_building_blocks_are_usable_alone() {
    // Closest approach of a point moving along x to the origin: at λ = 2, distance 1.
    let m = min_norm_minus_affine(&Vec3::new(-2.0, 1.0, 0.0), &Vec3::x(), 0.0, 0.0, 0.0, 10.0);
    assert_relative_eq!(m.arg, 2.0);
    assert_relative_eq!(m.value, 1.0);
    let f = NormMinusAffine2d {
        m: Vec3::new(-0.5, -0.5, 1.0),
        mx: Vec3::x(),
        my: Vec3::y(),
        k0: 0.0,
        k: Vec2::zeros(),
    };
    let square = [
        Vec2::new(0.0, 0.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(1.0, 1.0),
        Vec2::new(0.0, 1.0),
    ];
    assert_relative_eq!(min_over_convex_polygon(&f, &square), 1.0, epsilon = 1e-12);
}

/// Random segments against random cones: `segment_clear` never misses a sampled collision.
#[test]
fn random_segments_never_miss_a_sampled_collision() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let r3 = |rng: &mut ChaCha8Rng, s: f64| {
        Vec3::new(
            rng.random_range(-s..s),
            rng.random_range(-s..s),
            rng.random_range(-s..s),
        )
    };
    let mut blocked_count = 0;
    for trial in 0..300 {
        let shape = if trial % 2 == 0 {
            ObstacleShape::Sphere
        } else {
            ObstacleShape::Cylinder { half_height: 0.8 }
        };
        let f = Forecast::new(
            shape,
            r3(&mut rng, 1.0),
            r3(&mut rng, 2.0),
            0.0,
            0.5,
            0.1,
            rng.random_range(0.0..0.5),
        )
        .unwrap();
        let pdc = f.pdc(2.0).unwrap();
        let (a, b) = (r3(&mut rng, 4.0), r3(&mut rng, 4.0));
        let clear = pdc.segment_clear(&a, &b, 0.2);
        blocked_count += usize::from(!clear);
        for i in 0..=60 {
            for j in 0..=60 {
                let x = a + (b - a) * (i as f64 / 60.0);
                let d = f.signed_distance(&x, 2.0 * j as f64 / 60.0);
                assert!(
                    !(clear && d < 0.2 - CLEAR_TOLERANCE),
                    "trial {trial}: sampled hit d = {d} missed"
                );
            }
        }
    }
    assert!(
        blocked_count > 30,
        "the test should exercise blocked segments ({blocked_count})"
    );
}

//! Regression tests for the bugs `cargo xtask fuzz` (crates/fuzz) and issue 11 found at the edges of
//! f64, each named after the bug.

use trust_predict::{
    Aabb, CvEkf, EkfParams, Forecast, MAX_ACCEL_PSD, MAX_MANOEUVRE_GATE, MAX_SIGMA_SCALE,
    ObstacleShape, Pdc, PredictError, Vec3, convex, round_cone_sdf,
};

#[test]
fn forecast_accepting_1e300_speed_is_now_a_scale_error() {
    // Issue 11: magnitudes like 1e300 or f64::MAX were accepted, then gave NaN gradients.
    let e = Forecast::sphere(
        Vec3::zeros(),
        Vec3::new(1e300, 0.0, 0.0),
        0.0,
        1.0,
        0.0,
        0.0,
    )
    .unwrap_err();
    assert!(matches!(e, PredictError::Scale(_)), "{e:?}");
    assert!(e.to_string().contains("forecast.v0.x"), "{e}");
    assert!(e.to_string().contains("1.0e300"), "{e}");
    let e = Forecast::sphere(Vec3::zeros(), Vec3::zeros(), 0.0, f64::MAX, 0.0, 0.0).unwrap_err();
    assert!(e.to_string().contains("forecast.r_o"), "{e}");
}

#[test]
fn forecast_distance_at_infinite_point_is_not_nan() {
    let f = Forecast::sphere(Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0), 0.0, 0.5, 0.1, 0.2).unwrap();
    for (p, t) in [
        (Vec3::new(f64::INFINITY, 1.0, 0.0), 1.0),
        (Vec3::new(1.0, 1.0, 0.0), -f64::MAX),
        (Vec3::new(1e155, 0.0, 0.0), 0.0),
    ] {
        let (d, dp, dt) = f.distance_and_gradients(&p, t);
        assert!(!d.is_nan() && dp.iter().all(|x| !x.is_nan()) && !dt.is_nan());
    }
}

#[test]
fn million_sample_cone_surface_is_a_count_error() {
    // Issue 11: a 10⁶-sample cone surface took seconds.
    let f = Forecast::sphere(Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0), 0.0, 0.5, 0.1, 0.2).unwrap();
    let pdc = f.pdc(2.0).unwrap();
    let region = Aabb {
        min: Vec3::repeat(-10.0),
        max: Vec3::repeat(10.0),
    };
    let e = pdc.surface_samples(1000, 1000, 0.1, &region).unwrap_err();
    assert!(matches!(e, PredictError::Count(_)), "{e:?}");
    assert!(
        pdc.surface_samples(usize::MAX, usize::MAX, 0.1, &region)
            .is_err()
    );
}

#[test]
fn pdc_support_with_huge_direction_is_finite() {
    // Fuzz case 16281829902901881008: a direction with a 1e300 component gave NaN.
    let f = Forecast::sphere(
        Vec3::zeros(),
        Vec3::new(4.2, 2.9, -0.5),
        0.0,
        1.9,
        2.0,
        0.13,
    )
    .unwrap();
    let pdc = Pdc::new(&f, 0.2).unwrap();
    for d in [
        Vec3::new(1e300, -1e300, 0.5),
        Vec3::new(f64::INFINITY, 0.0, 0.0),
        Vec3::new(0.0, f64::MAX, f64::MAX),
    ] {
        assert!(pdc.support(&d).iter().all(|x| x.is_finite()), "{d:?}");
    }
}

#[test]
fn convex_helpers_with_huge_inputs_are_not_nan() {
    // Fuzz case 3786356886628797132.
    let a = Vec3::new(1e155, 5e-324, 2.34);
    let b = Vec3::new(-20.1, -20.7, -18.6);
    let c = Vec3::new(22.1, -23.2, 0.0);
    let d = Vec3::new(1e8, 0.0, 14.0);
    let (s, t) = convex::segment_segment_params(&a, &b, &c, &d);
    assert!(!s.is_nan() && !t.is_nan());
    let (dist, g) = round_cone_sdf(&a, &b, 1.0, 2.0, &c);
    assert!(!dist.is_nan() && g.iter().all(|x| !x.is_nan()));
}

#[test]
fn ekf_forecast_blames_the_filter_parameters_not_r_safe() {
    // Issue 11: an estimate that left the policy was reported as a bad forecast field.
    let params = EkfParams {
        init_vel_std: 1e4,
        sigma_scale: MAX_SIGMA_SCALE,
        ..EkfParams::default()
    };
    let ekf = CvEkf::new(0.0, Vec3::zeros(), params).unwrap();
    let e = ekf.forecast(ObstacleShape::Sphere, 0.5, 0.1).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, PredictError::Derived { .. }), "{e:?}");
    assert!(msg.contains("ekf.sigma_scale"), "{msg}");
    assert!(!msg.contains("forecast.r_safe"), "{msg}");
}

#[test]
fn ekf_time_cannot_run_past_the_policy() {
    let mut ekf = CvEkf::new(0.0, Vec3::zeros(), EkfParams::default()).unwrap();
    for _ in 0..3 {
        let _ = ekf.predict(9e6);
    }
    assert!(ekf.time() <= 1e7);
    assert!(ekf.covariance().iter().all(|x| x.is_finite()));
}

#[test]
fn cv_ekf_step_names_t_not_dt_which_it_does_not_take() {
    // Issue 18: a step from t = -1e7 to t = 1e7 failed on "`dt` = 2.0e7 is outside the accepted
    // range", a field `step` does not take. Both times are inside the policy: the step succeeds.
    let mut ekf = CvEkf::new(-1e7, Vec3::zeros(), EkfParams::default()).unwrap();
    ekf.step(1e7, Some(Vec3::new(1.0, 0.0, 0.0))).unwrap();
    assert!(ekf.state().iter().all(|x| x.is_finite()));
    // A time out of the policy is named `t`.
    let e = ekf.step(2e7, None).unwrap_err().to_string();
    assert!(e.contains("`t`") && !e.contains("dt"), "{e}");
    // `predict`, which takes `dt`, names `dt` (and the filter time it started from).
    let e = ekf.predict(5e6).unwrap_err().to_string();
    assert!(e.contains("dt"), "{e}");
}

#[test]
fn ekf_params_errors_carry_each_fields_own_unit() {
    // Issue 18: accel_psd (m²/s³) and sigma_scale (dimensionless) were reported in metres.
    let e = EkfParams {
        accel_psd: -1.0,
        ..EkfParams::default()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(e.contains("ekf.accel_psd") && e.contains("m²/s³"), "{e}");
    assert!(!e.contains("] m "), "{e}");
    let e = EkfParams {
        sigma_scale: 1e300,
        ..EkfParams::default()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("ekf.sigma_scale") && e.contains("dimensionless"),
        "{e}"
    );
    assert!(e.contains("1.0e300"), "{e}");
    let e = EkfParams {
        init_vel_std: 1e5,
        ..EkfParams::default()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(e.contains("ekf.init_vel_std") && e.contains("m/s"), "{e}");
}

#[test]
fn ekf_lag_compensation_smoothing_is_checked_by_name() {
    for bad in [-0.1, f64::NAN, f64::INFINITY, 2e7] {
        let e = EkfParams {
            accel_smoothing_s: bad,
            ..EkfParams::default()
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("ekf.accel_smoothing_s") && e.contains(" s"),
            "{bad}: {e}"
        );
    }
}

#[test]
fn ekf_at_the_edges_of_its_accepted_params_forecasts_or_names_its_params() {
    // Every accepted corner: the filter runs, and a forecast either succeeds or names the EKF
    // parameters that drove the growth rate / margin out of the policy (never another field).
    let corners = |lo: f64, hi: f64| [lo, hi];
    for meas_std in corners(1e-9, 1e6) {
        for accel_psd in corners(0.0, MAX_ACCEL_PSD) {
            for init_vel_std in corners(1e-9, 1e4) {
                for (sigma_scale, manoeuvre_gate) in corners(0.0, MAX_SIGMA_SCALE)
                    .into_iter()
                    .zip([1e-9, MAX_MANOEUVRE_GATE])
                {
                    for accel_smoothing_s in [0.0, 1e-9, 0.5, 1e7] {
                        let params = EkfParams {
                            meas_std,
                            accel_psd,
                            init_vel_std,
                            sigma_scale,
                            mu_min: 1e4,
                            inflate_by_position_std: true,
                            manoeuvre_gate,
                            accel_smoothing_s,
                        };
                        let mut ekf = CvEkf::new(0.0, Vec3::zeros(), params).unwrap();
                        for k in 1..=10 {
                            let t = f64::from(k) * 1e6;
                            ekf.step(t, (k % 3 != 0).then(|| Vec3::new(1.0, 2.0, 3.0)))
                                .unwrap();
                        }
                        assert!(ekf.covariance().iter().all(|x| x.is_finite()));
                        match ekf.forecast(ObstacleShape::Sphere, 0.5, 0.1) {
                            Ok(f) => assert!(f.validate().is_ok()),
                            Err(e) => {
                                let msg = e.to_string();
                                assert!(msg.contains("ekf."), "{msg}");
                            }
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn pdc_horizon_past_the_time_limit_names_horizon_not_t_end() {
    // Fuzz (params::predict::Forecast+Pdc): `Pdc::new(f, 1.00001e7)` failed on "`t_end` =
    // 1.00001e7 is outside the accepted range", a name the caller never used.
    let f = Forecast::sphere(Vec3::zeros(), Vec3::zeros(), 0.0, 0.5, 0.1, 0.2).unwrap();
    let e = f.pdc(1.00001e7).unwrap_err().to_string();
    assert!(e.contains("horizon"), "{e}");
    assert!(!e.contains("`t_end`"), "{e}");
    assert!(f.pdc(1e7).is_ok());
}

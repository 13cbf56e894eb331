//! Public-API tests of `trust_vehicle`: the shared contract of every `Vehicle`, the measured
//! tracking bounds on the figure-eights, limits, degenerate inputs and serde.

use approx::assert_relative_eq;
use proptest::prelude::*;
use trust_core::{PolyTraj, Vec3};
use trust_vehicle::{
    ControlledQuadrotor, FigureEight, PerfectTracking, Quadrotor, QuadrotorParams, Reference,
    Se3Controller, Se3Gains, Vehicle, VehicleError, VehicleState, tracking_error,
};

const DT: f64 = 0.002;

fn quad_on(r: &Reference) -> ControlledQuadrotor {
    ControlledQuadrotor::starting_on(QuadrotorParams::default(), Se3Gains::default(), 0.0, r)
        .unwrap()
}

/// Every implementation, built to start on `r` at t = 0.
fn every_vehicle(r: &Reference) -> Vec<Box<dyn Vehicle>> {
    vec![
        Box::new(quad_on(r)),
        Box::new(PerfectTracking::new(0.0, r).unwrap()),
    ]
}

fn assert_finite(s: &VehicleState) {
    assert!(s.validate().is_ok(), "non-finite state {s:?}");
}

fn bits(s: &VehicleState) -> Vec<u64> {
    let q = s.attitude.quaternion();
    [s.t, q.w, q.i, q.j, q.k]
        .into_iter()
        .chain(s.p.iter().copied())
        .chain(s.v.iter().copied())
        .chain(s.a.iter().copied())
        .chain(s.body_rate.iter().copied())
        .map(f64::to_bits)
        .collect()
}

// ---- The shared contract, run against every implementation ----------------------------------

#[test]
fn every_vehicle_is_deterministic() {
    let fig = FigureEight::aggressive();
    // A plan with a hole of NaNs in the middle exercises the fallback paths too.
    let reference = |t: f64| {
        if (3.0..3.1).contains(&t) {
            Reference::hover(Vec3::repeat(f64::NAN))
        } else {
            fig.reference(t)
        }
    };
    let runs = |_| {
        let mut out = Vec::new();
        for mut v in every_vehicle(&fig.reference(0.0)) {
            for _ in 0..3000 {
                v.step(DT, &reference).unwrap();
                out.push(bits(v.state()));
            }
        }
        out
    };
    assert_eq!(runs(0), runs(1));
}

#[test]
fn every_vehicle_advances_time_by_dt() {
    let fig = FigureEight::gentle();
    let reference = |t: f64| fig.reference(t);
    for mut v in every_vehicle(&fig.reference(0.0)) {
        for k in 1..=1000 {
            let t0 = v.state().t;
            v.step(DT, &reference).unwrap();
            assert_relative_eq!(v.state().t, t0 + DT, max_relative = 1e-15);
            assert_relative_eq!(v.state().t, f64::from(k) * DT, max_relative = 1e-12);
        }
    }
}

#[test]
fn every_vehicle_rejects_bad_dt_and_keeps_its_state() {
    let r = Reference::hover(Vec3::new(1.0, 2.0, 3.0));
    for mut v in every_vehicle(&r) {
        let before = bits(v.state());
        for dt in [0.0, -0.002, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let err = v.step(dt, &|_| r).unwrap_err();
            assert!(
                matches!(&err, VehicleError::NonFinite { field, .. } | VehicleError::OutOfRange { field, .. } if field == "dt"),
                "{}: {err}",
                v.name()
            );
        }
        assert_eq!(bits(v.state()), before, "{}", v.name());
    }
}

#[test]
fn every_vehicle_survives_a_non_finite_reference() {
    let start = Reference::hover(Vec3::new(0.0, 0.0, 5.0));
    let bad = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY];
    for mut v in every_vehicle(&start) {
        for (k, x) in bad.iter().cycle().take(1500).enumerate() {
            let mut r = start;
            match k % 5 {
                0 => r.p.x = *x,
                1 => r.v.y = *x,
                2 => r.a.z = *x,
                3 => r.j.x = *x,
                _ => r.yaw = *x,
            }
            let info = v.step(DT, &|_| r).unwrap();
            assert!(info.reference_non_finite, "{}", v.name());
            assert_finite(v.state());
        }
        // It hovered where it was.
        assert_relative_eq!(v.state().p, start.p, epsilon = 1e-9);
        // And it recovers when the plan becomes finite again.
        let next = Reference::hover(Vec3::new(1.0, 0.0, 5.0));
        for _ in 0..2500 {
            let info = v.step(DT, &|_| next).unwrap();
            assert!(!info.reference_non_finite);
        }
        assert_relative_eq!(v.state().p, next.p, epsilon = 1e-3);
    }
}

#[test]
fn absurd_finite_references_keep_the_state_finite() {
    let start = Reference::hover(Vec3::new(0.0, 0.0, 5.0));
    let absurd = [
        Reference::hover(Vec3::new(1e300, -1e300, 1e300)),
        Reference {
            a: Vec3::new(1e308, 0.0, -1e308),
            ..start
        },
        Reference {
            j: Vec3::new(-1e308, 1e308, 1e308),
            ..start
        },
    ];
    for r in absurd {
        let mut quad = quad_on(&start);
        for _ in 0..500 {
            quad.step(DT, &|_| r).unwrap();
            assert_finite(quad.state());
        }
    }
}

#[test]
fn every_vehicle_holds_a_static_reference() {
    let r = Reference::hover(Vec3::new(-3.0, 4.0, 7.5));
    for mut v in every_vehicle(&r) {
        for _ in 0..5000 {
            let info = v.step(DT, &|_| r).unwrap();
            assert!(!info.saturation.any());
        }
        assert_relative_eq!(v.state().p, r.p, epsilon = 1e-9);
        assert_relative_eq!(v.state().v, Vec3::zeros(), epsilon = 1e-9);
        assert_relative_eq!(v.state().a, Vec3::zeros(), epsilon = 1e-9);
    }
}

#[test]
fn every_vehicle_reports_an_acceleration_consistent_with_its_velocity() {
    // The run log's `a` is checked against the limits by an independent program: it must be the
    // derivative of the logged velocity (trapezoidal rule over one step). The logged `a` is the
    // end-of-step acceleration and the thrust is held per step, so they differ by O(dt · jerk):
    // measured 0.011 m/s² for the quadrotor on the aggressive figure-eight (0.07 % of a_max).
    let fig = FigureEight::aggressive();
    let reference = |t: f64| fig.reference(t);
    for mut v in every_vehicle(&fig.reference(0.0)) {
        let mut prev = *v.state();
        let mut worst = 0.0f64;
        for _ in 0..(3.0 * fig.period_s / DT) as usize {
            v.step(DT, &reference).unwrap();
            let s = *v.state();
            let dv = (s.v - prev.v) / DT;
            worst = worst.max((dv - 0.5 * (s.a + prev.a)).norm());
            prev = s;
        }
        assert!(worst < 0.03, "{}: {worst}", v.name());
    }
}

// ---- Tracking error on the figure-eights (numbers quoted in the module docs) -----------------

#[test]
fn gentle_figure_eight_is_tracked_to_a_few_millimetres() {
    // Measured (default vehicle, 500 Hz, 3 laps): RMS 0.86 mm, max 1.13 mm, RMS velocity 1.2 mm/s.
    let fig = FigureEight::gentle();
    let reference = |t: f64| fig.reference(t);
    let mut quad = quad_on(&reference(0.0));
    let r = tracking_error(&mut quad, &reference, 3.0 * fig.period_s, DT).unwrap();
    assert_eq!(r.step_count, 13_500);
    assert!(r.rms_position_m < 0.003, "{r:?}");
    assert!(r.max_position_m < 0.005, "{r:?}");
    assert!(r.rms_velocity_m_s < 0.005, "{r:?}");
    assert_eq!(r.saturated_step_count, 0);
    assert_relative_eq!(r.max_speed_m_s, fig.peak_speed(), max_relative = 0.01);
}

#[test]
fn aggressive_figure_eight_is_tracked_to_a_centimetre() {
    // Measured: RMS 5.1 mm, max 7.3 mm, RMS velocity 12 mm/s, max 27 mm/s; no limit reached.
    let fig = FigureEight::aggressive();
    let reference = |t: f64| fig.reference(t);
    let mut quad = quad_on(&reference(0.0));
    let r = tracking_error(&mut quad, &reference, 3.0 * fig.period_s, DT).unwrap();
    assert!(r.rms_position_m < 0.015, "{r:?}");
    assert!(r.max_position_m < 0.02, "{r:?}");
    assert!(r.rms_velocity_m_s < 0.04, "{r:?}");
    assert!(r.max_velocity_m_s < 0.08, "{r:?}");
    assert_eq!(r.saturated_step_count, 0);
    assert!(
        r.max_speed_m_s > 9.4 && r.max_acceleration_m_s2 > 12.5,
        "{r:?}"
    );
    let params = QuadrotorParams::default();
    let f = r.max_thrust_n.unwrap();
    assert!(
        f > params.mass_kg * 15.0 && f < params.max_thrust_n,
        "{r:?}"
    );
}

#[test]
fn perfect_tracking_reproduces_the_reference_exactly() {
    let fig = FigureEight::aggressive();
    let reference = |t: f64| fig.reference(t);
    let mut v = PerfectTracking::new(0.0, &reference(0.0)).unwrap();
    for _ in 0..5000 {
        let info = v.step(DT, &reference).unwrap();
        assert!(info.command.is_none() && !info.saturation.any());
        let s = v.state();
        let r = reference(s.t);
        // Copied, not computed: exact equality is the contract.
        assert_eq!((s.p, s.v, s.a), (r.p, r.v, r.a));
        assert_relative_eq!(
            s.attitude * Vec3::z(),
            (r.a + Vec3::z() * 9.81).normalize(),
            epsilon = 1e-12
        );
    }
    let report = tracking_error(&mut v, &reference, 10.0, DT).unwrap();
    assert_eq!((report.rms_position_m, report.max_velocity_m_s), (0.0, 0.0));
}

// ---- Controller behaviour --------------------------------------------------------------------

#[test]
fn hover_converges_from_an_offset() {
    let target = Reference::hover(Vec3::new(0.0, 0.0, 5.0));
    let mut start = target;
    start.p += Vec3::new(0.5, -0.3, 0.4);
    let mut quad = quad_on(&start);
    let mut worst = 0.0f64;
    for _ in 0..2500 {
        quad.step(DT, &|_| target).unwrap();
        worst = worst.max((quad.state().p - target.p).norm());
    }
    // Damping 0.7: no large overshoot, settled after 5 s.
    assert!(worst < 0.71, "{worst}");
    assert_relative_eq!(quad.state().p, target.p, epsilon = 1e-3);
    assert_relative_eq!(quad.state().attitude.angle(), 0.0, epsilon = 1e-3);
}

#[test]
fn constant_velocity_is_tracked() {
    let p0 = Vec3::new(-20.0, 5.0, 3.0);
    let vel = Vec3::new(8.0, -3.0, 1.0);
    let line = move |t: f64| Reference {
        p: p0 + vel * t,
        v: vel,
        a: Vec3::zeros(),
        j: Vec3::zeros(),
        yaw: 0.0,
    };
    // Starting on it: stays on it.
    let mut quad = quad_on(&line(0.0));
    let r = tracking_error(&mut quad, &line, 5.0, DT).unwrap();
    assert!(r.max_position_m < 1e-9, "{r:?}");
    // Starting 1 m off and at rest (9 m/s behind, so the feedback caps act): converges.
    let mut off = line(0.0);
    off.p += Vec3::new(0.0, 1.0, 0.0);
    off.v = Vec3::zeros();
    let mut quad = quad_on(&off);
    tracking_error(&mut quad, &line, 8.0, DT).unwrap();
    let s = *quad.state();
    assert_relative_eq!(s.p, line(s.t).p, epsilon = 1e-3);
    assert_relative_eq!(s.v, vel, epsilon = 1e-3);
}

#[test]
fn limits_are_never_exceeded() {
    // A 30 m step of the reference whose first second also asks for an impossible 30 m/s² climb
    // saturates the thrust; lowered rate or torque limits saturate those (the default gains never
    // reach the default torque and rate limits).
    let default = QuadrotorParams::default();
    let low_rate = QuadrotorParams {
        max_body_rate_rad_s: Vec3::new(3.0, 3.0, 1.0),
        ..default
    };
    let low_torque = QuadrotorParams {
        max_torque_n_m: Vec3::new(0.05, 0.05, 0.01),
        ..default
    };
    let start = Reference::hover(Vec3::zeros());
    let mut far = Reference::hover(Vec3::new(30.0, -10.0, 8.0));
    far.yaw = 1.5;
    let mut climb = far;
    climb.a.z = 30.0;
    let reference = |t: f64| if t < 1.0 { climb } else { far };
    for (params, which) in [
        (default, "thrust"),
        (low_rate, "body_rate"),
        (low_torque, "torque"),
    ] {
        let mut quad =
            ControlledQuadrotor::starting_on(params, Se3Gains::default(), 0.0, &start).unwrap();
        let mut seen = trust_vehicle::Saturation::default();
        for _ in 0..10_000 {
            let info = quad.step(DT, &reference).unwrap();
            let cmd = info.command.unwrap();
            assert!(cmd.thrust <= params.max_thrust_n && cmd.thrust >= params.min_thrust_n);
            for i in 0..3 {
                assert!(cmd.torque[i].abs() <= params.max_torque_n_m[i]);
                assert!(quad.state().body_rate[i].abs() <= params.max_body_rate_rad_s[i]);
            }
            seen = seen.merge(info.saturation);
            assert_finite(quad.state());
        }
        let hit = match which {
            "thrust" => seen.thrust,
            "body_rate" => seen.body_rate,
            _ => seen.torque,
        };
        assert!(hit, "{which}: {seen:?}");
        // Saturated, but still stable: it arrives and turns to the heading.
        assert_relative_eq!(quad.state().p, far.p, epsilon = 1e-2);
        assert_relative_eq!(
            quad.state().attitude.euler_angles().2,
            far.yaw,
            epsilon = 1e-2
        );
    }
}

#[test]
fn a_reference_below_free_fall_saturates_at_zero_thrust_without_nan() {
    // The planner's a_max = 15 m/s² allows a downward acceleration beyond g, which a quadrotor
    // with ordinary propellers cannot produce: thrust clamps to min_thrust_n.
    let start = Reference::hover(Vec3::new(0.0, 0.0, 100.0));
    let dive = move |t: f64| Reference {
        p: start.p + Vec3::new(0.0, 0.0, -7.5 * t * t),
        v: Vec3::new(0.0, 0.0, -15.0 * t),
        a: Vec3::new(0.0, 0.0, -15.0),
        j: Vec3::new(3.0, 0.0, 0.0),
        yaw: 0.0,
    };
    let mut quad = quad_on(&start);
    let mut saw_min = false;
    for _ in 0..500 {
        let info = quad.step(DT, &dive).unwrap();
        saw_min |= info.command.unwrap().thrust == QuadrotorParams::default().min_thrust_n;
        assert_finite(quad.state());
    }
    assert!(saw_min);
    // Exactly free fall on the reference: attitude undefined, still finite.
    let fall = move |t: f64| Reference {
        p: start.p + Vec3::new(0.0, 0.0, -4.905 * t * t),
        v: Vec3::new(0.0, 0.0, -9.81 * t),
        a: Vec3::new(0.0, 0.0, -9.81),
        j: Vec3::zeros(),
        yaw: 0.0,
    };
    for mut v in every_vehicle(&fall(0.0)) {
        for _ in 0..500 {
            v.step(DT, &fall).unwrap();
            assert_finite(v.state());
        }
    }
}

#[test]
fn the_controller_model_is_separate_from_the_body() {
    // A controller that believes the vehicle is 10 % lighter settles below the reference by
    // (m_true / m_model − 1) g / k_x, the steady state of a controller without integral action.
    let params = QuadrotorParams::default();
    let mut model = params;
    model.mass_kg *= 0.9;
    let target = Reference::hover(Vec3::new(0.0, 0.0, 5.0));
    let body = Quadrotor::new(params, VehicleState::hover(0.0, target.p)).unwrap();
    let gains = Se3Gains::default();
    let controller = Se3Controller::new(gains, &model).unwrap();
    let mut quad = ControlledQuadrotor::new(body, controller);
    for _ in 0..5000 {
        quad.step(DT, &|_| target).unwrap();
    }
    let sag = (1.0 / 0.9 - 1.0) * params.gravity_m_s2 / gains.k_x;
    assert_relative_eq!(quad.state().p.z, target.p.z - sag, epsilon = 1e-6);
}

#[test]
fn long_steps_are_split_into_physics_steps() {
    let fig = FigureEight::aggressive();
    let reference = |t: f64| fig.reference(t);
    let mut coarse = quad_on(&reference(0.0));
    let mut fine = quad_on(&reference(0.0));
    for _ in 0..300 {
        let info = coarse.step(0.01, &reference).unwrap();
        assert_eq!(info.substep_count, 5);
        for _ in 0..5 {
            assert_eq!(fine.step(DT, &reference).unwrap().substep_count, 1);
        }
    }
    assert_relative_eq!(coarse.state().t, fine.state().t, epsilon = 1e-12);
    assert_relative_eq!(coarse.state().p, fine.state().p, epsilon = 1e-9);
    // A 1 ms physics step tracks at least as well.
    let mut finer = quad_on(&reference(0.0)).with_max_substep(0.001).unwrap();
    let r = tracking_error(&mut finer, &reference, 7.0, DT).unwrap();
    assert!(r.rms_position_m < 0.015, "{r:?}");
    assert!(quad_on(&reference(0.0)).with_max_substep(0.0).is_err());
    // A step so long it would take more than 10⁷ physics steps is refused.
    assert!(coarse.step(1e6, &reference).is_err());
}

// ---- Construction, validation, serde ---------------------------------------------------------

#[test]
fn invalid_inputs_are_typed_errors_naming_the_field() {
    let r = Reference::hover(Vec3::zeros());
    let mut params = QuadrotorParams::default();
    params.inertia_kg_m2.x = 0.0;
    let err = ControlledQuadrotor::starting_on(params, Se3Gains::default(), 0.0, &r).unwrap_err();
    assert_eq!(
        err,
        VehicleError::OutOfRange {
            field: "inertia_kg_m2.x".into(),
            value: 0.0,
            expected: "a finite number > 0".into()
        }
    );
    let params = QuadrotorParams {
        min_thrust_n: 28.0,
        ..Default::default()
    };
    assert!(
        params
            .validate()
            .unwrap_err()
            .to_string()
            .contains("min_thrust_n")
    );
    let gains = Se3Gains {
        k_r: 0.0,
        ..Se3Gains::default()
    };
    let err =
        ControlledQuadrotor::starting_on(QuadrotorParams::default(), gains, 0.0, &r).unwrap_err();
    assert!(err.to_string().contains("k_r"), "{err}");
    let mut nan = r;
    nan.v.y = f64::NAN;
    assert!(
        PerfectTracking::new(0.0, &nan)
            .unwrap_err()
            .to_string()
            .contains("reference.v.y")
    );
    assert!(PerfectTracking::new(f64::INFINITY, &r).is_err());
    let mut state = VehicleState::hover(0.0, Vec3::zeros());
    state.body_rate.z = f64::NAN;
    let err = Quadrotor::new(QuadrotorParams::default(), state).unwrap_err();
    assert!(err.to_string().contains("state.body_rate.z"), "{err}");
    let report = tracking_error(&mut quad_on(&r), &|_| r, -1.0, DT);
    assert!(report.unwrap_err().to_string().contains("duration_s"));
}

#[test]
fn params_and_gains_deserialize_with_defaults_and_reject_unknown_fields() {
    let p: QuadrotorParams = serde_json::from_str(r#"{"mass_kg": 1.2}"#).unwrap();
    assert_relative_eq!(p.mass_kg, 1.2);
    assert_eq!(p.inertia_kg_m2, QuadrotorParams::default().inertia_kg_m2);
    assert!(serde_json::from_str::<QuadrotorParams>(r#"{"mass": 1.2}"#).is_err());
    let g: Se3Gains = serde_json::from_str(r#"{"k_x": 9.0}"#).unwrap();
    assert_relative_eq!(g.k_v, Se3Gains::default().k_v);
    assert!(serde_json::from_str::<Se3Gains>(r#"{"kx": 9.0}"#).is_err());
    // (serde_json's default float parser may be off by one ulp, hence the tolerances.)
    let d = QuadrotorParams::default();
    let back: QuadrotorParams = serde_json::from_str(&serde_json::to_string(&d).unwrap()).unwrap();
    assert_relative_eq!(back.max_thrust_n, d.max_thrust_n, max_relative = 1e-15);
    assert_relative_eq!(back.max_torque_n_m, d.max_torque_n_m, max_relative = 1e-15);
    assert_relative_eq!(back.inertia_kg_m2, d.inertia_kg_m2, max_relative = 1e-15);
    let fig = FigureEight::aggressive();
    let s = VehicleState::on_reference(1.5, &fig.reference(1.5), 9.81).unwrap();
    let back: VehicleState = serde_json::from_str(&serde_json::to_string(&s).unwrap()).unwrap();
    assert_relative_eq!(back.attitude, s.attitude, epsilon = 1e-15);
    assert_relative_eq!(back.t, s.t, max_relative = 1e-15);
    assert_relative_eq!(back.p, s.p, max_relative = 1e-15);
    assert_relative_eq!(back.a, s.a, max_relative = 1e-15);
}

#[test]
fn references_sample_planned_trajectories() {
    let traj = PolyTraj::hold(2.0, Vec3::new(1.0, 2.0, 3.0), 4.0).unwrap();
    let r = Reference::from_traj(&traj, 3.0, 0.25);
    assert_eq!(r.p, Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(
        (r.v, r.a, r.j),
        (Vec3::zeros(), Vec3::zeros(), Vec3::zeros())
    );
    assert_relative_eq!(r.yaw, 0.25);
    let s = VehicleState::on_reference(3.0, &r, 9.81).unwrap();
    assert_relative_eq!(s.attitude.euler_angles().2, 0.25, epsilon = 1e-12);
    assert_eq!(s.kinematic().p, r.p);
}

// ---- Property: arbitrary bounded plans never break the state ---------------------------------

fn bounded_vec(bound: f64) -> impl Strategy<Value = Vec3> {
    (-bound..bound, -bound..bound, -bound..bound).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn bounded_reference() -> impl Strategy<Value = Reference> {
    (
        bounded_vec(50.0),
        bounded_vec(10.0),
        bounded_vec(15.0),
        bounded_vec(200.0),
        -4.0..4.0f64,
    )
        .prop_map(|(p, v, a, j, yaw)| Reference { p, v, a, j, yaw })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn jumping_plans_keep_the_state_finite_and_within_limits(
        plan in proptest::collection::vec(bounded_reference(), 4),
    ) {
        let params = QuadrotorParams::default();
        let mut quad = quad_on(&Reference::hover(Vec3::zeros()));
        // A new arbitrary reference every 0.5 s.
        let reference = |t: f64| plan[((t / 0.5) as usize).min(plan.len() - 1)];
        for _ in 0..1000 {
            let info = quad.step(DT, &reference).unwrap();
            let s = quad.state();
            prop_assert!(s.validate().is_ok());
            prop_assert!(info.command.unwrap().thrust <= params.max_thrust_n);
            for i in 0..3 {
                prop_assert!(s.body_rate[i].abs() <= params.max_body_rate_rad_s[i]);
            }
            prop_assert!(s.a.norm() <= params.max_thrust_n / params.mass_kg + params.gravity_m_s2 + 1e-9);
        }
    }
}

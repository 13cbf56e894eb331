//! The backend contract of issue 18 (trust-core crate docs): every accepted parameter solves
//! (no "cost = inf" / NaN / error about another field), an `Ok` that violates the request says
//! so in `Solution::violations`, and errors name the true culprit. Tests named after the defect.

use trust_core::{
    Aabb, GuidePath, InitialGuess, Limits, PlanError, PolyTraj, Scene, State, StaticMap,
    TrajRequest, TrajectoryBackend, Vec3, Violation,
};
use trust_geometry::{Shape, Sphere};
use trust_minco::backend::{Minco, MincoParams, UtfMinco, UtfMincoParams};
use trust_minco::scenes::{e2_dynamic, e2_static};

fn request<'a>(start: State, goal: Vec3, limits: Limits, guide: &'a GuidePath) -> TrajRequest<'a> {
    TrajRequest {
        start,
        goal,
        limits,
        initial: InitialGuess::Guide(guide),
        deadline: None,
        horizon_s: None,
        max_evaluations: Some(60),
    }
}

/// `(field path, value)` at both ends of every float field's accepted range.
fn edges() -> Vec<(&'static str, f64)> {
    vec![
        ("weights.time", 1e-6),
        ("weights.time", 1e6),
        ("weights.terminal", 0.0),
        ("weights.terminal", 1e6),
        ("weights.obstacle", 0.0),
        ("weights.obstacle", 1e6),
        ("weights.feasibility", 0.0),
        ("weights.feasibility", 1e6),
        ("weights.energy", 0.0),
        ("weights.energy", 1e6),
        ("penalty.smoothing", 1e-9),
        ("penalty.smoothing", 1.0),
        ("penalty.dynamic_clearance_m", 0.0),
        ("penalty.dynamic_clearance_m", 1e6),
        ("penalty.static_clearance_m", 0.0),
        ("penalty.static_clearance_m", 1e6),
        ("penalty.goal_radius_m", 1e-9),
        ("penalty.goal_radius_m", 1e6),
        ("penalty.terminal_norm_epsilon", 1e-6),
        ("penalty.terminal_norm_epsilon", 1e6),
        ("penalty.guidance_smoothing_m", 1e-9),
        ("penalty.guidance_smoothing_m", 1e6),
        ("penalty.braking_tail_decel_fraction", 1e-300),
        ("penalty.braking_tail_delay_s", 0.0),
        ("penalty.braking_tail_delay_s", 1e7),
        ("pieces.target_piece_length_m", 1e-9),
        ("pieces.target_piece_length_m", 1e6),
        ("pieces.min_piece_duration_s", 1e-9),
        ("pieces.min_piece_duration_s", 10.0),
    ]
}

fn set<T: serde::Serialize + serde::de::DeserializeOwned>(params: &T, path: &str, v: f64) -> T {
    let mut json = serde_json::to_value(params).unwrap();
    let mut slot = &mut json;
    for key in path.split('.') {
        slot = slot.get_mut(key).unwrap();
    }
    *slot = serde_json::Value::from(v);
    serde_json::from_value(json).unwrap()
}

#[test]
fn every_accepted_parameter_edge_solves_without_an_error_about_something_else() {
    // Issue 18: extreme but accepted `weights.time`, `penalty.terminal_norm_epsilon`,
    // `penalty.dynamic_clearance_m` and `pieces.min_piece_duration_s` made the solve fail with
    // "cost at the start point = inf", "g[0] = NaN" or an error naming `limits.v_max`.
    for case in [e2_static(), e2_dynamic()] {
        let guide = case.guide();
        let mut req = request(case.start, case.goal, case.limits, &guide);
        for (field, v) in edges() {
            for horizon in [None, Some(2.0)] {
                req.horizon_s = horizon;
                let u = UtfMinco::new(set(&UtfMincoParams::default(), field, v))
                    .unwrap_or_else(|e| panic!("{field} = {v:e} rejected: {e}"));
                let m = Minco::new(set(&MincoParams::default(), field, v))
                    .unwrap_or_else(|e| panic!("{field} = {v:e} rejected: {e}"));
                for backend in [&u as &dyn TrajectoryBackend, &m] {
                    match backend.optimize(&req, &case.scene()) {
                        Ok(sol) => assert!(
                            sol.costs.total.is_finite(),
                            "{} {} {field} = {v:e}",
                            case.name,
                            backend.name()
                        ),
                        Err(e) => panic!(
                            "{} {} {field} = {v:e} horizon {horizon:?}: {e}",
                            case.name,
                            backend.name()
                        ),
                    }
                }
            }
        }
    }
}

#[test]
fn parameters_outside_their_range_are_rejected_naming_the_field() {
    for (field, v) in [
        ("weights.time", 1e300),
        ("weights.time", 0.0),
        ("penalty.terminal_norm_epsilon", 1e-300),
        ("penalty.dynamic_clearance_m", 1e300),
        ("penalty.smoothing", 1e300),
        ("pieces.min_piece_duration_s", 1e6),
    ] {
        for e in [
            UtfMinco::new(set(&UtfMincoParams::default(), field, v)).unwrap_err(),
            Minco::new(set(&MincoParams::default(), field, v)).unwrap_err(),
        ] {
            let msg = e.to_string();
            assert!(msg.contains(&format!("params.{field}")), "{field}: {msg}");
            assert!(!msg.contains("v_max") && msg.len() < 220, "{msg}");
        }
    }
}

fn ball_map() -> StaticMap {
    let bounds = Aabb::new(Vec3::new(0.0, -5.0, -5.0), Vec3::new(20.0, 5.0, 5.0)).unwrap();
    let ball = Shape::Sphere(Sphere::new(Vec3::new(10.0, 0.0, 0.0), 2.0).unwrap());
    StaticMap::from_shapes(bounds, vec![ball]).unwrap()
}

#[test]
fn ok_solve_through_a_static_sphere_reports_the_penetration() {
    // Issue 18: a UTF-MINCO solve with an extreme `penalty.smoothing` returned `Ok` (Stalled)
    // 0.98 m inside a static sphere without saying so. Such a smoothing is now rejected; an
    // accepted setting that still ends inside (no obstacle weight) must report it.
    let map = ball_map();
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let guide = GuidePath::new(vec![Vec3::new(1.0, 0.0, 0.0), Vec3::new(19.0, 0.0, 0.0)]).unwrap();
    let req = request(
        State::at_rest(0.0, Vec3::new(1.0, 0.0, 0.0)),
        Vec3::new(19.0, 0.0, 0.0),
        Limits::default(),
        &guide,
    );
    let mut p = UtfMincoParams::default();
    p.weights.obstacle = 0.0;
    let sol = UtfMinco::new(p).unwrap().optimize(&req, &scene).unwrap();
    let depth = sol
        .violations
        .iter()
        .find_map(|v| match v {
            Violation::StaticPenetration { depth_m, .. } => Some(*depth_m),
            _ => None,
        })
        .unwrap_or_else(|| panic!("no penetration reported: {:?}", sol.violations));
    assert!(depth > 1.0, "{depth}");
    assert!(!sol.is_clean());
    let text = sol.violations[0].to_string();
    assert!(
        text.contains("static map") && text.contains(" m deep"),
        "{text}"
    );
}

#[test]
fn minco_warm_started_outside_the_map_is_an_error_naming_the_terminal() {
    // Issue 18: a `Minco` solve warm-started outside the map returned `Ok` ending 30 m outside
    // the bounds at 9.8 m/s against a 3 m/s limit, without saying so.
    let map = ball_map();
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let mut piece = [Vec3::zeros(); 6];
    piece[0] = Vec3::new(1.0, 0.0, 0.0);
    piece[1] = Vec3::new(10.0, 0.0, 0.0);
    let warm = PolyTraj::new(0.0, vec![5.0], vec![piece]).unwrap(); // ends at x = 51
    let req = TrajRequest {
        start: State::at_rest(0.0, Vec3::new(1.0, 0.0, 0.0)),
        goal: Vec3::new(19.0, 0.0, 0.0),
        limits: Limits::new(3.0, 5.0).unwrap(),
        initial: InitialGuess::WarmStart(&warm),
        deadline: None,
        horizon_s: None,
        max_evaluations: Some(100),
    };
    let e = Minco::default().optimize(&req, &scene).unwrap_err();
    assert!(matches!(e, PlanError::OutOfBounds { .. }), "{e:?}");
    assert!(e.to_string().contains("warm start"), "{e}");
    // UTF-MINCO has a free terminal: it may solve, but an `Ok` must report what it violates.
    if let Ok(sol) = UtfMinco::default().optimize(&req, &scene) {
        let (v, _) = sol.traj.max_speed_and_acceleration(64);
        let outside = sol
            .traj
            .sample_positions(0.01)
            .unwrap()
            .iter()
            .any(|(_, p)| !map.bounds().contains(p));
        assert_eq!(
            v > 3.0 + 1e-9,
            sol.violations
                .iter()
                .any(|x| matches!(x, Violation::OverSpeed { .. })),
            "{:?}",
            sol.violations
        );
        assert_eq!(
            outside,
            sol.violations
                .iter()
                .any(|x| matches!(x, Violation::LeavesBounds { .. })),
            "{:?}",
            sol.violations
        );
    }
}

#[test]
fn ok_solve_over_the_speed_limit_reports_it() {
    let map = ball_map();
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let guide = GuidePath::new(vec![Vec3::new(1.0, 4.0, 0.0), Vec3::new(19.0, 4.0, 0.0)]).unwrap();
    let req = request(
        State::at_rest(0.0, Vec3::new(1.0, 4.0, 0.0)),
        Vec3::new(19.0, 4.0, 0.0),
        Limits::new(2.0, 15.0).unwrap(),
        &guide,
    );
    let mut p = MincoParams::default();
    p.weights.feasibility = 0.0;
    p.weights.time = 1e4;
    let sol = Minco::new(p).unwrap().optimize(&req, &scene).unwrap();
    let over = sol.violations.iter().find_map(|v| match v {
        Violation::OverSpeed { v, v_max, .. } => Some((*v, *v_max)),
        _ => None,
    });
    let (v, v_max) = over.unwrap_or_else(|| panic!("{:?}", sol.violations));
    assert!(v > 2.0 && v_max == 2.0, "{v} {v_max}");
}

#[test]
fn start_time_near_the_time_limit_names_request_start_t_not_traj_t_end() {
    // Issue 18: a start time near the scale policy's 1e7 s was reported as `traj.t_end`.
    let map = ball_map();
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let guide = GuidePath::new(vec![Vec3::new(1.0, 4.0, 0.0), Vec3::new(19.0, 4.0, 0.0)]).unwrap();
    let req = request(
        State::at_rest(1e7 - 1.0, Vec3::new(1.0, 4.0, 0.0)),
        Vec3::new(19.0, 4.0, 0.0),
        Limits::default(),
        &guide,
    );
    for backend in [
        &UtfMinco::default() as &dyn TrajectoryBackend,
        &Minco::default(),
    ] {
        let e = backend.optimize(&req, &scene).unwrap_err().to_string();
        assert!(e.contains("request.start.t"), "{}: {e}", backend.name());
        assert!(!e.contains("`traj."), "{e}");
    }
}

//! Public-API tests of the two trajectory backends on the E2 scenes (design.md §5) and on
//! degenerate requests: validity of the returned trajectory (starts at the start state, within
//! the limits, clear of every obstacle at dense times), typed errors for invalid input,
//! budgets, determinism and warm starts.

use std::time::Instant;

use trust_core::{
    Aabb, Forecast, GuidePath, InitialGuess, Limits, PlanError, PolyTraj, Scene, Solution,
    SolveStatus, State, StaticMap, TrajRequest, TrajectoryBackend, Vec3,
};
use trust_minco::backend::{Minco, MincoParams, UtfMinco, UtfMincoParams};
use trust_minco::scenes::{E2Case, e2_dynamic, e2_static};

fn request<'a>(case: &E2Case, guide: &'a GuidePath) -> TrajRequest<'a> {
    TrajRequest {
        start: case.start,
        goal: case.goal,
        limits: case.limits,
        initial: InitialGuess::Guide(guide),
        deadline: None,
        horizon_s: None,
        max_evaluations: None,
    }
}

/// Smallest clearance (static map and forecasts) every 5 ms along the trajectory.
fn min_clearance(scene: &Scene<'_>, traj: &PolyTraj) -> f64 {
    let mut worst = f64::INFINITY;
    traj.for_each_sample(0.005, |t, s| worst = worst.min(scene.clearance(&s.p, t)))
        .expect("positive dt");
    worst
}

/// Checks everything a caller relies on: finite, starts at `start`, within the limits (5 %),
/// clear of obstacles, cost breakdown finite and consistent with the weights.
fn assert_valid(
    solution: &Solution,
    start: &State,
    limits: &Limits,
    scene: &Scene<'_>,
    what: &str,
) {
    let traj = &solution.traj;
    assert_eq!(traj.t_start(), start.t, "{what}: start time");
    let s0 = traj.state(start.t);
    assert!(
        (s0.p - start.p).norm() < 1e-9,
        "{what}: start position {:?}",
        s0.p
    );
    assert!(
        (s0.v - start.v).norm() < 1e-9,
        "{what}: start velocity {:?}",
        s0.v
    );
    assert!(
        (s0.a - start.a).norm() < 1e-8,
        "{what}: start acceleration {:?}",
        s0.a
    );
    assert!(traj.duration() > 0.0 && traj.duration().is_finite());
    let (v, a) = traj.max_speed_and_acceleration(64);
    assert!(v <= 1.05 * limits.v_max, "{what}: speed {v}");
    assert!(a <= 1.05 * limits.a_max, "{what}: acceleration {a}");
    let clearance = min_clearance(scene, traj);
    assert!(clearance >= 0.0, "{what}: collides (clearance {clearance})");
    let c = &solution.costs;
    for (name, value) in [
        ("ht", c.ht),
        ("hs", c.hs),
        ("io", c.io),
        ("id", c.id),
        ("ie", c.ie),
        ("total", c.total),
    ] {
        assert!(
            value.is_finite() && value >= 0.0,
            "{what}: {name} = {value}"
        );
    }
}

#[test]
fn utf_minco_solves_both_e2_cases() {
    let backend = UtfMinco::default();
    let w = &backend.params().weights;
    for case in [e2_static(), e2_dynamic()] {
        let guide = case.guide();
        let solution = backend
            .optimize(&request(&case, &guide), &case.scene())
            .expect("valid request");
        assert_valid(
            &solution,
            &case.start,
            &case.limits,
            &case.scene(),
            case.name,
        );
        let c = solution.costs;
        let total = w.combine(c.ht, c.hs, c.io, c.id, c.ie);
        assert!(
            (total - c.total).abs() <= 1e-9 * c.total,
            "{}: {total} vs {}",
            case.name,
            c.total
        );
        assert!(solution.stats.evaluation_count > 1);
        assert!(solution.stats.evaluation_count <= backend.params().solver.max_evaluations + 1);
    }
}

#[test]
fn utf_minco_reaches_a_free_goal() {
    // In the static case the goal is free: the free terminal ends on it.
    let case = e2_static();
    let guide = case.guide();
    let solution = UtfMinco::default()
        .optimize(&request(&case, &guide), &case.scene())
        .expect("valid");
    let end = solution.traj.position(solution.traj.t_end());
    assert!((end - case.goal).norm() < 0.1, "ends at {end:?}");
}

#[test]
fn minco_ends_at_rest_at_the_end_of_the_guide() {
    let case = e2_static();
    let guide = case.guide();
    let solution = Minco::default()
        .optimize(&request(&case, &guide), &case.scene())
        .expect("valid");
    assert_valid(
        &solution,
        &case.start,
        &case.limits,
        &case.scene(),
        "minco static",
    );
    let end = solution.traj.state(solution.traj.t_end());
    assert!((end.p - guide.end()).norm() < 1e-6, "{:?}", end.p);
    assert!(end.v.norm() < 1e-6 && end.a.norm() < 1e-6);
    assert_eq!(solution.costs.hs, 0.0);
}

fn empty_map() -> StaticMap {
    StaticMap::empty(Aabb {
        min: Vec3::zeros(),
        max: Vec3::new(30.0, 20.0, 10.0),
    })
    .expect("bounds")
}

fn backends() -> [Box<dyn TrajectoryBackend>; 2] {
    [Box::new(UtfMinco::default()), Box::new(Minco::default())]
}

#[test]
fn start_on_the_goal_hovers() {
    let map = empty_map();
    let scene = Scene::new(&map, &[], 0.0).expect("scene");
    let p = Vec3::new(5.0, 5.0, 5.0);
    let guide = GuidePath::new(vec![p]).expect("one point");
    let start = State::at_rest(0.0, p);
    for backend in backends() {
        let req = TrajRequest {
            start,
            goal: p,
            limits: Limits::default(),
            initial: InitialGuess::Guide(&guide),
            deadline: None,
            horizon_s: None,
            max_evaluations: None,
        };
        let solution = backend.optimize(&req, &scene).expect("valid");
        assert_valid(&solution, &start, &req.limits, &scene, backend.name());
        let mut far: f64 = 0.0;
        solution
            .traj
            .for_each_sample(0.01, |_, s| far = far.max((s.p - p).norm()))
            .expect("dt");
        assert!(far < 1e-6, "{}: drifts {far} m", backend.name());
    }
}

#[test]
fn single_point_guide_with_a_moving_start() {
    // Zero-length guide at the start while moving at 4 m/s: the trajectory must brake (MINCO) or
    // head for the goal (UTF-MINCO); both stay finite and within the limits.
    let map = empty_map();
    let scene = Scene::new(&map, &[], 0.0).expect("scene");
    let start = State {
        t: 2.0,
        p: Vec3::new(5.0, 10.0, 5.0),
        v: Vec3::new(4.0, 0.0, 0.0),
        a: Vec3::zeros(),
    };
    let guide = GuidePath::new(vec![start.p]).expect("one point");
    let goal = Vec3::new(12.0, 10.0, 5.0);
    for backend in backends() {
        let req = TrajRequest {
            start,
            goal,
            limits: Limits::default(),
            initial: InitialGuess::Guide(&guide),
            deadline: None,
            horizon_s: None,
            max_evaluations: None,
        };
        let solution = backend.optimize(&req, &scene).expect("valid");
        assert_valid(&solution, &start, &req.limits, &scene, backend.name());
    }
    let req = TrajRequest {
        start,
        goal,
        limits: Limits::default(),
        initial: InitialGuess::Guide(&guide),
        deadline: None,
        horizon_s: None,
        max_evaluations: None,
    };
    let utf = UtfMinco::default().optimize(&req, &scene).expect("valid");
    let end = utf.traj.position(utf.traj.t_end());
    assert!(
        (end - goal).norm() < 0.5,
        "UTF-MINCO heads for the goal, ends at {end:?}"
    );
}

#[test]
fn no_obstacles_straight_flight() {
    let map = empty_map();
    let scene = Scene::new(&map, &[], 0.0).expect("scene");
    let start = State::at_rest(0.0, Vec3::new(2.0, 10.0, 5.0));
    let goal = Vec3::new(28.0, 10.0, 5.0);
    let guide = GuidePath::new(vec![start.p, goal]).expect("path");
    let req = TrajRequest {
        start,
        goal,
        limits: Limits::default(),
        initial: InitialGuess::Guide(&guide),
        deadline: None,
        horizon_s: None,
        max_evaluations: None,
    };
    for backend in backends() {
        let solution = backend.optimize(&req, &scene).expect("valid");
        assert_valid(&solution, &start, &req.limits, &scene, backend.name());
        // UTF-MINCO reaches the goal at speed (α = 0 this far from the start, paper eq.
        // design-of-Hs) and its braking tail just touches the clearance of the map's bound 2 m
        // beyond the goal: a trace of I_o, nothing else.
        assert!(solution.costs.io < 1e-5, "{:?}", solution.costs);
        let end = solution.traj.position(solution.traj.t_end());
        assert!(
            (end - goal).norm() < 0.1,
            "{} ends at {end:?}",
            backend.name()
        );
        // Nearly straight: no reason to leave the line.
        let mut off: f64 = 0.0;
        solution
            .traj
            .for_each_sample(0.01, |_, s| off = off.max((s.p.yz() - start.p.yz()).norm()))
            .expect("dt");
        assert!(off < 1e-3, "{} leaves the line by {off} m", backend.name());
    }
}

#[test]
fn start_inside_a_static_obstacle_is_an_error() {
    let mut case = e2_static();
    case.start.p = Vec3::new(12.0, 10.5, 5.0); // axis of the first column
    let guide = GuidePath::new(vec![case.start.p, case.goal]).expect("path");
    for backend in backends() {
        match backend.optimize(&request(&case, &guide), &case.scene()) {
            Err(PlanError::InCollision {
                field, clearance, ..
            }) => {
                assert_eq!(field, "request.start.p");
                assert!(clearance < 0.0);
            }
            other => panic!("{}: expected InCollision, got {other:?}", backend.name()),
        }
    }
}

#[test]
fn start_inside_a_moving_obstacle_is_optimized_anyway() {
    let mut case = e2_dynamic();
    // Inside the first moving ball at t0.
    case.start.p = case.forecasts[0].center(case.t0) + Vec3::new(0.2, 0.0, 0.0);
    assert!(case.scene().dynamic_clearance(&case.start.p, case.t0) < 0.0);
    let guide = GuidePath::new(vec![case.start.p, case.goal]).expect("path");
    for backend in backends() {
        let solution = backend
            .optimize(&request(&case, &guide), &case.scene())
            .unwrap_or_else(|e| panic!("{}: {e}", backend.name()));
        assert!(solution.costs.total.is_finite());
        assert!((solution.traj.position(case.t0) - case.start.p).norm() < 1e-9);
        // It gets out: clear of everything after the first second.
        let scene = case.scene();
        let mut worst = f64::INFINITY;
        solution
            .traj
            .for_each_sample(0.01, |t, s| {
                if t > case.t0 + 1.0 {
                    worst = worst.min(scene.clearance(&s.p, t));
                }
            })
            .expect("dt");
        if backend.name() == "utf-minco" {
            assert!(worst >= 0.0, "still in collision after 1 s: {worst}");
        }
    }
}

fn expect_invalid(result: Result<Solution, PlanError>, field: &str) {
    match result {
        Err(PlanError::InvalidInput { field: f, .. }) => assert_eq!(f, field),
        other => panic!("expected InvalidInput on {field}, got {other:?}"),
    }
}

#[test]
fn non_finite_requests_name_the_field() {
    let case = e2_static();
    let guide = case.guide();
    let scene = case.scene();
    for backend in backends() {
        let mut req = request(&case, &guide);
        req.start.v.y = f64::NAN;
        expect_invalid(backend.optimize(&req, &scene), "request.start.v");
        let mut req = request(&case, &guide);
        req.goal.x = f64::INFINITY;
        expect_invalid(backend.optimize(&req, &scene), "request.goal");
        let mut req = request(&case, &guide);
        req.limits.a_max = f64::NAN;
        expect_invalid(backend.optimize(&req, &scene), "limits.a_max");
        let mut bad_guide = guide.clone();
        bad_guide.points[1].z = f64::NAN;
        let req = TrajRequest {
            initial: InitialGuess::Guide(&bad_guide),
            ..request(&case, &guide)
        };
        expect_invalid(backend.optimize(&req, &scene), "request.initial.points[1]");
        let empty_guide = GuidePath { points: Vec::new() };
        let req = TrajRequest {
            initial: InitialGuess::Guide(&empty_guide),
            ..request(&case, &guide)
        };
        expect_invalid(backend.optimize(&req, &scene), "request.initial.points");
        let mut bad_forecasts = e2_dynamic().forecasts;
        bad_forecasts[2].r_o = -1.0;
        let bad_scene = Scene {
            forecasts: &bad_forecasts,
            ..scene
        };
        expect_invalid(
            backend.optimize(&request(&case, &guide), &bad_scene),
            "scene.forecasts[2]",
        );
    }
}

#[test]
fn start_outside_the_map_is_an_error() {
    let mut case = e2_static();
    case.start.p.z = -3.0;
    let guide = case.guide();
    for backend in backends() {
        match backend.optimize(&request(&case, &guide), &case.scene()) {
            Err(PlanError::OutOfBounds { field, .. }) => assert_eq!(field, "request.start.p"),
            other => panic!("expected OutOfBounds, got {other:?}"),
        }
    }
}

#[test]
fn invalid_parameters_are_rejected() {
    let mut p = UtfMincoParams::default();
    p.penalty.smoothing = 0.0;
    let e = UtfMinco::new(p).unwrap_err().to_string();
    assert!(e.contains("params.penalty.smoothing"), "{e}");
    let mut p = MincoParams::default();
    p.weights.energy = f64::NAN;
    let e = Minco::new(p).unwrap_err().to_string();
    assert!(e.contains("params.weights.energy"), "{e}");
}

/// Same input, same output — bit for bit (style rule 13), for every backend.
#[test]
fn solves_are_deterministic() {
    let case = e2_dynamic();
    let guide = case.guide();
    for backend in backends() {
        let a = backend
            .optimize(&request(&case, &guide), &case.scene())
            .expect("valid");
        let b = backend
            .optimize(&request(&case, &guide), &case.scene())
            .expect("valid");
        assert_eq!(a.traj, b.traj, "{}", backend.name());
        assert_eq!(a.costs, b.costs);
        assert_eq!(a.stats.iteration_count, b.stats.iteration_count);
        assert_eq!(a.stats.status, b.stats.status);
    }
}

#[test]
fn evaluation_budget_and_deadline_are_respected() {
    let case = e2_static();
    let guide = case.guide();
    let mut p = UtfMincoParams::default();
    p.solver.max_evaluations = 15;
    let solution = UtfMinco::new(p)
        .expect("valid")
        .optimize(&request(&case, &guide), &case.scene())
        .expect("valid");
    assert_eq!(solution.stats.status, SolveStatus::EvaluationLimit);
    assert!(
        solution.stats.evaluation_count <= 16,
        "{}",
        solution.stats.evaluation_count
    );
    assert!(solution.traj.duration().is_finite());

    let mut p = MincoParams::default();
    p.solver.max_evaluations = 15;
    let solution = Minco::new(p)
        .expect("valid")
        .optimize(&request(&case, &guide), &case.scene())
        .expect("valid");
    assert_eq!(solution.stats.status, SolveStatus::EvaluationLimit);

    for backend in backends() {
        let req = TrajRequest {
            deadline: Some(Instant::now()),
            horizon_s: None,
            max_evaluations: None,
            ..request(&case, &guide)
        };
        let solution = backend.optimize(&req, &case.scene()).expect("valid");
        assert_eq!(
            solution.stats.status,
            SolveStatus::TimeLimit,
            "{}",
            backend.name()
        );
        assert!(solution.stats.iteration_count <= 1);
        assert!(solution.costs.total.is_finite());
    }
}

#[test]
fn warm_start_from_a_previous_solution() {
    let case = e2_dynamic();
    let guide = case.guide();
    let backend = UtfMinco::default();
    let first = backend
        .optimize(&request(&case, &guide), &case.scene())
        .expect("valid");
    // One second later, replan from where the vehicle is, warm-started from the old plan.
    let t = case.t0 + 1.0;
    let start = first.traj.state(t);
    let req = TrajRequest {
        start,
        goal: case.goal,
        limits: case.limits,
        initial: InitialGuess::WarmStart(&first.traj),
        deadline: None,
        horizon_s: None,
        max_evaluations: None,
    };
    let second = backend.optimize(&req, &case.scene()).expect("valid");
    assert_valid(&second, &start, &case.limits, &case.scene(), "warm start");
    // It continues the old plan: arrives about when the old one did.
    assert!(
        (second.traj.t_end() - first.traj.t_end()).abs() < 1.5,
        "{} vs {}",
        second.traj.t_end(),
        first.traj.t_end()
    );
    // A warm start at or after the old trajectory's end is still valid (hover-like guess).
    let late = first.traj.state(first.traj.t_end());
    let req = TrajRequest {
        start: State {
            t: first.traj.t_end() + 3.0,
            ..late
        },
        initial: InitialGuess::WarmStart(&first.traj),
        ..req
    };
    let third = Minco::default()
        .optimize(&req, &case.scene())
        .expect("valid");
    assert!(third.costs.total.is_finite());
}

#[test]
fn forecasts_matter_only_when_near() {
    // A far-away moving obstacle changes nothing (broad phase) — the solution equals the one
    // without it, bit for bit.
    let map = empty_map();
    let far = [Forecast::sphere(
        Vec3::new(25.0, 1.0, 1.0),
        Vec3::new(0.0, -1.0, 0.0),
        0.0,
        0.5,
        0.1,
        0.0,
    )
    .expect("valid")];
    let start = State::at_rest(0.0, Vec3::new(2.0, 10.0, 5.0));
    let goal = Vec3::new(28.0, 10.0, 5.0);
    let guide = GuidePath::new(vec![start.p, goal]).expect("path");
    let req = TrajRequest {
        start,
        goal,
        limits: Limits::default(),
        initial: InitialGuess::Guide(&guide),
        deadline: None,
        horizon_s: None,
        max_evaluations: None,
    };
    let a = UtfMinco::default()
        .optimize(&req, &Scene::new(&map, &[], 0.0).expect("scene"))
        .expect("valid");
    let b = UtfMinco::default()
        .optimize(&req, &Scene::new(&map, &far, 0.0).expect("scene"))
        .expect("valid");
    assert_eq!(a.traj, b.traj);
}

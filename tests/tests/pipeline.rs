//! End-to-end tests across crates: frontend → backend → homotopy checker, through the `trust-core`
//! traits only (as `sim` and the manager will use them), plus the shared backend and checker tests
//! run against every implementation (style rule 11).

use std::time::{Duration, Instant};

use rand::SeedableRng;
use trust_core::{
    Curve, GuidePath, HomotopyChecker, InitialGuess, PathFrontend, PathQuery, PolyTraj, Rng, Scene,
    SolveStatus, TrajRequest, TrajectoryBackend,
};
use trust_minco::scenes::{E2Case, e2_dynamic, e2_static};
use trust_minco::{Minco, UtfMinco};
use trust_topo_prm::scenes::{SceneParams, random_dynamic_scene};
use trust_topo_prm::{DevPrm, Tvd, Uvd};

fn backends() -> Vec<Box<dyn TrajectoryBackend>> {
    vec![Box::new(UtfMinco::default()), Box::new(Minco::default())]
}

fn checkers() -> Vec<Box<dyn HomotopyChecker>> {
    vec![Box::new(Uvd::default()), Box::new(Tvd::default())]
}

/// Smallest clearance of `traj` against the static map over its span, sampled every 10 ms.
fn min_static_clearance(traj: &PolyTraj, scene: &Scene<'_>) -> f64 {
    let mut worst = f64::INFINITY;
    traj.for_each_sample(0.01, |_, s| worst = worst.min(scene.static_clearance(&s.p)))
        .unwrap();
    worst
}

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

#[test]
fn every_backend_solves_the_static_e2_scene_deterministically() {
    let case = e2_static();
    let guide = case.guide();
    let scene = case.scene();
    for backend in backends() {
        let a = backend.optimize(&request(&case, &guide), &scene).unwrap();
        let b = backend.optimize(&request(&case, &guide), &scene).unwrap();
        assert_eq!(
            a.traj,
            b.traj,
            "{}: same input, different output",
            backend.name()
        );
        assert!(
            (a.traj.position(a.traj.t_start()) - case.start.p).norm() < 1e-9,
            "{}: trajectory does not start at the start",
            backend.name()
        );
        let clearance = min_static_clearance(&a.traj, &scene);
        assert!(
            clearance > -1e-3,
            "{}: static clearance {clearance}",
            backend.name()
        );
        assert!(a.costs.total.is_finite() && a.costs.ht > 0.0);
    }
}

#[test]
fn every_backend_respects_a_deadline() {
    let case = e2_dynamic();
    let guide = case.guide();
    let scene = case.scene();
    for backend in backends() {
        let mut req = request(&case, &guide);
        req.deadline = Some(Instant::now());
        let t0 = Instant::now();
        let sol = backend.optimize(&req, &scene).unwrap();
        assert!(
            t0.elapsed() < Duration::from_secs(2),
            "{} ignored an expired deadline",
            backend.name()
        );
        assert_eq!(
            sol.stats.status,
            SolveStatus::TimeLimit,
            "{}",
            backend.name()
        );
        assert!(sol.costs.total.is_finite(), "{}", backend.name());
    }
}

#[test]
fn every_checker_is_reflexive_and_symmetric() {
    let case = e2_dynamic();
    let guide = case.guide();
    let scene = case.scene();
    let sol = UtfMinco::default()
        .optimize(&request(&case, &guide), &scene)
        .unwrap();
    let shifted = PolyTraj::new(
        sol.traj.t_start(),
        sol.traj.durations().to_vec(),
        sol.traj
            .pieces()
            .iter()
            .map(|p| {
                let mut q = *p;
                q[0].z += 0.05;
                q
            })
            .collect(),
    )
    .unwrap();
    for checker in checkers() {
        let same = checker.equivalent(&sol.traj, &sol.traj, &scene).unwrap();
        assert!(
            same,
            "{}: a trajectory is not equivalent to itself",
            checker.name()
        );
        let ab = checker.equivalent(&sol.traj, &shifted, &scene).unwrap();
        let ba = checker.equivalent(&shifted, &sol.traj, &scene).unwrap();
        assert_eq!(ab, ba, "{}: not symmetric", checker.name());
    }
    // TVD needs timed curves.
    assert!(Tvd::default().equivalent(&guide, &guide, &scene).is_err());
}

/// The whole hierarchy of the paper on a random E1 scene: DEV-PRM guide paths, one UTF-MINCO
/// trajectory per path, TVD to group them. Every trajectory must be finite and free of the static map;
/// at least one must keep clear of the moving obstacles.
#[test]
fn dev_prm_guides_utf_minco_to_collision_free_trajectories() {
    let mut rng = Rng::seed_from_u64(7);
    let world = random_dynamic_scene(8, &SceneParams::default(), &mut rng).unwrap();
    let scene = Scene::new(&world.map, &world.forecasts, 0.0).unwrap();
    let query: PathQuery = world.query;
    let paths = DevPrm::default()
        .search(&query, &scene, &mut rng)
        .unwrap()
        .paths;
    assert!(
        !paths.is_empty(),
        "DEV-PRM found no path on a solvable scene"
    );

    let backend = UtfMinco::default();
    let mut trajs = Vec::new();
    for path in &paths {
        let req = TrajRequest {
            start: query.start,
            goal: query.goal,
            limits: query.limits,
            initial: InitialGuess::Guide(path),
            deadline: None,
            horizon_s: None,
            max_evaluations: None,
        };
        let sol = backend.optimize(&req, &scene).unwrap();
        assert!(min_static_clearance(&sol.traj, &scene) > -1e-3);
        trajs.push(sol.traj);
    }
    let dynamic_ok = trajs.iter().any(|tr| {
        let mut worst = f64::INFINITY;
        tr.for_each_sample(0.01, |t, s| worst = worst.min(scene.clearance(&s.p, t)))
            .unwrap();
        worst > -0.05
    });
    assert!(dynamic_ok, "no trajectory avoided the moving obstacles");

    let tvd = Tvd::default();
    for tr in &trajs {
        assert!(tvd.equivalent(tr, tr, &scene).unwrap());
        assert!(Curve::length(tr) > 0.0);
    }
}

//! Public-API tests: degenerate and invalid queries, budgets, the goal guidance surface, moving
//! obstacles, and the homotopy checkers.

use rand::SeedableRng;
use trust_core::{
    Aabb, Forecast, GuidePath, HomotopyChecker, Limits, ObstacleShape, PathFrontend, PathQuery,
    PlanError, PolyTraj, Rng, Scene, State, StaticMap, Vec3,
};
use trust_geometry::{Cylinder, Shape, Sphere};
use trust_topo_prm::visibility::Obstacles;
use trust_topo_prm::{
    DevPrm, DevPrmParams, SparseAStar, SparseAStarParams, StraightLine, Tvd, Uvd, Vprm, VprmParams,
    tvd, uvd,
};

fn box_map(shapes: Vec<Shape>) -> StaticMap {
    StaticMap::from_shapes(
        Aabb::new(Vec3::zeros(), Vec3::new(20.0, 20.0, 10.0)).unwrap(),
        shapes,
    )
    .unwrap()
}

fn query(start: Vec3, goal: Vec3) -> PathQuery {
    PathQuery {
        start: State::at_rest(0.0, start),
        goal,
        limits: Limits::default(),
        horizon_s: 2.0,
        exploration: 1.0,
    }
}

/// All frontends with deterministic (sample-bound) budgets.
fn frontends() -> Vec<Box<dyn PathFrontend>> {
    vec![
        Box::new(
            Vprm::new(VprmParams {
                budget_ms: 10_000.0,
                max_samples: 400,
                ..VprmParams::default()
            })
            .unwrap(),
        ),
        Box::new(
            DevPrm::new(DevPrmParams {
                budget_ms: 10_000.0,
                max_samples: 400,
                ..DevPrmParams::default()
            })
            .unwrap(),
        ),
        Box::new(StraightLine),
        Box::new(
            SparseAStar::new(SparseAStarParams {
                budget_ms: 10_000.0,
                ..SparseAStarParams::default()
            })
            .unwrap(),
        ),
    ]
}

fn run(
    f: &dyn PathFrontend,
    map: &StaticMap,
    forecasts: &[Forecast],
    q: &PathQuery,
) -> Result<Vec<GuidePath>, PlanError> {
    let scene = Scene::new(map, forecasts, 0.0)?;
    Ok(f.search(q, &scene, &mut Rng::seed_from_u64(9))?.paths)
}

#[test]
fn vertical_start_to_goal_does_not_break_the_sampling_frame() {
    // A ball right between a start below and a goal above.
    let map = box_map(vec![Shape::from(
        Sphere::new(Vec3::new(10.0, 10.0, 5.0), 1.5).unwrap(),
    )]);
    let q = query(Vec3::new(10.0, 10.0, 1.0), Vec3::new(10.0, 10.0, 9.0));
    for f in frontends() {
        let paths = run(f.as_ref(), &map, &[], &q).unwrap();
        assert!(!paths.is_empty(), "{}", f.name());
        for p in &paths {
            assert!(
                p.points.iter().all(|x| x.iter().all(|c| c.is_finite())),
                "{}",
                f.name()
            );
        }
    }
}

#[test]
fn start_equal_to_goal_returns_the_point_without_sampling() {
    let map = box_map(vec![]);
    let p = Vec3::new(3.0, 4.0, 5.0);
    let q = query(p, p);
    for f in frontends() {
        let scene = Scene::new(&map, &[], 0.0).unwrap();
        let r = f.search(&q, &scene, &mut Rng::seed_from_u64(1)).unwrap();
        assert_eq!(
            r.paths,
            vec![GuidePath::new(vec![p, p]).unwrap()],
            "{}",
            f.name()
        );
        assert_eq!(r.stats.sample_count, 0);
    }
}

#[test]
fn paths_shorter_than_one_resolution_step_work() {
    let map = box_map(vec![]);
    let q = query(Vec3::new(3.0, 4.0, 5.0), Vec3::new(3.0, 4.0, 5.05));
    for f in frontends() {
        let paths = run(f.as_ref(), &map, &[], &q).unwrap();
        assert!(!paths.is_empty(), "{}", f.name());
        // Two tiny paths are UVD-comparable (no division by zero).
        let scene = Scene::new(&map, &[], 0.0).unwrap();
        assert!(
            Uvd::default()
                .equivalent(&paths[0], &paths[0], &scene)
                .unwrap()
        );
    }
    let a = GuidePath::new(vec![Vec3::zeros(), Vec3::new(0.01, 0.0, 0.0)]).unwrap();
    let b = GuidePath::new(vec![Vec3::zeros(), Vec3::new(0.0, 0.02, 0.0)]).unwrap();
    assert!(uvd::equivalent(&a, &b, 0.1, |_, _| true).unwrap());
}

#[test]
fn no_obstacles_gives_the_straight_segment() {
    let map = box_map(vec![]);
    let q = query(Vec3::new(1.0, 2.0, 3.0), Vec3::new(15.0, 12.0, 6.0));
    for f in frontends().into_iter().take(2) {
        let paths = run(f.as_ref(), &map, &[], &q).unwrap();
        assert_eq!(paths.len(), 1, "{}", f.name());
        assert_eq!(paths[0].points, vec![q.start.p, q.goal], "{}", f.name());
    }
}

#[test]
fn start_inside_a_cone_still_plans() {
    // An obstacle heading straight at the start: its PDC covers the start.
    let map = box_map(vec![]);
    let start = Vec3::new(2.0, 10.0, 5.0);
    let f = Forecast::sphere(
        Vec3::new(5.0, 10.0, 5.0),
        Vec3::new(-2.0, 0.0, 0.0),
        0.0,
        1.0,
        0.0,
        0.2,
    )
    .unwrap();
    let cone = trust_predict::Pdc::new(&f, 2.0).unwrap();
    assert!(cone.contains(&start));
    let q = query(start, Vec3::new(18.0, 10.0, 5.0));
    for fe in frontends() {
        let paths = run(fe.as_ref(), &map, &[f], &q).unwrap();
        assert!(!paths.is_empty(), "{}", fe.name());
    }
}

#[test]
fn devprm_paths_avoid_the_cones() {
    // A ball on the straight line, moving sideways: DEV-PRM must go around its whole sweep.
    let map = box_map(vec![]);
    let f = Forecast::new(
        ObstacleShape::Sphere,
        Vec3::new(10.0, 10.0, 5.0),
        Vec3::new(0.0, 1.0, 0.0),
        0.0,
        0.5,
        0.0,
        0.2,
    )
    .unwrap();
    let q = query(Vec3::new(1.0, 10.0, 5.0), Vec3::new(19.0, 10.0, 5.0));
    let dev = &frontends()[1];
    let paths = run(dev.as_ref(), &map, &[f], &q).unwrap();
    assert!(paths.len() >= 2, "{} paths", paths.len());
    let obs = Obstacles::with_forecast_cones(&map, &[f], 0.0, 2.0).unwrap();
    for p in &paths {
        for s in p.points.windows(2) {
            assert!(obs.segment_clear(&s[0], &s[1], 0.0), "{s:?}");
        }
    }
    // V-PRM only sees the cylinder where it is now, so its straight-ish path may cross the sweep.
    let v = &frontends()[0];
    assert!(!run(v.as_ref(), &map, &[f], &q).unwrap().is_empty());
}

#[test]
fn bad_queries_are_typed_errors() {
    let map = box_map(vec![Shape::from(
        Sphere::new(Vec3::new(5.0, 5.0, 5.0), 1.0).unwrap(),
    )]);
    let good = query(Vec3::new(1.0, 1.0, 1.0), Vec3::new(18.0, 18.0, 8.0));
    for f in frontends() {
        let name = f.name().to_string();
        let inside = PathQuery {
            goal: Vec3::new(5.0, 5.0, 5.5),
            ..good
        };
        let e = run(f.as_ref(), &map, &[], &inside).unwrap_err();
        assert!(
            matches!(&e, PlanError::InCollision { field, .. } if field == "query.goal"),
            "{name}: {e}"
        );
        let outside = PathQuery {
            start: State::at_rest(0.0, Vec3::new(-1.0, 1.0, 1.0)),
            ..good
        };
        let e = run(f.as_ref(), &map, &[], &outside).unwrap_err();
        assert!(
            matches!(&e, PlanError::OutOfBounds { field, .. } if field == "query.start.p"),
            "{name}: {e}"
        );
        let nan = PathQuery {
            goal: Vec3::new(f64::NAN, 1.0, 1.0),
            ..good
        };
        let e = run(f.as_ref(), &map, &[], &nan).unwrap_err();
        assert!(e.to_string().contains("query.goal"), "{name}: {e}");
        let no_horizon = PathQuery {
            horizon_s: 0.0,
            ..good
        };
        assert!(run(f.as_ref(), &map, &[], &no_horizon).is_err(), "{name}");
        // A forecast with NaN size (built without validation) is rejected, not ignored.
        let mut bad =
            Forecast::sphere(Vec3::new(9.0, 9.0, 5.0), Vec3::zeros(), 0.0, 1.0, 0.0, 0.1).unwrap();
        bad.mu = f64::NAN;
        let scene = Scene {
            map: &map,
            forecasts: &[bad],
            t0: 0.0,
        };
        let e = f
            .search(&good, &scene, &mut Rng::seed_from_u64(1))
            .unwrap_err();
        assert!(e.to_string().contains("forecasts[0].mu"), "{name}: {e}");
    }
}

#[test]
fn a_tiny_time_budget_stops_the_roadmap() {
    let map = box_map(vec![Shape::from(
        Cylinder::new(Vec3::new(10.0, 10.0, 5.0), 2.0, 5.0).unwrap(),
    )]);
    let q = query(Vec3::new(1.0, 10.0, 5.0), Vec3::new(19.0, 10.0, 5.0));
    let f = Vprm::new(VprmParams {
        budget_ms: 1e-6,
        max_samples: trust_core::scale::MAX_SAMPLE_COUNT,
        ..VprmParams::default()
    })
    .unwrap();
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let r = f.search(&q, &scene, &mut Rng::seed_from_u64(1)).unwrap();
    assert!(r.stats.budget_exhausted);
    assert!(r.stats.sample_count < 1000);
}

#[test]
fn devprm_stops_sampling_when_the_roadmap_stalls() {
    // Open space: after the first connector every sample is redundant, so the roadmap stalls after
    // `stall_samples` samples; with the stop switched off the sample cap binds.
    let map = box_map(vec![Shape::from(
        Cylinder::new(Vec3::new(10.0, 10.0, 5.0), 1.0, 5.0).unwrap(),
    )]);
    let q = query(Vec3::new(1.0, 10.0, 5.0), Vec3::new(19.0, 10.0, 5.0));
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let planner = |stall_samples: usize| {
        DevPrm::new(DevPrmParams {
            budget_ms: 10_000.0,
            max_samples: 3000,
            stall_samples,
            ..DevPrmParams::default()
        })
        .unwrap()
    };
    let stalled = planner(100)
        .search(&q, &scene, &mut Rng::seed_from_u64(4))
        .unwrap();
    assert!(!stalled.stats.budget_exhausted);
    assert!(stalled.stats.stalled);
    assert!(
        (100..3000).contains(&stalled.stats.sample_count),
        "{}",
        stalled.stats.sample_count
    );
    assert!(stalled.paths.len() >= 2, "{} paths", stalled.paths.len());
    let full = planner(0)
        .search(&q, &scene, &mut Rng::seed_from_u64(4))
        .unwrap();
    assert!(full.stats.budget_exhausted);
    assert!(!full.stats.stalled);
    assert_eq!(full.stats.sample_count, 3000);
    assert!(
        DevPrmParams {
            stall_samples: 0,
            ..DevPrmParams::default()
        }
        .validate()
        .is_ok()
    );
}

#[test]
fn the_goal_guidance_surface_ends_paths_early() {
    let map =
        StaticMap::new(Aabb::new(Vec3::zeros(), Vec3::new(80.0, 20.0, 10.0)).unwrap()).unwrap();
    let q = query(Vec3::new(1.0, 10.0, 5.0), Vec3::new(79.0, 10.0, 5.0));
    let paths = run(frontends()[1].as_ref(), &map, &[], &q).unwrap();
    let r_des = 78.0 - 20.0;
    for p in &paths {
        assert!(((p.end() - q.goal).norm() - r_des).abs() < 1e-6);
    }
    let no_ggs = DevPrm::new(DevPrmParams {
        goal_guidance_surface: false,
        budget_ms: 10_000.0,
        max_samples: 300,
        ..DevPrmParams::default()
    })
    .unwrap();
    let paths = run(&no_ggs, &map, &[], &q).unwrap();
    assert!(paths.iter().all(|p| p.end() == q.goal));
}

/// Constant-velocity trajectory from `a` to `b` in `d` seconds starting at 0.
fn traj(a: Vec3, b: Vec3, d: f64) -> PolyTraj {
    let mut piece = [Vec3::zeros(); 6];
    piece[0] = a;
    piece[1] = (b - a) / d;
    PolyTraj::new(0.0, vec![d], vec![piece]).unwrap()
}

#[test]
fn tvd_sees_when_uvd_sees_where() {
    let map = box_map(vec![]);
    // An obstacle crossing the gap between two parallel trajectories after they have passed.
    let f = Forecast::sphere(
        Vec3::new(5.0, 10.0, -3.0),
        Vec3::new(0.0, 0.0, 1.0),
        0.0,
        0.5,
        0.0,
        0.0,
    )
    .unwrap();
    let forecasts = [f];
    let scene = Scene::new(&map, &forecasts, 0.0).unwrap();
    let upper = traj(Vec3::new(1.0, 12.0, 5.0), Vec3::new(19.0, 12.0, 5.0), 2.0);
    let lower = traj(Vec3::new(1.0, 8.0, 5.0), Vec3::new(19.0, 8.0, 5.0), 2.0);
    // At t in [0, 2] the ball is at z in [-3, -1]: far below; TVD says equivalent.
    assert!(Tvd::default().equivalent(&upper, &lower, &scene).unwrap());
    assert!(tvd::equivalent(&upper, &lower, &scene, 0.01).unwrap());
    // UVD with a long-horizon PDC sees the whole sweep (z from -3 up to 7) between them: distinct.
    assert!(
        !Uvd::with_pdc(10.0)
            .unwrap()
            .equivalent(&upper, &lower, &scene)
            .unwrap()
    );
    // An obstacle sitting between them at t = 1: TVD says distinct.
    let g = Forecast::sphere(
        Vec3::new(10.0, 10.0, 5.0),
        Vec3::zeros(),
        0.0,
        0.5,
        0.0,
        0.0,
    )
    .unwrap();
    let forecasts = [g];
    let scene = Scene::new(&map, &forecasts, 0.0).unwrap();
    assert!(!Tvd::default().equivalent(&upper, &lower, &scene).unwrap());
    let path = GuidePath::new(vec![Vec3::zeros(), Vec3::x()]).unwrap();
    assert!(matches!(
        Tvd::default().equivalent(&path, &upper, &scene),
        Err(PlanError::Unsupported { .. })
    ));
}

#[test]
fn point_cloud_maps_work() {
    // A wall of points at x = 10 with a gap around y = 15: every frontend that avoids obstacles must
    // pass through the gap.
    let mut points = Vec::new();
    for iy in 0..=100 {
        let y = iy as f64 * 0.2;
        if (13.0..17.0).contains(&y) {
            continue;
        }
        for iz in 0..=50 {
            points.push(Vec3::new(10.0, y, iz as f64 * 0.2));
        }
    }
    let map = box_map(vec![]).with_point_cloud(&points, 0.2).unwrap();
    let q = query(Vec3::new(2.0, 12.0, 5.0), Vec3::new(18.0, 12.0, 5.0));
    for f in frontends() {
        if f.name() == "straight-line" {
            continue;
        }
        let paths = run(f.as_ref(), &map, &[], &q).unwrap();
        assert!(!paths.is_empty(), "{}", f.name());
        for p in &paths {
            for s in p.points.windows(2) {
                assert!(map.segment_clear(&s[0], &s[1], 0.0), "{}: {s:?}", f.name());
            }
        }
    }
}

#[test]
fn the_pdc_horizon_caps_how_far_ahead_the_cones_reach() {
    // A full-height wall-like cylinder sweeps across the corridor at 5 m/s: over the query's 4 s
    // horizon its cone closes the whole width at x ≈ 10 m, over 2 s it leaves y > 11.5 m open.
    let map = box_map(vec![]);
    let wall = Forecast::new(
        ObstacleShape::Cylinder { half_height: 5.0 },
        Vec3::new(10.0, 0.5, 5.0),
        Vec3::new(0.0, 5.0, 0.0),
        0.0,
        1.0,
        0.0,
        0.0,
    )
    .unwrap();
    let mut q = query(Vec3::new(1.0, 10.0, 5.0), Vec3::new(19.0, 10.0, 5.0));
    q.horizon_s = 4.0;
    let planner = |pdc_horizon_s| {
        DevPrm::new(DevPrmParams {
            budget_ms: 10_000.0,
            max_samples: 1500,
            pdc_horizon_s,
            ..DevPrmParams::default()
        })
        .unwrap()
    };
    let full = run(&planner(None), &map, &[wall], &q).unwrap();
    assert!(
        full.is_empty(),
        "{} paths through a closed wall",
        full.len()
    );
    let capped = run(&planner(Some(2.0)), &map, &[wall], &q).unwrap();
    assert!(!capped.is_empty());
    for p in &capped {
        // Each path passes the wall's line x = 10 m beyond the 2 s cone (y > 11.5 m).
        let crossing = p
            .points
            .windows(2)
            .find(|w| (w[0].x - 10.0) * (w[1].x - 10.0) <= 0.0)
            .expect("the path crosses x = 10 m");
        let s = (10.0 - crossing[0].x) / (crossing[1].x - crossing[0].x);
        let y = crossing[0].y + s * (crossing[1].y - crossing[0].y);
        assert!(y > 11.5, "crossed at y = {y}");
    }
    for bad in [-1.0, f64::NAN, f64::INFINITY] {
        let e = DevPrmParams {
            pdc_horizon_s: Some(bad),
            ..DevPrmParams::default()
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(e.contains("devprm.pdc_horizon_s"), "{e}");
    }
}

//! The shared frontend test (style rule 11): every `PathFrontend` of this crate runs on the same small
//! maps and must return paths that start at the start, end at the goal or on the goal guidance surface,
//! avoid the static map at the query time (all but the deliberately obstacle-blind straight line), are
//! pairwise distinct under the planner's own checker (PRMs), and are identical for the same seed.

use rand::SeedableRng;
use trust_core::{
    Aabb, Forecast, GuidePath, HomotopyChecker, Limits, PathFrontend, PathQuery, Rng, Scene, State,
    StaticMap, Vec3,
};
use trust_geometry::{AaBox, Cylinder, Shape, Sphere};
use trust_topo_prm::ggs::Terminal;
use trust_topo_prm::{
    DevPrm, DevPrmParams, SparseAStar, SparseAStarParams, StraightLine, Uvd, UvdParams, Vprm,
    VprmParams, scenes,
};

/// One test world: a static map, forecasts, and a query.
struct World {
    name: &'static str,
    map: StaticMap,
    forecasts: Vec<Forecast>,
    query: PathQuery,
}

fn query(start: Vec3, goal: Vec3, horizon_s: f64) -> PathQuery {
    PathQuery {
        start: State::at_rest(0.0, start),
        goal,
        limits: Limits::default(),
        horizon_s,
        exploration: 1.0,
    }
}

fn bounds(max: Vec3) -> Aabb {
    Aabb::new(Vec3::zeros(), max).unwrap()
}

fn worlds() -> Vec<World> {
    let size = Vec3::new(20.0, 20.0, 10.0);
    let pillars: Vec<Shape> = [(7.0, 9.0), (10.0, 11.5), (13.0, 8.5), (10.0, 7.0)]
        .iter()
        .map(|&(x, y)| Shape::from(Cylinder::new(Vec3::new(x, y, 5.0), 1.0, 5.0).unwrap()))
        .collect();
    let wall = vec![
        Shape::from(AaBox::new(Vec3::new(9.8, 0.0, 0.0), Vec3::new(10.2, 7.0, 10.0)).unwrap()),
        Shape::from(AaBox::new(Vec3::new(9.8, 9.5, 0.0), Vec3::new(10.2, 12.5, 10.0)).unwrap()),
        Shape::from(AaBox::new(Vec3::new(9.8, 15.0, 0.0), Vec3::new(10.2, 20.0, 10.0)).unwrap()),
    ];
    let mut e1 = scenes::random_dynamic_scene(
        6,
        &scenes::SceneParams::default(),
        &mut Rng::seed_from_u64(3),
    )
    .unwrap();
    // A static ball too, so that the collision check has something to check in the dynamic world.
    e1.map = e1
        .map
        .with_shapes([Shape::from(
            Sphere::new(Vec3::new(10.0, 3.0, 8.0), 1.0).unwrap(),
        )])
        .unwrap();
    vec![
        World {
            name: "empty",
            map: StaticMap::new(bounds(size)).unwrap(),
            forecasts: Vec::new(),
            query: query(Vec3::new(1.0, 10.0, 5.0), Vec3::new(19.0, 10.0, 5.0), 2.0),
        },
        World {
            name: "pillars",
            map: StaticMap::from_shapes(bounds(size), pillars).unwrap(),
            forecasts: Vec::new(),
            query: query(Vec3::new(1.0, 9.0, 5.0), Vec3::new(19.0, 9.5, 5.0), 2.0),
        },
        World {
            name: "wall-with-gaps",
            map: StaticMap::from_shapes(bounds(size), wall).unwrap(),
            forecasts: Vec::new(),
            query: query(Vec3::new(2.0, 11.0, 5.0), Vec3::new(18.0, 11.0, 5.0), 2.0),
        },
        World {
            name: "far-goal-ggs",
            map: StaticMap::from_shapes(
                bounds(Vec3::new(60.0, 20.0, 10.0)),
                vec![Shape::from(
                    Cylinder::new(Vec3::new(10.0, 10.0, 5.0), 1.5, 5.0).unwrap(),
                )],
            )
            .unwrap(),
            forecasts: Vec::new(),
            query: query(Vec3::new(1.0, 10.0, 5.0), Vec3::new(59.0, 10.0, 5.0), 2.0),
        },
        World {
            name: "e1-dynamic",
            map: e1.map,
            forecasts: e1.forecasts,
            query: e1.query,
        },
    ]
}

/// A frontend under test with what the shared test may demand of it.
struct Candidate {
    frontend: Box<dyn PathFrontend>,
    /// Its paths avoid the static map.
    avoids_obstacles: bool,
    /// Its paths end on the GGS when it exists (else at the goal).
    uses_ggs: bool,
    /// The checker under which its paths are pairwise distinct, per world (`None`: not claimed).
    checker: fn(&World) -> Option<Uvd>,
}

fn candidates() -> Vec<Candidate> {
    // Sample budgets that bind long before the time budgets: deterministic.
    let vprm = Vprm::new(VprmParams {
        budget_ms: 10_000.0,
        max_samples: 500,
        ..VprmParams::default()
    })
    .unwrap();
    let devprm = DevPrm::new(DevPrmParams {
        budget_ms: 10_000.0,
        max_samples: 500,
        ..DevPrmParams::default()
    })
    .unwrap();
    let astar = SparseAStar::new(SparseAStarParams {
        budget_ms: 10_000.0,
        ..SparseAStarParams::default()
    })
    .unwrap();
    vec![
        Candidate {
            frontend: Box::new(vprm),
            avoids_obstacles: true,
            uses_ggs: false,
            // V-PRM's own checker sees the static map and the moving obstacles frozen at t0.
            checker: |_| {
                Some(
                    Uvd::new(UvdParams {
                        freeze_forecasts: true,
                        ..UvdParams::default()
                    })
                    .unwrap(),
                )
            },
        },
        Candidate {
            frontend: Box::new(devprm),
            avoids_obstacles: true,
            uses_ggs: true,
            checker: |w| Some(Uvd::with_pdc(w.query.horizon_s).unwrap()),
        },
        Candidate {
            frontend: Box::new(StraightLine),
            avoids_obstacles: false,
            uses_ggs: true,
            checker: |_| None,
        },
        Candidate {
            frontend: Box::new(astar),
            avoids_obstacles: true,
            uses_ggs: true,
            checker: |_| None,
        },
    ]
}

fn ends_on_terminal(end: &Vec3, w: &World, uses_ggs: bool) -> bool {
    let q = &w.query;
    let terminal = if uses_ggs {
        Terminal::goal_guidance_surface(&q.start.p, &q.goal, q.horizon_s, q.limits.v_max)
    } else {
        Terminal::Point(q.goal)
    };
    terminal.reaches(end, 1e-6)
}

fn search(c: &Candidate, w: &World, seed: u64) -> Vec<GuidePath> {
    let scene = Scene::new(&w.map, &w.forecasts, w.query.start.t).unwrap();
    c.frontend
        .search(&w.query, &scene, &mut Rng::seed_from_u64(seed))
        .unwrap_or_else(|e| panic!("{} on {}: {e}", c.frontend.name(), w.name))
        .paths
}

#[test]
fn every_frontend_returns_valid_paths_on_every_map() {
    for w in worlds() {
        let scene = Scene::new(&w.map, &w.forecasts, w.query.start.t).unwrap();
        for c in candidates() {
            let name = c.frontend.name().to_string();
            let paths = search(&c, &w, 11);
            assert!(!paths.is_empty(), "{name} found nothing on {}", w.name);
            for p in &paths {
                assert_eq!(p.start(), w.query.start.p, "{name} on {}", w.name);
                assert!(
                    ends_on_terminal(&p.end(), &w, c.uses_ggs),
                    "{name} on {}: path ends at {:?}",
                    w.name,
                    p.end()
                );
                assert!(p.points.iter().all(|x| x.iter().all(|c| c.is_finite())));
                if c.avoids_obstacles {
                    for s in p.points.windows(2) {
                        assert!(
                            w.map.segment_clear(&s[0], &s[1], 0.0),
                            "{name} on {}: segment {s:?} hits the static map",
                            w.name
                        );
                    }
                }
            }
            if let Some(checker) = (c.checker)(&w) {
                for i in 0..paths.len() {
                    for j in 0..i {
                        assert!(
                            !checker.equivalent(&paths[i], &paths[j], &scene).unwrap(),
                            "{name} on {}: paths {i} and {j} are {}-equivalent",
                            w.name,
                            checker.name()
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn same_seed_gives_the_same_paths() {
    for w in worlds() {
        for c in candidates() {
            assert_eq!(
                search(&c, &w, 5),
                search(&c, &w, 5),
                "{} on {}",
                c.frontend.name(),
                w.name
            );
        }
    }
}

#[test]
fn prms_find_several_classes_where_there_are_several() {
    let ws = worlds();
    for c in candidates().iter().take(2) {
        for w in ws
            .iter()
            .filter(|w| w.name == "pillars" || w.name == "wall-with-gaps")
        {
            let n = search(c, w, 2).len();
            assert!(
                n >= 2,
                "{} found {n} classes on {}",
                c.frontend.name(),
                w.name
            );
        }
    }
}

/// `PathQuery::exploration` widens DEV-PRM's sampling box: a full-height wall 17 m to either side
/// of the line to the goal is beyond the default box's 10 m lateral inflation, and within twice
/// it. (The time budget is made large so that only the sample counts bind: deterministic.)
#[test]
fn exploration_widens_the_sampling_box() {
    let wall =
        Shape::from(AaBox::new(Vec3::new(9.8, 3.0, 0.0), Vec3::new(10.2, 37.0, 10.0)).unwrap());
    let map = StaticMap::from_shapes(bounds(Vec3::new(40.0, 40.0, 10.0)), vec![wall]).unwrap();
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let frontend = DevPrm::new(DevPrmParams {
        goal_guidance_surface: false,
        budget_ms: 60_000.0,
        ..DevPrmParams::default()
    })
    .unwrap();
    let paths_with = |exploration: f64| {
        let q = PathQuery {
            exploration,
            ..query(Vec3::new(2.0, 20.0, 5.0), Vec3::new(18.0, 20.0, 5.0), 2.0)
        };
        frontend
            .search(&q, &scene, &mut Rng::seed_from_u64(5))
            .unwrap()
            .paths
    };
    assert!(paths_with(1.0).is_empty());
    let wide = paths_with(2.0);
    assert!(!wide.is_empty());
    assert!(
        wide.iter()
            .all(|p| p.points.iter().any(|v| !(3.0..=37.0).contains(&v.y)))
    );
    for bad in [0.5, f64::NAN, 17.0] {
        let q = PathQuery {
            exploration: bad,
            ..query(Vec3::new(2.0, 20.0, 5.0), Vec3::new(18.0, 20.0, 5.0), 2.0)
        };
        let e = frontend
            .search(&q, &scene, &mut Rng::seed_from_u64(5))
            .unwrap_err();
        assert!(e.to_string().contains("query.exploration"), "{e}");
    }
}

//! Public API of `trust-route`: routes around walls and traps, degenerate inputs, caps, and the
//! properties of the route and its queries on random maps.

use approx::assert_relative_eq;
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trust_geometry::{AaBox, Aabb, Cylinder, Shape, StaticMap, Vec3};
use trust_route::scenes::{box_with_hole, crazyflie_room, sealed_goal_room};
use trust_route::{
    Endpoint, GlobalRoute, RouteError, RouteParams, RoutePlanner, RouteProgress, Unreachable,
    UnreachableCause,
};

fn planner() -> RoutePlanner {
    RoutePlanner::new(RouteParams::default()).unwrap()
}

fn bounds(max: [f64; 3]) -> Aabb {
    Aabb::new(Vec3::zeros(), Vec3::new(max[0], max[1], max[2])).unwrap()
}

fn aabox(min: [f64; 3], max: [f64; 3]) -> Shape {
    AaBox::new(
        Vec3::new(min[0], min[1], min[2]),
        Vec3::new(max[0], max[1], max[2]),
    )
    .unwrap()
    .into()
}

/// Every segment of `route` is clear at its clearance (less a rounding tolerance), except the
/// first when the start was inside the inflation.
fn assert_clear(map: &StaticMap, route: &GlobalRoute) {
    let c = route.clearance_m() * (1.0 - 1e-9);
    let skip = usize::from(route.start_inside_clearance());
    for (i, w) in route.points().windows(2).enumerate().skip(skip) {
        assert!(
            map.segment_clear(&w[0], &w[1], c),
            "segment {i} {} -> {} closer than {c}",
            w[0],
            w[1]
        );
    }
}

/// A 30 m full-height wall 25 m ahead in a 120 × 60 × 20 m world.
fn wide_wall() -> StaticMap {
    StaticMap::from_shapes(
        bounds([120.0, 60.0, 20.0]),
        vec![aabox([25.0, 15.0, 0.0], [26.0, 45.0, 20.0])],
    )
    .unwrap()
}

#[test]
fn a_wide_wall_ahead_is_gone_around() {
    let map = wide_wall();
    let (s, g) = (Vec3::new(2.0, 30.0, 5.0), Vec3::new(100.0, 30.0, 5.0));
    assert!(
        !map.segment_clear(&s, &g, 0.0),
        "the straight line must be blocked"
    );
    let route = planner().plan(&map, &s, &g, 0.3).unwrap();
    assert_clear(&map, &route);
    assert_eq!(route.points()[0], s);
    assert_eq!(*route.points().last().unwrap(), g);
    // Around an edge (y < 15 or y > 45) or over the top is impossible (full height).
    assert!(
        route.points().iter().any(|p| p.y < 15.0 || p.y > 45.0),
        "{:?}",
        route.points()
    );
    // Near-shortest: the detour around an end of the wall, with some slack for the grid.
    let detour = (Vec3::new(25.0, 15.0 - 0.45, 5.0) - s).norm()
        + (g - Vec3::new(26.0, 15.0 - 0.45, 5.0)).norm()
        + 1.0;
    assert!(
        route.length() < 1.05 * detour,
        "{} vs {detour}",
        route.length()
    );
    assert!(route.points().len() <= 6, "shortcut: {:?}", route.points());
}

#[test]
fn a_cul_de_sac_opening_toward_the_start_is_left_by_its_mouth() {
    // A U of full-height walls around the straight line, open toward the start (x = 20).
    let map = StaticMap::from_shapes(
        bounds([100.0, 60.0, 10.0]),
        vec![
            aabox([40.0, 20.0, 0.0], [41.0, 40.0, 10.0]), // back
            aabox([20.0, 20.0, 0.0], [41.0, 21.0, 10.0]), // side
            aabox([20.0, 39.0, 0.0], [41.0, 40.0, 10.0]), // side
        ],
    )
    .unwrap();
    let (s, g) = (Vec3::new(2.0, 30.0, 5.0), Vec3::new(90.0, 30.0, 5.0));
    let route = planner().plan(&map, &s, &g, 0.3).unwrap();
    assert_clear(&map, &route);
    assert!(
        route
            .points()
            .iter()
            .all(|p| !(p.x > 20.0 && p.x < 41.0 && p.y > 21.0 && p.y < 39.0)),
        "no vertex inside the trap: {:?}",
        route.points()
    );
    assert!(route.points().iter().any(|p| p.y < 20.0 || p.y > 40.0));
}

#[test]
fn a_crazyflie_room_with_thin_pillars_is_crossed_with_clearance() {
    let map = crazyflie_room().expect("room map");
    let (s, g) = (Vec3::new(1.0, 1.0, 1.0), Vec3::new(7.0, 1.0, 1.5));
    let route = planner().plan(&map, &s, &g, 0.1).unwrap();
    assert_relative_eq!(route.clearance_m(), 0.15);
    // The coarse grid (4 × 0.075 m cells) is wide enough here.
    assert!(route.cell_m().unwrap() <= 0.31, "{:?}", route.cell_m());
    assert_clear(&map, &route);
    // The fine grid alone finds a route as well, with its 0.075 m cells.
    let fine = RoutePlanner::new(RouteParams {
        coarse_factor: 1.0,
        ..RouteParams::default()
    })
    .unwrap()
    .plan(&map, &s, &g, 0.1)
    .unwrap();
    assert!(fine.cell_m().unwrap() <= 0.1, "{:?}", fine.cell_m());
    assert_clear(&map, &fine);
    // Through the gap between the wall's end (y = 4.5) and the far side (y = 6).
    assert!(route.points().iter().any(|p| p.y > 4.5));
    // A pillar straight between two points is avoided too.
    let (s2, g2) = (Vec3::new(1.0, 2.0, 1.0), Vec3::new(3.5, 2.0, 1.0));
    let r2 = planner().plan(&map, &s2, &g2, 0.1).unwrap();
    assert!(r2.points().len() >= 3);
    assert_clear(&map, &r2);
}

#[test]
fn open_space_gives_the_straight_line_and_start_equal_goal_a_point() {
    let map = StaticMap::empty(bounds([10.0, 10.0, 3.0])).unwrap();
    let (s, g) = (Vec3::new(1.0, 1.0, 1.0), Vec3::new(9.0, 8.0, 2.0));
    let r = planner().plan(&map, &s, &g, 0.2).unwrap();
    assert_eq!(r.points(), &[s, g]);
    assert_eq!(r.cell_m(), None);
    assert_relative_eq!(r.length(), (g - s).norm());
    let p = planner().plan(&map, &s, &s, 0.2).unwrap();
    assert_eq!(p.points(), &[s]);
    assert_eq!(p.length(), 0.0);
    assert_eq!(p.point_at(3.0), s);
    assert_eq!(p.progress(&g).unwrap(), 0.0);
    assert_eq!(p.local_goal(&g, 1.0).unwrap().point, s);
    assert_eq!(p.remaining_length(&g).unwrap(), 0.0);
    // Zero radius in open space is fine (no grid needed).
    assert!(planner().plan(&map, &s, &g, 0.0).is_ok());
}

#[test]
fn bad_inputs_are_typed_errors() {
    let map = wide_wall();
    let p = planner();
    let ok = Vec3::new(2.0, 30.0, 5.0);
    let e = p
        .plan(&map, &Vec3::new(f64::NAN, 0.0, 0.0), &ok, 0.3)
        .unwrap_err();
    assert!(matches!(e, RouteError::NonFinitePoint { ref field, .. } if field == "start"));
    let e = p
        .plan(&map, &ok, &Vec3::new(500.0, 30.0, 5.0), 0.3)
        .unwrap_err();
    assert!(matches!(
        e,
        RouteError::OutsideBounds {
            which: Endpoint::Goal,
            ..
        }
    ));
    for r in [-1.0, f64::NAN, f64::INFINITY] {
        let e = p.plan(&map, &ok, &ok, r).unwrap_err();
        assert!(matches!(e, RouteError::InvalidParam { ref field, .. } if field == "radius_m"));
    }
    let bad = RouteParams {
        max_cells: 0,
        ..RouteParams::default()
    };
    let e = RoutePlanner::new(bad).unwrap_err();
    assert!(e.to_string().contains("route.max_cells"), "{e}");
    let bad = RouteParams {
        cells_per_clearance: f64::NAN,
        ..RouteParams::default()
    };
    assert!(RoutePlanner::new(bad).is_err());
    let r = GlobalRoute::from_points(vec![ok, ok + Vec3::x()]).unwrap();
    assert!(r.local_goal(&ok, 0.0).is_err());
    assert!(r.local_goal(&ok, f64::NAN).is_err());
    assert!(r.progress(&Vec3::new(0.0, f64::INFINITY, 0.0)).is_err());
    assert!(GlobalRoute::from_points(vec![]).is_err());
}

#[test]
fn params_deserialize_with_defaults_and_reject_unknown_fields() {
    let p: RouteParams = toml::from_str("max_expansions = 10").unwrap();
    assert_eq!(p.max_expansions, 10);
    assert_eq!(p.max_cells, RouteParams::default().max_cells);
    assert!(toml::from_str::<RouteParams>("max_expansion = 10").is_err());
}

#[test]
fn an_enclosed_goal_is_unreachable_not_a_hang() {
    // The goal sits in a closed box (walls all round, floor to ceiling).
    let map = StaticMap::from_shapes(
        bounds([20.0, 20.0, 4.0]),
        vec![
            aabox([10.0, 8.0, 0.0], [11.0, 14.0, 4.0]),
            aabox([16.0, 8.0, 0.0], [17.0, 14.0, 4.0]),
            aabox([10.0, 8.0, 0.0], [17.0, 9.0, 4.0]),
            aabox([10.0, 13.0, 0.0], [17.0, 14.0, 4.0]),
        ],
    )
    .unwrap();
    let e = planner()
        .plan(
            &map,
            &Vec3::new(2.0, 2.0, 2.0),
            &Vec3::new(13.5, 11.0, 2.0),
            0.3,
        )
        .unwrap_err();
    assert!(matches!(e, RouteError::Unreachable { .. }), "{e}");
}

#[test]
fn caps_are_typed_errors_naming_the_cap() {
    let map = wide_wall();
    let (s, g) = (Vec3::new(2.0, 30.0, 5.0), Vec3::new(100.0, 30.0, 5.0));
    let few = RoutePlanner::new(RouteParams {
        max_expansions: 100,
        ..RouteParams::default()
    })
    .unwrap();
    assert_eq!(
        few.plan(&map, &s, &g, 0.3).unwrap_err(),
        RouteError::ExpansionCap { cap: 100 }
    );
    let small = RoutePlanner::new(RouteParams {
        max_cells: 1000,
        max_coarsening: 1.0,
        ..RouteParams::default()
    })
    .unwrap();
    let e = small.plan(&map, &s, &g, 0.3).unwrap_err();
    assert!(
        matches!(e, RouteError::TooManyCells { cap: 1000, .. }),
        "{e}"
    );
    let past = std::time::Instant::now();
    let e = planner()
        .plan_until(&map, &s, &g, 0.3, Some(past))
        .unwrap_err();
    assert!(matches!(e, RouteError::Deadline { .. }), "{e}");
}

#[test]
fn a_start_inside_the_inflation_snaps_out_and_a_buried_goal_ends_short() {
    let map = wide_wall();
    // 0.2 m from the wall's face: inside the 0.45 m inflation.
    let s = Vec3::new(24.8, 30.0, 5.0);
    let g = Vec3::new(100.0, 30.0, 5.0);
    let r = planner().plan(&map, &s, &g, 0.3).unwrap();
    assert!(r.start_inside_clearance());
    assert_eq!(r.points()[0], s);
    assert_clear(&map, &r);
    // A goal inside the wall: the route ends at a free cell near it.
    let buried = Vec3::new(25.5, 30.0, 5.0);
    let r = planner()
        .plan(&map, &Vec3::new(2.0, 30.0, 5.0), &buried, 0.3)
        .unwrap();
    assert!(
        r.goal_gap_m() > 0.5 && r.goal_gap_m() < 4.0 * 0.45 + 1e-9,
        "{}",
        r.goal_gap_m()
    );
    assert_clear(&map, &r);
    // Deep inside a big block, farther than the snap radius from any free cell.
    let block = StaticMap::from_shapes(
        bounds([40.0, 40.0, 10.0]),
        vec![aabox([10.0, 10.0, 0.0], [30.0, 30.0, 10.0])],
    )
    .unwrap();
    let e = planner()
        .plan(
            &block,
            &Vec3::new(20.0, 20.0, 5.0),
            &Vec3::new(2.0, 2.0, 2.0),
            0.3,
        )
        .unwrap_err();
    assert!(
        matches!(
            e,
            RouteError::NoFreeCell {
                which: Endpoint::Start,
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn a_route_reports_a_new_obstacle_only_ahead_of_the_vehicle() {
    let empty = StaticMap::empty(bounds([50.0, 20.0, 5.0])).unwrap();
    let (s, g) = (Vec3::new(1.0, 10.0, 2.0), Vec3::new(49.0, 10.0, 2.0));
    let r = planner().plan(&empty, &s, &g, 0.3).unwrap();
    assert!(!r.is_blocked(&empty, 0.45, 0.0).unwrap());
    let later = StaticMap::from_shapes(
        bounds([50.0, 20.0, 5.0]),
        vec![aabox([20.0, 8.0, 0.0], [21.0, 12.0, 5.0])],
    )
    .unwrap();
    let b = r.first_blocked(&later, 0.45, 0.0).unwrap().unwrap();
    assert_eq!(b.segment, 0);
    // Past the obstacle, the rest of the route is clear.
    assert!(!r.is_blocked(&later, 0.45, 25.0).unwrap());
}

#[test]
fn the_aim_in_sight_stops_at_the_corner_a_building_hides_the_rest_behind() {
    // Holdout: an 18 m/s vehicle 62 m before a building corner where its route turns by 29°
    // aimed 10 m past the corner along the face, with the building in the way.
    let map = StaticMap::from_shapes(
        bounds([200.0, 160.0, 70.0]),
        vec![aabox([60.0, 52.0, 0.0], [92.0, 108.0, 36.0])],
    )
    .unwrap();
    let start = Vec3::new(5.0, 80.0, 15.0);
    let corner = Vec3::new(60.0, 49.0, 15.0);
    let route = GlobalRoute::from_points(vec![start, corner, Vec3::new(93.0, 49.0, 15.0)]).unwrap();
    let local = route.local_goal(&start, 72.0).unwrap();
    assert!(
        local.s > (corner - start).norm(),
        "the local goal is past the corner"
    );
    assert!(
        !map.segment_clear(&start, &local.point, 0.2),
        "and hidden by the building"
    );
    let seen = route.last_in_sight(&map, &start, 0.0, local, 0.2);
    assert!(map.segment_clear(&start, &seen.point, 0.2));
    // At the corner or a little past it (the face is in sight up to the building's edge).
    assert!(
        seen.s >= (corner - start).norm() - 1e-9 && seen.s < local.s,
        "{seen:?}"
    );
    assert!((seen.point - route.point_at(seen.s)).norm() < 1e-9);
    // An aim in sight is kept; an aim from off the route (the projection hidden) too.
    let near = route.local_goal(&start, 40.0).unwrap();
    assert_eq!(route.last_in_sight(&map, &start, 0.0, near, 0.2), near);
    let inside = Vec3::new(70.0, 80.0, 15.0);
    let far = route.local_goal(&inside, 72.0).unwrap();
    assert_eq!(route.last_in_sight(&map, &inside, 0.0, far, 0.2), far);
}

#[test]
fn a_hairpin_of_short_segments_is_a_sharp_turn_over_a_span() {
    // A sensed U-trap's route: out of the pocket round the end of a side wall the vehicle has
    // not seen, then on to the goal behind the pocket's back wall. No vertex turns by more than
    // 45°, but within 3 m the route doubles back.
    let p = |x: f64, y: f64| Vec3::new(x, y, 4.0);
    let route = GlobalRoute::from_points(vec![
        p(39.0, 28.0),
        p(34.0, 20.0),
        p(34.0, 19.0),
        p(35.0, 18.0),
        p(41.0, 18.0),
        p(90.0, 30.0),
    ])
    .unwrap();
    let len = route.length();
    let turn = std::f64::consts::FRAC_PI_3;
    assert_eq!(route.first_sharp_turn(0.0, len, turn, 0.0), None);
    let corner = route.first_sharp_turn(0.0, len, turn, 3.0).unwrap();
    assert!((corner.point - p(34.0, 20.0)).norm() < 1e-9, "{corner:?}");
    assert!((corner.s - (p(34.0, 20.0) - p(39.0, 28.0)).norm()).abs() < 1e-9);
    // A single sharp vertex is found at every span; a straight route has none; a bad span is 0.
    let l = GlobalRoute::from_points(vec![p(0.0, 0.0), p(10.0, 0.0), p(10.0, 10.0)]).unwrap();
    for span in [0.0, 1.0, 30.0, f64::NAN, -1.0, f64::INFINITY] {
        let c = l.first_sharp_turn(0.0, 20.0, turn, span).unwrap();
        assert!((c.point - p(10.0, 0.0)).norm() < 1e-9, "span {span}");
    }
    let straight = GlobalRoute::from_points(vec![p(0.0, 0.0), p(5.0, 0.1), p(10.0, 0.0)]).unwrap();
    assert_eq!(straight.first_sharp_turn(0.0, 10.0, turn, 5.0), None);
}

/// A random map of full-height pillars and boxes in a `size` world, start and goal kept free.
fn random_map(seed: u64, size: [f64; 3], count: usize, r: f64) -> (StaticMap, Vec3, Vec3) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let s = Vec3::new(0.05 * size[0], 0.5 * size[1], 0.5 * size[2]);
    let g = Vec3::new(0.95 * size[0], 0.5 * size[1], 0.5 * size[2]);
    let mut shapes = Vec::new();
    while shapes.len() < count {
        let c = Vec3::new(
            rng.random_range(0.0..size[0]),
            rng.random_range(0.0..size[1]),
            0.5 * size[2],
        );
        let w = rng.random_range(0.02..0.08) * size[1];
        let shape: Shape = if rng.random_bool(0.5) {
            Cylinder::new(c, w, 0.5 * size[2]).unwrap().into()
        } else {
            AaBox::from_center_half_extents(c, Vec3::new(w, 2.0 * w, 0.5 * size[2]))
                .unwrap()
                .into()
        };
        if shape.signed_distance(&s) > 4.0 * r && shape.signed_distance(&g) > 4.0 * r {
            shapes.push(shape);
        }
    }
    let map = StaticMap::from_shapes(bounds(size), shapes).unwrap();
    (map, s, g)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(
        std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(16)
    ))]

    /// Any seed, room or E4-like scale: the route keeps its clearance (shortcut included), is
    /// deterministic, and its queries behave.
    #[test]
    fn routes_are_clear_deterministic_and_queryable(seed in 0_u64..10_000, big in any::<bool>(), frac in 0.0_f64..1.0, horizon in 0.2_f64..20.0, off in -0.5_f64..0.5) {
        let (size, r, n) = if big { ([120.0, 40.0, 10.0], 0.3, 40) } else { ([8.0, 6.0, 3.0], 0.1, 8) };
        let (map, s, g) = random_map(seed, size, n, r);
        let p = planner();
        let route = match p.plan(&map, &s, &g, r) {
            Ok(route) => route,
            // A random map may wall the goal off; that must be a typed answer, never a panic:
            // `Unreachable`, the expansion cap when the walled-in free space is larger than
            // the cap (regression_seed_5240_big_map_ends_in_a_typed_answer), or `Unresolved`
            // when the only passage is narrower than the grid can prove (seed 1604, big).
            Err(
                RouteError::Unreachable { .. }
                | RouteError::ExpansionCap { .. }
                | RouteError::Unresolved { .. },
            ) => return Ok(()),
            Err(e) => return Err(TestCaseError::fail(format!("{e}"))),
        };
        assert_clear(&map, &route);
        // Without the shortcut, too (the grid edges alone keep the clearance).
        let raw = RoutePlanner::new(RouteParams { shortcut: false, ..RouteParams::default() }).unwrap()
            .plan(&map, &s, &g, r).unwrap();
        assert_clear(&map, &raw);
        prop_assert!(route.length() <= raw.length() + 1e-9);
        prop_assert_eq!(&route, &p.plan(&map, &s, &g, r).unwrap());
        prop_assert_eq!(route.points()[0], s);
        prop_assert_eq!(*route.points().last().unwrap(), g);

        // Progress is monotone along the route and equals arc length on it.
        let mut last = -1.0;
        for k in 0..=50 {
            let sk = route.length() * k as f64 / 50.0;
            let pr = route.progress(&route.point_at(sk)).unwrap();
            prop_assert!(pr >= last - 1e-9, "progress went back: {} < {}", pr, last);
            prop_assert!((pr - sk).abs() < 1e-6 * (1.0 + sk), "{} vs {}", pr, sk);
            last = pr;
        }

        // The local goal lies on the route, within the horizon of the projection, ahead of it.
        let pos = route.point_at(frac * route.length()) + Vec3::new(0.0, off * r, off * r);
        let proj = route.project(&pos).unwrap();
        let lg = route.local_goal(&pos, horizon).unwrap();
        prop_assert!((route.point_at(lg.s) - lg.point).norm() < 1e-6);
        prop_assert!((lg.point - proj.point).norm() <= horizon + 1e-9);
        prop_assert!(lg.s >= proj.s - 1e-12);
        prop_assert!(lg.point.iter().all(|c| c.is_finite()));
        if lg.s < route.length() - 1e-9 {
            prop_assert!(((lg.point - proj.point).norm() - horizon).abs() < 1e-6);
        }
        prop_assert!((route.remaining_length(&pos).unwrap() - (route.length() - proj.s)).abs() < 1e-9);
    }
}

/// CI's pinned proptest seed drew this map (seed 1604, 120 × 40 × 10 m, r = 0.3): no route at
/// the inflated clearance on the grid, and no proof either (a passage narrower than a cell may
/// exist): the answer is the typed `Unresolved`, the same on every call.
#[test]
fn regression_seed_1604_big_map_is_unresolved_not_a_false_verdict() {
    let (map, s, g) = random_map(1604, [120.0, 40.0, 10.0], 40, 0.3);
    let first = planner().plan(&map, &s, &g, 0.3);
    match &first {
        Ok(route) => assert_clear(&map, route),
        Err(RouteError::Unresolved { .. } | RouteError::Unreachable { .. }) => {}
        Err(e) => panic!("unexpected error: {e}"),
    }
    assert_eq!(first, planner().plan(&map, &s, &g, 0.3));
}

/// CI's commit-derived proptest seed 564830140411337884 drew this map (120 × 40 × 10 m, r = 0.3):
/// the search ran into its expansion cap. Whatever the map, the answer must be typed and the
/// search must stop at the cap; with a cap large enough to exhaust the reachable space the
/// answer is a route or `Unreachable`, never the cap.
#[test]
fn regression_seed_5240_big_map_ends_in_a_typed_answer() {
    let (map, s, g) = random_map(5240, [120.0, 40.0, 10.0], 40, 0.3);
    match planner().plan(&map, &s, &g, 0.3) {
        Ok(route) => assert_clear(&map, &route),
        Err(RouteError::Unreachable { .. } | RouteError::ExpansionCap { .. }) => {}
        Err(e) => panic!("unexpected error: {e}"),
    }
    let exhaustive = RoutePlanner::new(RouteParams {
        max_expansions: 20_000_000,
        ..RouteParams::default()
    })
    .unwrap();
    match exhaustive.plan(&map, &s, &g, 0.3) {
        Ok(route) => assert_clear(&map, &route),
        Err(RouteError::Unreachable { .. }) => {}
        Err(e) => panic!("with the cap out of the way: {e}"),
    }
}

/// A world too large for the fine grid at its coarsest is still routed on the coarse grid,
/// which coarsens to fit the cap like the fine one (holdout: a 320 × 320 × 45 m city with a
/// 0.25 m vehicle had no route and the vehicle stopped at a building). The wide wall with
/// 20 000 cells: the fine grid (0.225 m cells, at most 0.9 m) needs 2.1 M.
#[test]
fn a_world_too_large_for_the_fine_grid_is_routed_on_the_coarse_one() {
    let map = wide_wall();
    let (s, g) = (Vec3::new(2.0, 30.0, 5.0), Vec3::new(100.0, 30.0, 5.0));
    let capped = RouteParams {
        max_cells: 20_000,
        ..RouteParams::default()
    };
    let fine_only = RoutePlanner::new(RouteParams {
        coarse_factor: 1.0,
        ..capped.clone()
    })
    .unwrap();
    let e = fine_only.plan(&map, &s, &g, 0.3).unwrap_err();
    assert!(matches!(e, RouteError::TooManyCells { .. }), "{e}");
    let route = RoutePlanner::new(capped)
        .unwrap()
        .plan(&map, &s, &g, 0.3)
        .unwrap();
    assert_clear(&map, &route);
    assert!(route.points().iter().any(|p| p.y < 15.0 || p.y > 45.0));
}

/// A 12 × 10 × 3 m store with three staggered full-height shelving rows 2.4 m apart (holdout
/// finding: the coarse grid closed the aisles and its route went round the rows).
fn store() -> StaticMap {
    StaticMap::from_shapes(
        bounds([12.0, 10.0, 3.0]),
        vec![
            aabox([3.5, 2.0, 0.0], [4.1, 7.0, 3.0]),
            aabox([6.5, 3.0, 0.0], [7.1, 8.0, 3.0]),
            aabox([9.5, 2.0, 0.0], [10.1, 7.0, 3.0]),
            Cylinder::new(Vec3::new(2.0, 8.0, 1.5), 0.15, 1.5)
                .unwrap()
                .into(),
            Cylinder::new(Vec3::new(8.3, 1.4, 1.5), 0.15, 1.5)
                .unwrap()
                .into(),
        ],
    )
    .unwrap()
}

/// The store's aisles were closed by the coarse grid while a free cell needed `c + h·√3/2`;
/// now that a free cell needs `c` and each edge is checked exactly, the coarse grid takes the
/// aisle too, and the refinement keeps the shorter of the two routes.
#[test]
fn a_small_world_is_refined_on_the_fine_grid_through_passages_the_coarse_one_closes() {
    let map = store();
    let (s, g) = (Vec3::new(7.87, 6.69, 1.15), Vec3::new(1.15, 1.46, 2.05));
    let refined = planner().plan(&map, &s, &g, 0.22).unwrap();
    let coarse_only = RoutePlanner::new(RouteParams {
        refine_max_cells: 0,
        ..RouteParams::default()
    })
    .unwrap()
    .plan(&map, &s, &g, 0.22)
    .unwrap();
    assert_clear(&map, &refined);
    assert_clear(&map, &coarse_only);
    // Down the aisle between the second and third rows, then past the first row's end: 10.6 m
    // at the clearance; round the rows' far ends: 15.6 m.
    assert!(
        refined.length() < 11.5 && refined.length() <= coarse_only.length(),
        "refined {} m, coarse only {} m",
        refined.length(),
        coarse_only.length()
    );
    assert!(refined.expanded_count() > coarse_only.expanded_count());
    // A refinement cap below the fine grid's size keeps the coarse route.
    let capped = RoutePlanner::new(RouteParams {
        refine_max_cells: 10_000,
        ..RouteParams::default()
    })
    .unwrap()
    .plan(&map, &s, &g, 0.22)
    .unwrap();
    assert_eq!(capped.points(), coarse_only.points());
}

/// Runs a search to its answer with the given slice per call.
fn run_sliced(map: &StaticMap, s: Vec3, g: Vec3, r: f64, slice: usize) -> (RouteProgress, usize) {
    let mut search = planner().start_search(map, &s, &g, r).unwrap();
    let mut calls = 0_usize;
    loop {
        calls += 1;
        let before = search.work_done();
        let p = search.advance(map, slice);
        assert!(
            search.work_done() - before <= slice,
            "a call did more than its budget"
        );
        if !matches!(p, RouteProgress::Pending) {
            assert_eq!(p, search.advance(map, slice), "an answer is sticky");
            return (p, search.work_done());
        }
        assert!(calls < 10_000_000, "no answer");
    }
}

fn unreachable(p: &RouteProgress) -> &Unreachable {
    match p {
        RouteProgress::Unreachable(u) => u,
        other => panic!("expected a verdict, got {other:?}"),
    }
}

#[test]
fn a_sealed_goal_gets_its_verdict_in_a_few_thousand_units() {
    let (map, s, g) = sealed_goal_room().unwrap();
    let (p, work) = run_sliced(&map, s, g, 0.3, usize::MAX);
    let u = unreachable(&p);
    assert_eq!(u.cause, UnreachableCause::SealedOff, "{}", u.cause);
    assert!(work < 50_000, "{work} units");
    assert_eq!(u.work_done, work);
    let nearest = u.nearest.as_ref().expect("a route to the nearest point");
    assert_clear(&map, nearest);
    assert_eq!(nearest.points()[0], s);
    assert!(nearest.goal_gap_m() < (g - s).norm());
    let e = planner().plan(&map, &s, &g, 0.3).unwrap_err();
    assert!(
        matches!(
            e,
            RouteError::Unreachable {
                cause: UnreachableCause::SealedOff,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("sealed off"), "{e}");
    // The start sealed in instead: the start side runs dry.
    let (p, work) = run_sliced(&map, g, s, 0.3, usize::MAX);
    assert_eq!(unreachable(&p).cause, UnreachableCause::SealedOff);
    assert!(work < 50_000, "{work} units");
}

#[test]
fn the_answer_does_not_depend_on_how_the_work_is_sliced() {
    let (sealed, s1, g1) = sealed_goal_room().unwrap();
    let wall = wide_wall();
    let (s2, g2) = (Vec3::new(2.0, 30.0, 5.0), Vec3::new(100.0, 30.0, 5.0));
    let (slot, s3, g3) = slot_world(SlotAxis::Y, 0.58, 2.0);
    let (slot3, _, _) = slot_world(SlotAxis::Y, 0.3, 2.0);
    for (map, s, g, r) in [
        (&sealed, s1, g1, 0.3),
        (&wall, s2, g2, 0.3),
        (&slot, s3, g3, 0.2),
        (&slot3, s3, g3, 0.2),
        (&wall, s2, Vec3::new(25.5, 30.0, 5.0), 0.3),
    ] {
        let whole = run_sliced(map, s, g, r, usize::MAX);
        for slice in [1, 7, 1000] {
            assert_eq!(run_sliced(map, s, g, r, slice), whole, "slice {slice}");
        }
    }
}

/// Which face of a 1 m thick full wall across the room holds the slot, and how it runs.
#[derive(Clone, Copy)]
enum SlotAxis {
    /// A wall across x with a vertical slot (width along y).
    Y,
    /// A wall across x with a horizontal slot (width along z).
    Z,
    /// A wall across y with a vertical slot (width along x).
    X,
}

/// A 12 × 4 × 3 m room (4 × 12 × 3 for `SlotAxis::X`) cut by a full wall with one slot of
/// `width` whose lower edge is at `at`; the start on one side, the goal on the other.
fn slot_world(axis: SlotAxis, width: f64, at: f64) -> (StaticMap, Vec3, Vec3) {
    let big = 100.0;
    let (size, wall_min, wall_max, slot_axis, s, g) = match axis {
        SlotAxis::Y => (
            [12.0, 4.0, 3.0],
            Vec3::new(5.5, -big, -big),
            Vec3::new(6.5, big, big),
            1,
            Vec3::new(1.0, 2.0, 1.5),
            Vec3::new(11.0, 2.0, 1.5),
        ),
        SlotAxis::Z => (
            [12.0, 4.0, 3.0],
            Vec3::new(5.5, -big, -big),
            Vec3::new(6.5, big, big),
            2,
            Vec3::new(1.0, 2.0, 1.5),
            Vec3::new(11.0, 2.0, 1.5),
        ),
        SlotAxis::X => (
            [4.0, 12.0, 3.0],
            Vec3::new(-big, 5.5, -big),
            Vec3::new(big, 6.5, big),
            0,
            Vec3::new(2.0, 1.0, 1.5),
            Vec3::new(2.0, 11.0, 1.5),
        ),
    };
    let (mut lo_max, mut hi_min) = (wall_max, wall_min);
    lo_max[slot_axis] = at;
    hi_min[slot_axis] = at + width;
    let shapes: Vec<Shape> = vec![
        AaBox::new(wall_min, lo_max).unwrap().into(),
        AaBox::new(hi_min, wall_max).unwrap().into(),
    ];
    (StaticMap::from_shapes(bounds(size), shapes).unwrap(), s, g)
}

/// The crate docs' promise: a slot `2c + h` wide stays open (c = 0.3 m, h = 0.15 m for a
/// 0.2 m radius), whatever its alignment with the grid and its orientation (a full wall with a
/// 0.75 m slot used to be "unreachable at clearance 0.30000000000000004 m"). A verdict is a
/// proof: narrower slots are `TooNarrow` or `SealedOff` only where the grid can prove it.
#[test]
fn slots_as_wide_as_the_docs_promise_are_open_and_narrower_ones_too_narrow() {
    let (r, c, h) = (0.2, 0.3, 0.15);
    let open = 2.0 * c + h + 1e-3;
    for axis in [SlotAxis::Y, SlotAxis::Z, SlotAxis::X] {
        for (width, at) in [
            (open, 1.0),
            (open, 1.037),
            (open, 1.074),
            (open, 1.111),
            (0.8, 1.02),
            (1.0, 1.3),
        ] {
            let (map, s, g) = slot_world(axis, width, at);
            let route = planner()
                .plan(&map, &s, &g, r)
                .unwrap_or_else(|e| panic!("slot {width} at {at}: {e}"));
            assert_clear(&map, &route);
        }
    }
    // Narrower than 2c but too wide for the grid to prove it (the proof needs every cell
    // centre below c − h·√3/2 = 0.17 m): no route, and no verdict either.
    for at in [1.0, 1.05, 1.1] {
        let (map, s, g) = slot_world(SlotAxis::Y, 0.58, at);
        let e = planner().plan(&map, &s, &g, r).unwrap_err();
        assert!(matches!(e, RouteError::Unresolved { .. }), "{e}");
        assert!(e.to_string().contains("clearance 0.3 m"), "{e}");
    }
    // Narrow enough for the proof at the clearance, too narrow for the vehicle: sealed off.
    for at in [1.0, 1.05, 1.1] {
        let (map, s, g) = slot_world(SlotAxis::Y, 0.3, at);
        let e = planner().plan(&map, &s, &g, r).unwrap_err();
        assert!(
            matches!(
                e,
                RouteError::Unreachable {
                    cause: UnreachableCause::SealedOff,
                    ..
                }
            ),
            "{e}"
        );
    }
    // Wide enough for the vehicle (2r + h = 0.55 m), not for a clearance of c = 0.6 m (margin
    // twice the radius, h = 0.15 m): the proof at c holds below 2(c − h·√3/2) = 0.94 m.
    let wide_margin = RoutePlanner::new(RouteParams {
        margin_radius_factor: 2.0,
        cells_per_clearance: 4.0,
        ..RouteParams::default()
    })
    .unwrap();
    for at in [1.0, 1.05, 1.1] {
        let (map, s, g) = slot_world(SlotAxis::Y, 0.7, at);
        let e = wide_margin.plan(&map, &s, &g, r).unwrap_err();
        assert!(
            matches!(
                e,
                RouteError::Unreachable {
                    cause: UnreachableCause::TooNarrow { .. },
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("clearance of 0.6 m"), "{e}");
    }
}

/// A 0.6 m slot between two 1 m walls (x from 5 to 6, y from 4.7 to 5.3) in a 12 × 10 × 3 m
/// room; with a 0.2 m radius (c = 0.3 m) no free cell lies inside it.
fn narrow_corridor() -> StaticMap {
    StaticMap::from_shapes(
        bounds([12.0, 10.0, 3.0]),
        vec![
            aabox([5.0, 3.7, -1.0], [6.0, 4.7, 4.0]),
            aabox([5.0, 5.3, -1.0], [6.0, 6.3, 4.0]),
        ],
    )
    .unwrap()
}

/// A start inside the inflation leaves it by a segment that keeps the start's own clearance
/// (it used to snap to the nearest free cell across a wall, 0.022 m inside it); a goal inside
/// the inflation is joined the same way.
#[test]
fn ends_inside_the_inflation_are_joined_without_coming_closer_to_the_obstacles() {
    let map = narrow_corridor();
    let r = 0.2;
    let c = 0.3;
    for (sy, sx) in [(4.85, 5.7), (4.8, 5.5), (5.1, 5.2), (4.75, 5.9)] {
        let s = Vec3::new(sx, sy, 1.5);
        let keep = map.signed_distance(&s).min(c) - 1e-6;
        let g = Vec3::new(11.0, 8.0, 2.0);
        let route = planner().plan(&map, &s, &g, r).unwrap();
        assert!(route.start_inside_clearance());
        for w in route.points().windows(2) {
            assert!(
                map.segment_clear(&w[0], &w[1], keep),
                "start {s}: segment {} -> {} closer than {keep}",
                w[0],
                w[1]
            );
        }
        // The goal in the corridor, at least the radius from the walls.
        let goal = Vec3::new(sx, 4.95, 1.5);
        let keep_goal = map.signed_distance(&goal).min(c) - 1e-6;
        let route = planner()
            .plan(&map, &Vec3::new(1.0, 1.0, 1.0), &goal, r)
            .unwrap();
        let end = *route.points().last().unwrap();
        assert!(route.goal_gap_m() > 0.0);
        assert!(map.segment_clear(&end, &goal, keep_goal), "{end} -> {goal}");
        assert_clear(&map, &route);
    }
}

#[test]
fn a_goal_outside_the_bounds_or_inside_an_obstacle_is_a_verdict_with_a_nearest_route() {
    let map = wide_wall();
    let s = Vec3::new(2.0, 30.0, 5.0);
    let outside = Vec3::new(500.0, 30.0, 5.0);
    let (p, _) = run_sliced(&map, s, outside, 0.3, usize::MAX);
    let u = unreachable(&p);
    assert_eq!(u.cause, UnreachableCause::GoalOutsideBounds);
    let near = u.nearest.as_ref().unwrap();
    assert_clear(&map, near);
    assert!(
        near.points().last().unwrap().x > 115.0,
        "{:?}",
        near.points()
    );
    // Deep in a block, farther than the snap radius from any free cell: the search leaves the
    // block along the distance gradient and routes to its side.
    let block = StaticMap::from_shapes(
        bounds([40.0, 40.0, 10.0]),
        vec![aabox([10.0, 10.0, 0.0], [30.0, 30.0, 10.0])],
    )
    .unwrap();
    let buried = Vec3::new(20.0, 12.0, 5.0);
    let (p, _) = run_sliced(&block, Vec3::new(2.0, 2.0, 2.0), buried, 0.3, usize::MAX);
    let u = unreachable(&p);
    assert!(
        matches!(u.cause, UnreachableCause::GoalInsideObstacle { signed_distance_m } if (signed_distance_m + 2.0).abs() < 1e-9),
        "{:?}",
        u.cause
    );
    assert!(
        u.cause.to_string().contains("2 m inside an obstacle"),
        "{}",
        u.cause
    );
    let near = u.nearest.as_ref().unwrap();
    assert_clear(&block, near);
    assert!(near.goal_gap_m() < 3.0, "{}", near.goal_gap_m());
}

#[test]
fn huge_tiny_and_non_finite_coordinates_are_typed_errors_on_every_entry() {
    let map = wide_wall();
    let p = planner();
    let ok = Vec3::new(2.0, 30.0, 5.0);
    let route = GlobalRoute::from_points(vec![ok, ok + Vec3::x()]).unwrap();
    for bad in [1.3e154, 1.0e7, -2.0e6, f64::MAX, f64::NAN, f64::INFINITY] {
        let q = Vec3::new(bad, 30.0, 5.0);
        let typed = |e: RouteError| {
            assert!(
                matches!(
                    e,
                    RouteError::PointOutOfScale { .. } | RouteError::NonFinitePoint { .. }
                ),
                "{bad}: {e}"
            );
        };
        typed(p.plan(&map, &q, &ok, 0.3).unwrap_err());
        typed(p.plan(&map, &ok, &q, 0.3).unwrap_err());
        typed(p.start_search(&map, &q, &ok, 0.3).unwrap_err());
        typed(p.start_search(&map, &ok, &q, 0.3).unwrap_err());
        typed(GlobalRoute::from_points(vec![ok, q]).unwrap_err());
        typed(route.project(&q).unwrap_err());
        typed(route.project_after(&q, 0.0).unwrap_err());
        typed(route.progress(&q).unwrap_err());
        typed(route.remaining_length(&q).unwrap_err());
        typed(route.local_goal(&q, 5.0).unwrap_err());
        // Queries that answer a plain value stay finite and do not panic.
        let to = route.local_goal_from(0.5, 5.0).unwrap();
        let seen = route.last_in_sight(&map, &q, 0.0, to, 0.2);
        assert!(seen.point.iter().all(|c| c.is_finite()));
        assert!(route.point_at(bad).iter().all(|c| c.is_finite()));
        assert!(route.local_goal_from(bad, 5.0).is_ok());
        assert!(route.first_blocked(&map, 0.45, bad).is_ok());
    }
    let e = GlobalRoute::from_points(vec![ok, Vec3::new(1.3e154, 0.0, 0.0)]).unwrap_err();
    assert!(
        e.to_string().contains("1e6") || e.to_string().contains("1.00000e6"),
        "{e}"
    );
    // Tiny coordinates are ordinary ones.
    let tiny = Vec3::new(1e-300, 5e-324, 1e-310);
    let empty = StaticMap::empty(bounds([10.0, 10.0, 3.0])).unwrap();
    let r = p
        .plan(&empty, &tiny, &Vec3::new(5.0, 5.0, 1.0), 0.2)
        .unwrap();
    assert_eq!(r.points()[0], tiny);
    let r = GlobalRoute::from_points(vec![tiny, Vec3::new(1e-300, 0.0, 0.0)]).unwrap();
    assert!(r.length().is_finite());
    assert!(r.project(&tiny).is_ok());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(8))]

    /// Random slicings of the same search give the same answer and the same work total.
    #[test]
    fn slicing_never_changes_the_answer(seed in 0_u64..10_000, slices in proptest::collection::vec(1_usize..5000, 1..8)) {
        let (map, s, g) = random_map(seed, [8.0, 6.0, 3.0], 8, 0.1);
        let mut whole = planner().start_search(&map, &s, &g, 0.1).unwrap();
        let answer = whole.advance(&map, usize::MAX);
        let mut sliced = planner().start_search(&map, &s, &g, 0.1).unwrap();
        let mut k = 0;
        let got = loop {
            let p = sliced.advance(&map, slices[k % slices.len()]);
            k += 1;
            if !matches!(p, RouteProgress::Pending) {
                break p;
            }
        };
        prop_assert_eq!(got, answer);
        prop_assert_eq!(sliced.work_done(), whole.work_done());
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(
        std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(8)
    ))]

    /// A verdict is a proof: whatever the box, its wall thickness and its hole (sealed, too
    /// narrow, or wide enough), a goal declared unreachable at the clearance has no route at
    /// that clearance on a grid twice finer either (the proof's floods run on layers
    /// twice coarser than the fine grid and with bounds stamped from other cells' distances);
    /// a hole wide enough for the grid to resolve gives a route.
    #[test]
    fn a_verdict_is_never_given_where_a_finer_grid_finds_a_route(
        half in 0.8_f64..2.0,
        t in 0.02_f64..0.5,
        hole in prop_oneof![Just(0.0), 0.1_f64..1.6],
        r in 0.1_f64..0.3,
        side in any::<bool>(),
    ) {
        let centre = Vec3::new(7.0, 3.0, 3.0);
        let map = StaticMap::from_shapes(bounds([10.0, 6.0, 6.0]), box_with_hole(centre, half, t, hole).unwrap()).unwrap();
        let outside = Vec3::new(1.5, 3.0, 3.0);
        let (s, g) = if side { (outside, centre) } else { (centre, outside) };
        let answer = planner().plan(&map, &s, &g, r);
        let c = r * 1.5;
        if let Err(RouteError::Unreachable { cause, .. }) = &answer {
            let fine = RoutePlanner::new(RouteParams {
                cells_per_clearance: 4.0,
                coarse_factor: 1.0,
                ..RouteParams::default()
            })
            .unwrap();
            if let Ok(route) = fine.plan(&map, &s, &g, r) {
                prop_assert!(false, "{cause}, but a finer grid found {:?}", route.points());
            }
        }
        // A hole wider than 2c plus a fine cell (and the diagonal a box corner costs) is open.
        if hole > 2.0 * c + c / 2.0 * 3.0_f64.sqrt() + 0.05 {
            let route = answer.map_err(|e| TestCaseError::fail(format!("hole {hole}, c {c}: {e}")))?;
            assert_clear(&map, &route);
        }
    }
}

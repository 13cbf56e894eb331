//! Work units, time and the cost of one unit of work for the bench cases, on analytic shapes
//! and on the same E4 world as a point-cloud ESDF (0.2 m voxels), and the answer when the work
//! is sliced per planning cycle. A measurement aid: `cargo run --release -p trust-route
//! --example route_timing` (timings are indicative on a shared machine).

use std::time::Instant;

use trust_geometry::{StaticMap, Vec3};
use trust_route::scenes::{
    E4_START_GOAL, crazyflie_room, e4_like, sealed_goal_e4, sealed_goal_room, shape_cloud,
    slot_wall,
};
use trust_route::{RouteParams, RoutePlanner, RouteProgress};

/// Slice per call for the sliced run, in units of work.
const SLICE: usize = 20_000;

fn kind(p: &RouteProgress) -> String {
    match p {
        RouteProgress::Found(r) => format!("found {:.1} m", r.length()),
        RouteProgress::Unreachable(u) => format!("unreachable: {}", u.cause),
        RouteProgress::Failed(e) => format!("failed: {e}"),
        _ => "pending".to_owned(),
    }
}

fn measure(planner: &RoutePlanner, name: &str, map: &StaticMap, s: Vec3, g: Vec3, r: f64) {
    let t0 = Instant::now();
    let mut search = planner.start_search(map, &s, &g, r).expect("valid query");
    let p = search.advance(map, usize::MAX);
    let ms = t0.elapsed().as_secs_f64() * 1e3;
    let work = search.work_done();
    // Per slice: the slowest call.
    let mut sliced = planner.start_search(map, &s, &g, r).expect("valid query");
    let (mut calls, mut worst_ms) = (0, 0.0_f64);
    let q = loop {
        let t = Instant::now();
        let q = sliced.advance(map, SLICE);
        worst_ms = worst_ms.max(t.elapsed().as_secs_f64() * 1e3);
        calls += 1;
        if !matches!(q, RouteProgress::Pending) {
            break q;
        }
    };
    assert_eq!(p, q, "slicing changed the answer");
    println!(
        "{name:<28} {work:>9} units {ms:>9.1} ms {:>6.3} us/unit | {calls:>4} slices of {SLICE}, slowest {worst_ms:.1} ms | {}",
        1e3 * ms / work.max(1) as f64,
        kind(&p)
    );
}

fn main() {
    let planner = RoutePlanner::new(RouteParams::default()).unwrap();
    let (s, t) = (Vec3::from(E4_START_GOAL[0]), Vec3::from(E4_START_GOAL[1]));
    println!("-- analytic shapes");
    let e4 = e4_like(0, false).expect("E4-like map");
    measure(&planner, "e4_forest_250m", &e4, s, t, 0.3);
    let e4_wall = e4_like(0, true).expect("E4-like map");
    measure(&planner, "e4_forest_with_30m_wall", &e4_wall, s, t, 0.3);
    let room = crazyflie_room().expect("room");
    let (rs, rt) = (Vec3::new(1.0, 1.0, 1.0), Vec3::new(7.0, 1.0, 1.5));
    measure(&planner, "room_8x6x3_r0.1", &room, rs, rt, 0.1);
    let (m, a, b) = sealed_goal_room().expect("sealed room");
    measure(&planner, "sealed_goal_room", &m, a, b, 0.3);
    let (m, a, b) = sealed_goal_e4(0).expect("sealed E4");
    measure(&planner, "sealed_goal_e4", &m, a, b, 0.3);
    let (m, a, b) = slot_wall(0.76).expect("slot wall");
    measure(&planner, "slot_wall_0.76m_r0.2", &m, a, b, 0.2);

    println!("-- point-cloud ESDF (0.2 m voxels)");
    for (name, shapes_map) in [
        ("e4_forest_with_30m_wall", e4_wall),
        ("sealed_goal_e4", sealed_goal_e4(0).expect("sealed E4").0),
    ] {
        let t0 = Instant::now();
        let cloud = shape_cloud(&shapes_map, 0.1);
        let map = StaticMap::empty(*shapes_map.bounds())
            .expect("bounds")
            .with_point_cloud(&cloud, 0.2)
            .expect("ESDF");
        println!(
            "({} points, ESDF built in {:.1} s)",
            cloud.len(),
            t0.elapsed().as_secs_f64()
        );
        let goal = if name == "sealed_goal_e4" {
            s + Vec3::new(35.0, 0.0, 0.0)
        } else {
            t
        };
        measure(&planner, name, &map, s, goal, 0.3);
    }
}

//! Route planning on an E4-size world (250 × 75 × 20 m, radius 0.3 m) and on a Crazyflie room
//! (8 × 6 × 3 m, radius 0.1 m), and the tail: the time to the verdict for a goal sealed in a
//! closed box 35 m away (a 60 × 20 × 10 m room and an E4 world) and the route through a full
//! wall with one slot. Work units per case: `cargo run --release -p trust-route --example
//! route_timing`. Smoke run: `cargo bench -p trust-route -- --test`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use trust_geometry::{StaticMap, Vec3};
use trust_route::scenes::{crazyflie_room, e4_like, sealed_goal_e4, sealed_goal_room, slot_wall};
use trust_route::{RouteParams, RoutePlanner, RouteProgress};

/// The search run to its answer in one call.
fn answer(planner: &RoutePlanner, map: &StaticMap, s: &Vec3, g: &Vec3, r: f64) -> RouteProgress {
    planner
        .start_search(map, s, g, r)
        .expect("valid query")
        .advance(map, usize::MAX)
}

fn bench(c: &mut Criterion) {
    let planner = RoutePlanner::new(RouteParams::default()).unwrap();
    let mut g = c.benchmark_group("route");
    g.sample_size(10);
    let (s, t) = (Vec3::new(2.0, 37.5, 5.0), Vec3::new(248.0, 37.5, 5.0));
    let e4 = e4_like(0, false).expect("E4-like map");
    g.bench_function("e4_forest_250m", |b| {
        b.iter(|| black_box(planner.plan(&e4, &s, &t, 0.3)))
    });
    let e4_wall = e4_like(0, true).expect("E4-like map");
    g.bench_function("e4_forest_with_30m_wall", |b| {
        b.iter(|| black_box(planner.plan(&e4_wall, &s, &t, 0.3)))
    });
    let room = crazyflie_room().expect("room map");
    let (rs, rt) = (Vec3::new(1.0, 1.0, 1.0), Vec3::new(7.0, 1.0, 1.5));
    g.bench_function("room_8x6x3_r0.1", |b| {
        b.iter(|| black_box(planner.plan(&room, &rs, &rt, 0.1)))
    });
    g.finish();

    let mut g = c.benchmark_group("route_tail");
    g.sample_size(10);
    let (room, s, t) = sealed_goal_room().expect("sealed room");
    g.bench_function("sealed_goal_room_60x20x10_verdict", |b| {
        b.iter(|| black_box(answer(&planner, &room, &s, &t, 0.3)))
    });
    let (e4s, s, t) = sealed_goal_e4(0).expect("sealed E4");
    g.bench_function("sealed_goal_e4_verdict", |b| {
        b.iter(|| black_box(answer(&planner, &e4s, &s, &t, 0.3)))
    });
    let (slot, s, t) = slot_wall(0.76).expect("slot wall");
    g.bench_function("full_wall_one_0.76m_slot_r0.2", |b| {
        b.iter(|| black_box(answer(&planner, &slot, &s, &t, 0.2)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

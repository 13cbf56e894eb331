//! Route planning on an E4-size world (250 × 75 × 20 m, radius 0.3 m) and on a Crazyflie room
//! (8 × 6 × 3 m, radius 0.1 m). Smoke run: `cargo bench -p trust-route -- --test`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use trust_geometry::Vec3;
use trust_route::scenes::{crazyflie_room, e4_like};
use trust_route::{RouteParams, RoutePlanner};

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
}

criterion_group!(benches, bench);
criterion_main!(benches);

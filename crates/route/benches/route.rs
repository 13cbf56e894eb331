//! Route planning on an E4-size world (250 × 75 × 20 m, radius 0.3 m) and on a Crazyflie room
//! (8 × 6 × 3 m, radius 0.1 m). Smoke run: `cargo bench -p trust-route -- --test`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trust_geometry::{AaBox, Aabb, Cylinder, Shape, StaticMap, Vec3};
use trust_route::{RouteParams, RoutePlanner};

/// An E4-like world: 40 blocks, 40 walls and 320 full-height pillars, 10 m kept free around
/// start and goal, plus (if `wall`) a 30 m wide full-height wall across the straight line.
fn e4_like(seed: u64, wall: bool) -> StaticMap {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut shapes: Vec<Shape> = Vec::new();
    let x = |rng: &mut ChaCha8Rng| rng.random_range(12.0..238.0);
    let y = |rng: &mut ChaCha8Rng| rng.random_range(0.0..75.0);
    for _ in 0..40 {
        let c = Vec3::new(x(&mut rng), y(&mut rng), rng.random_range(2.0..8.0));
        let half = Vec3::new(
            rng.random_range(1.0..3.0),
            rng.random_range(1.0..3.0),
            rng.random_range(1.0..4.0),
        );
        shapes.push(AaBox::from_center_half_extents(c, half).unwrap().into());
    }
    for _ in 0..40 {
        let c = Vec3::new(x(&mut rng), y(&mut rng), 10.0);
        let half = if rng.random_bool(0.5) {
            Vec3::new(0.3, rng.random_range(2.0..6.0), 10.0)
        } else {
            Vec3::new(rng.random_range(2.0..6.0), 0.3, 10.0)
        };
        shapes.push(AaBox::from_center_half_extents(c, half).unwrap().into());
    }
    for _ in 0..320 {
        let c = Vec3::new(x(&mut rng), y(&mut rng), 10.0);
        shapes.push(
            Cylinder::new(c, rng.random_range(0.3..0.8), 10.0)
                .unwrap()
                .into(),
        );
    }
    if wall {
        let c = Vec3::new(27.0, 37.5, 10.0);
        shapes.push(
            AaBox::from_center_half_extents(c, Vec3::new(0.5, 15.0, 10.0))
                .unwrap()
                .into(),
        );
    }
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(250.0, 75.0, 20.0)).unwrap();
    StaticMap::from_shapes(bounds, shapes).unwrap()
}

/// An 8 × 6 × 3 m room with four thin pillars and a wall half across the middle.
fn room() -> StaticMap {
    let mut shapes: Vec<Shape> = [(2.5, 2.0), (2.5, 4.0), (5.5, 2.0), (5.5, 4.0)]
        .iter()
        .map(|&(x, y)| {
            Cylinder::new(Vec3::new(x, y, 1.5), 0.05, 1.5)
                .unwrap()
                .into()
        })
        .collect();
    shapes.push(
        AaBox::new(Vec3::new(3.9, 0.0, 0.0), Vec3::new(4.1, 4.5, 3.0))
            .unwrap()
            .into(),
    );
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(8.0, 6.0, 3.0)).unwrap();
    StaticMap::from_shapes(bounds, shapes).unwrap()
}

fn bench(c: &mut Criterion) {
    let planner = RoutePlanner::new(RouteParams::default()).unwrap();
    let mut g = c.benchmark_group("route");
    g.sample_size(10);
    let (s, t) = (Vec3::new(2.0, 37.5, 5.0), Vec3::new(248.0, 37.5, 5.0));
    let e4 = e4_like(0, false);
    g.bench_function("e4_forest_250m", |b| {
        b.iter(|| black_box(planner.plan(&e4, &s, &t, 0.3)))
    });
    let e4_wall = e4_like(0, true);
    g.bench_function("e4_forest_with_30m_wall", |b| {
        b.iter(|| black_box(planner.plan(&e4_wall, &s, &t, 0.3)))
    });
    let room = room();
    let (rs, rt) = (Vec3::new(1.0, 1.0, 1.0), Vec3::new(7.0, 1.0, 1.5));
    g.bench_function("room_8x6x3_r0.1", |b| {
        b.iter(|| black_box(planner.plan(&room, &rs, &rt, 0.1)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

//! Micro-benchmarks for the queries planners run in inner loops, and for building an ESDF.
//! Smoke run: `cargo bench -p trust-geometry -- --test`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trust_geometry::{AaBox, Aabb, Cylinder, Esdf, Shape, Sphere, StaticMap, Vec3};

fn bounds() -> Aabb {
    Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(100.0, 100.0, 10.0)).expect("valid bounds")
}

fn random_point(rng: &mut ChaCha8Rng) -> Vec3 {
    Vec3::new(
        rng.random_range(0.0..100.0),
        rng.random_range(0.0..100.0),
        rng.random_range(0.0..10.0),
    )
}

/// 1000 random spheres, cylinders and boxes in a 100 x 100 x 10 m world.
fn thousand_shape_map() -> StaticMap {
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let shapes: Vec<Shape> = (0..1000)
        .map(|i| {
            let c = random_point(&mut rng);
            match i % 3 {
                0 => Sphere::new(c, 0.5).expect("valid").into(),
                1 => Cylinder::new(c, 0.4, 3.0).expect("valid").into(),
                _ => AaBox::from_center_half_extents(c, Vec3::new(0.5, 0.5, 1.0))
                    .expect("valid")
                    .into(),
            }
        })
        .collect();
    StaticMap::from_shapes(bounds(), shapes).expect("valid map")
}

fn map_queries(c: &mut Criterion) {
    let map = thousand_shape_map();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let points: Vec<Vec3> = (0..256).map(|_| random_point(&mut rng)).collect();
    let segments: Vec<(Vec3, Vec3)> = (0..256)
        .map(|_| {
            let a = random_point(&mut rng);
            let d = Vec3::new(
                rng.random_range(-5.0..5.0),
                rng.random_range(-5.0..5.0),
                rng.random_range(-1.0..1.0),
            );
            (a, a + d)
        })
        .collect();
    c.bench_function("map1000/distance_and_gradient", |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) % points.len();
            black_box(map.distance_and_gradient(black_box(&points[k])))
        })
    });
    c.bench_function("map1000/is_free_0.5", |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) % points.len();
            black_box(map.is_free(black_box(&points[k]), 0.5))
        })
    });
    c.bench_function("map1000/segment_clear_5m_0.5", |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) % segments.len();
            let (a, e) = &segments[k];
            black_box(map.segment_clear(a, e, 0.5))
        })
    });
    let mut out = Vec::new();
    c.bench_function("map1000/shapes_near_5m_box", |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) % segments.len();
            let (a, e) = &segments[k];
            map.shapes_near(&Aabb::from_segment(a, e).inflated(1.0), &mut out);
            black_box(out.len())
        })
    });
}

fn esdf(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let b = Aabb::new(Vec3::zeros(), Vec3::new(10.0, 10.0, 10.0)).expect("valid bounds");
    let points: Vec<Vec3> = (0..5000)
        .map(|_| 10.0 * Vec3::new(rng.random(), rng.random(), rng.random()))
        .collect();
    let mut group = c.benchmark_group("esdf");
    group.sample_size(10);
    group.bench_function("build_100^3", |bch| {
        bch.iter(|| black_box(Esdf::from_points(&b, black_box(&points), 0.1).expect("valid grid")))
    });
    group.finish();
    let field = Esdf::from_points(&b, &points, 0.1).expect("valid grid");
    let queries: Vec<Vec3> = (0..256)
        .map(|_| 10.0 * Vec3::new(rng.random(), rng.random(), rng.random()))
        .collect();
    c.bench_function("esdf/distance_and_gradient", |bch| {
        let mut k = 0;
        bch.iter(|| {
            k = (k + 1) % queries.len();
            black_box(field.distance_and_gradient(black_box(&queries[k])))
        })
    });
}

criterion_group!(benches, map_queries, esdf);
criterion_main!(benches);

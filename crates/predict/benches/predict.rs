//! Micro-benchmarks of the hot trust-predict queries: the DDF evaluation used inside the trajectory
//! optimizer, the PDC visibility and membership tests used by DEV-PRM, surface sampling, and one
//! tracker step. Smoke mode: `cargo bench -p trust-predict -- --test`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use trust_predict::{CvEkf, EkfParams, Forecast, ObstacleShape, Vec3};

fn forecasts() -> [Forecast; 2] {
    let sphere = Forecast::sphere(
        Vec3::new(1.0, 2.0, 1.5),
        Vec3::new(1.0, -0.5, 0.2),
        0.0,
        0.5,
        0.2,
        0.3,
    )
    .unwrap();
    let cylinder = Forecast::new(
        ObstacleShape::Cylinder { half_height: 1.0 },
        Vec3::new(1.0, 2.0, 1.0),
        Vec3::new(1.0, -0.5, 0.0),
        0.0,
        0.4,
        0.2,
        0.3,
    )
    .unwrap();
    [sphere, cylinder]
}

fn bench(c: &mut Criterion) {
    let names = ["sphere", "cylinder"];
    for (name, f) in names.iter().zip(forecasts()) {
        let pdc = f.pdc(2.0).unwrap();
        let (a, b) = (Vec3::new(-3.0, 0.5, 1.2), Vec3::new(5.0, 1.5, 1.4));
        let p = Vec3::new(2.5, 2.5, 1.3);
        c.bench_function(&format!("ddf_distance_and_gradients/{name}"), |bch| {
            bch.iter(|| black_box(&f).distance_and_gradients(black_box(&p), black_box(0.7)))
        });
        c.bench_function(&format!("pdc_segment_clear/{name}"), |bch| {
            bch.iter(|| black_box(&pdc).segment_clear(black_box(&a), black_box(&b), black_box(0.3)))
        });
        let (fa, fb) = (Vec3::new(-3.0, 9.0, 1.2), Vec3::new(5.0, 8.0, 1.4));
        c.bench_function(&format!("pdc_segment_clear_far/{name}"), |bch| {
            bch.iter(|| {
                black_box(&pdc).segment_clear(black_box(&fa), black_box(&fb), black_box(0.3))
            })
        });
        c.bench_function(&format!("pdc_point_clear/{name}"), |bch| {
            bch.iter(|| black_box(&pdc).point_clear(black_box(&p), black_box(0.3)))
        });
        c.bench_function(&format!("pdc_signed_distance/{name}"), |bch| {
            bch.iter(|| black_box(&pdc).signed_distance(black_box(&p)))
        });
        let region = trust_predict::Aabb {
            min: Vec3::repeat(-10.0),
            max: Vec3::repeat(10.0),
        };
        let mut out = Vec::with_capacity(66);
        c.bench_function(&format!("pdc_surface_samples_8x8/{name}"), |bch| {
            bch.iter(|| {
                out.clear();
                black_box(&pdc)
                    .surface_samples_into(8, 8, 0.1, &region, &mut out)
                    .unwrap();
                black_box(out.len())
            })
        });
    }
    let mut ekf = CvEkf::new(0.0, Vec3::zeros(), EkfParams::default()).unwrap();
    let mut t = 0.0;
    c.bench_function("ekf_step_with_measurement", |bch| {
        bch.iter(|| {
            t += 0.05;
            ekf.step(t, Some(black_box(Vec3::new(0.05 * t, 0.0, 1.0))))
                .unwrap();
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);

//! Criterion benches: one DEV-PRM search and one V-PRM search on an E1 scene (K = 10), the UVD test
//! the roadmap runs for every connector candidate (two connectors of the same guards, on the same and
//! on opposite sides of a moving obstacle's PDC), one TVD check between two trajectories among the E1
//! obstacles, and the segment test of one predictive directional cone (`trust_predict::Pdc`).
//!
//! `cargo bench -p trust-topo-prm` for medians; `cargo bench -p trust-topo-prm -- --test` runs each
//! once (CI smoke mode).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use rand::SeedableRng;

use trust_core::{PathFrontend, PolyTraj, Rng, Scene, StaticMap, Vec3};
use trust_topo_prm::visibility::Obstacles;
use trust_topo_prm::{DevPrm, DevPrmParams, Vprm, VprmParams, scenes, tvd, uvd};

fn world() -> scenes::RandomScene {
    scenes::random_dynamic_scene(
        10,
        &scenes::SceneParams::default(),
        &mut Rng::seed_from_u64(42),
    )
    .expect("default scene params are valid")
}

fn bench_frontends(c: &mut Criterion) {
    let w = world();
    let scene = Scene::new(&w.map, &w.forecasts, 0.0).expect("valid scene");
    let devprm = DevPrm::new(DevPrmParams {
        budget_ms: 20.0,
        ..DevPrmParams::default()
    })
    .expect("valid params");
    let vprm = Vprm::new(VprmParams {
        budget_ms: 20.0,
        ..VprmParams::default()
    })
    .expect("valid params");
    c.bench_function("devprm_search_e1_k10", |b| {
        let mut rng = Rng::seed_from_u64(7);
        b.iter(|| {
            black_box(
                devprm
                    .search(&w.query, &scene, &mut rng)
                    .expect("valid query"),
            )
        });
    });
    c.bench_function("vprm_search_e1_k10", |b| {
        let mut rng = Rng::seed_from_u64(7);
        b.iter(|| {
            black_box(
                vprm.search(&w.query, &scene, &mut rng)
                    .expect("valid query"),
            )
        });
    });
}

/// The connector-redundancy test of the roadmap: `[start, via, goal]` against `[start, via', goal]`
/// around the PDC of a ball crossing the straight line (UVD at 0.1 m, threshold 0).
fn bench_uvd_connectors(c: &mut Criterion) {
    let map = StaticMap::new(
        trust_core::Aabb::new(Vec3::zeros(), Vec3::new(20.0, 20.0, 10.0)).expect("valid box"),
    )
    .expect("valid map");
    let f = trust_core::Forecast::sphere(
        Vec3::new(10.0, 9.0, 5.0),
        Vec3::new(0.0, 1.0, 0.0),
        0.0,
        1.0,
        0.0,
        0.2,
    )
    .expect("valid forecast");
    let obstacles = Obstacles::with_forecast_cones(&map, &[f], 0.0, 2.0).expect("valid forecast");
    let (s, g) = (Vec3::new(1.0, 10.0, 5.0), Vec3::new(19.0, 10.0, 5.0));
    let above = [s, Vec3::new(9.0, 13.5, 5.0), g];
    let above2 = [s, Vec3::new(11.0, 14.5, 5.3), g];
    let below = [s, Vec3::new(10.0, 6.5, 5.0), g];
    let mut scratch = uvd::UvdScratch::default();
    c.bench_function("uvd_connectors_same_side", |b| {
        b.iter(|| {
            black_box(uvd::polylines_equivalent_among(
                &obstacles,
                &above,
                &above2,
                0.1,
                0.0,
                &mut scratch,
            ))
        });
    });
    c.bench_function("uvd_connectors_opposite_sides", |b| {
        b.iter(|| {
            black_box(uvd::polylines_equivalent_among(
                &obstacles,
                &above,
                &below,
                0.1,
                0.0,
                &mut scratch,
            ))
        });
    });
}

/// A straight constant-velocity trajectory from `a` to `b` over `duration` seconds.
fn straight(a: Vec3, b: Vec3, duration: f64) -> PolyTraj {
    let mut piece = [Vec3::zeros(); 6];
    piece[0] = a;
    piece[1] = (b - a) / duration;
    PolyTraj::new(0.0, vec![duration], vec![piece]).expect("valid trajectory")
}

fn bench_tvd(c: &mut Criterion) {
    let w = world();
    let scene = Scene::new(&w.map, &w.forecasts, 0.0).expect("valid scene");
    let (s, g) = (w.query.start.p, w.query.goal);
    let side = Vec3::new(0.0, 0.0, 2.0);
    let t1 = straight(s, g + side, 2.0);
    let t2 = straight(s, g - side, 2.0);
    c.bench_function("tvd_check_2s_dt005_k10", |b| {
        b.iter(|| black_box(tvd::equivalent(&t1, &t2, &scene, 0.05).expect("timed curves")));
    });
}

/// 1000 random segments against one moving-sphere PDC (`trust_predict::Pdc::segment_clear`).
fn bench_cone_tests(c: &mut Criterion) {
    use rand::Rng as _;
    let f = trust_core::Forecast::sphere(
        Vec3::new(10.0, 10.0, 5.0),
        Vec3::new(2.0, -1.0, 0.0),
        0.0,
        1.0,
        0.0,
        0.2,
    )
    .expect("valid forecast");
    let cone = trust_predict::Pdc::over_window(&f, 0.0, 2.0).expect("valid window");
    let mut rng = Rng::seed_from_u64(3);
    let mut point = || {
        Vec3::new(
            rng.random_range(0.0..20.0),
            rng.random_range(0.0..20.0),
            rng.random_range(3.0..7.0),
        )
    };
    let segments: Vec<(Vec3, Vec3)> = (0..1000).map(|_| (point(), point())).collect();
    c.bench_function("cone_segment_clear_x1000", |b| {
        b.iter(|| {
            segments
                .iter()
                .filter(|(p, q)| cone.segment_clear(p, q, 0.1))
                .count()
        });
    });
}

criterion_group!(
    benches,
    bench_frontends,
    bench_uvd_connectors,
    bench_tvd,
    bench_cone_tests
);
criterion_main!(benches);

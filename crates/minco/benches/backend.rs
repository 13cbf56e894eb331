//! Benchmarks of the cost evaluation and the backends (design.md §6).
//!
//! - `cost_eval/representative_16x17_5spheres`: one full evaluation of the UTF-MINCO objective
//!   (MINCO solve, trapezoidal penalties at 16 pieces × 17 samples against 5 moving spheres plus
//!   speed and acceleration, jerk energy, adjoint propagation to every decision variable) on the
//!   reference's representative problem (waypoints `q_i = (2i, 3 sin i, 1 + 0.5 cos i)`,
//!   `T_i = 0.5 s`). C++ anchor (GCOPTER): 17.2 µs.
//! - `cost_eval/representative_16x17_free`: the same without obstacles (broad phase only).
//! - `solve/utf_minco_e2_dynamic`, `solve/minco_e2_dynamic`, `solve/utf_minco_e2_static`: one
//!   complete cold `optimize` call on the E2 scenes from the guide path (target for UTF-MINCO
//!   dynamic: ≤ 1 ms median).
//! - `solve/utf_minco_e2_dynamic_warm`, `solve/utf_minco_e2_static_warm`: the manager's common
//!   case, a re-solve one replanning period (0.1 s) later from the state the previous solution
//!   reaches then, warm-started from that solution (`InitialGuess::WarmStart`).
//! - `solve/utf_minco_random_dynamic_x8`, `solve/utf_minco_random_static_x8`: cold solves of the
//!   first 8 random E2-like scenes of each kind (`scenes::random_e2_dynamic` / `random_e2_static`,
//!   seeds 0..8), all 8 per iteration: a check on a spread of scenes rather than one case. The
//!   per-scene distribution over 60 scenes is `examples/e2_compare.rs --random 60`.
//!
//! Smoke mode: `cargo bench -p trust-minco --bench backend -- --test`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trust_core::{
    Aabb, Forecast, InitialGuess, Limits, PolyTraj, Scene, State, StaticMap, TrajRequest,
    TrajectoryBackend, Vec3,
};
use trust_minco::backend::{Minco, UtfMinco, UtfMincoObjective, UtfMincoParams};
use trust_minco::scenes::{E2Case, e2_dynamic, e2_static, random_e2_dynamic, random_e2_static};

/// A random scene generator of `trust_minco::scenes`.
type DrawScene = fn(&mut ChaCha8Rng) -> E2Case;

const PIECES: usize = 16;

fn reference_waypoints() -> Vec<Vec3> {
    (1..PIECES)
        .map(|i| {
            let x = i as f64;
            Vec3::new(2.0 * x, 3.0 * x.sin(), 1.0 + 0.5 * x.cos())
        })
        .collect()
}

/// Five slowly moving spheres placed on the reference path at 1.5, 3, 4.5, 6 and 7.5 s, so that
/// every one of them survives the broad phase of several pieces and is penetrated.
fn reference_spheres() -> Vec<Forecast> {
    let waypoints = reference_waypoints();
    (1..=5)
        .map(|k| {
            let p = waypoints[3 * k - 1];
            Forecast::sphere(
                p + Vec3::new(0.3, 0.4, 0.0),
                Vec3::new(0.2, -0.3, 0.0),
                0.0,
                1.0,
                0.2,
                0.05,
            )
            .expect("valid sphere")
        })
        .collect()
}

fn bench_cost_eval(c: &mut Criterion) {
    let map = StaticMap::empty(Aabb {
        min: Vec3::new(-10.0, -10.0, -10.0),
        max: Vec3::new(50.0, 10.0, 10.0),
    })
    .expect("bounds");
    let spheres = reference_spheres();
    let start = State::at_rest(0.0, Vec3::new(0.0, 0.0, 1.0));
    let goal = Vec3::new(2.0 * PIECES as f64, 0.0, 1.0);
    let limits = Limits::new(5.0, 8.0).expect("limits");
    let params = UtfMincoParams::default();
    let waypoints = reference_waypoints();
    let mut group = c.benchmark_group("cost_eval");
    for (name, forecasts) in [
        ("representative_16x17_5spheres", &spheres[..]),
        ("representative_16x17_free", &[][..]),
    ] {
        let scene = Scene::new(&map, forecasts, 0.0).expect("scene");
        let mut f = UtfMincoObjective::new(&scene, &start, goal, limits, &params, PIECES)
            .expect("objective");
        let mut x = vec![0.0; f.dimension()];
        f.encode(
            &waypoints,
            &goal,
            &Vec3::zeros(),
            0.5 * PIECES as f64,
            &mut x,
        )
        .expect("encode");
        let mut g = vec![0.0; x.len()];
        let cost = f.eval(&x, &mut g);
        assert!(cost.is_finite());
        if !forecasts.is_empty() {
            assert!(f.breakdown().io > 0.0, "the spheres must be penetrated");
        }
        group.bench_function(name, |b| {
            b.iter(|| black_box(f.eval(black_box(&x), &mut g)))
        });
    }
    group.finish();
}

/// Replanning period of the warm re-solve benchmarks (s).
const REPLAN_PERIOD_S: f64 = 0.1;

fn solve(case: &E2Case, backend: &dyn TrajectoryBackend) -> PolyTraj {
    let guide = case.guide();
    let req = TrajRequest {
        start: case.start,
        goal: case.goal,
        limits: case.limits,
        initial: InitialGuess::Guide(&guide),
        deadline: None,
        horizon_s: None,
        max_evaluations: None,
    };
    backend
        .optimize(&req, &case.scene())
        .expect("E2 solves")
        .traj
}

/// Re-solves `REPLAN_PERIOD_S` after the start of `previous`, warm-started from it.
fn warm_resolve(case: &E2Case, backend: &dyn TrajectoryBackend, previous: &PolyTraj) -> f64 {
    let t = previous.t_start() + REPLAN_PERIOD_S;
    let req = TrajRequest {
        start: previous.state(t),
        goal: case.goal,
        limits: case.limits,
        initial: InitialGuess::WarmStart(previous),
        deadline: None,
        horizon_s: None,
        max_evaluations: None,
    };
    let scene = Scene {
        t0: t,
        ..case.scene()
    };
    backend
        .optimize(&req, &scene)
        .expect("E2 re-solves")
        .traj
        .duration()
}

fn bench_solve(c: &mut Criterion) {
    let (dynamic, stat) = (e2_dynamic(), e2_static());
    let (utf, minco) = (UtfMinco::default(), Minco::default());
    let mut group = c.benchmark_group("solve");
    group.sample_size(20);
    group.bench_function("utf_minco_e2_dynamic", |b| {
        b.iter(|| black_box(solve(&dynamic, &utf).duration()))
    });
    group.bench_function("minco_e2_dynamic", |b| {
        b.iter(|| black_box(solve(&dynamic, &minco).duration()))
    });
    group.bench_function("utf_minco_e2_static", |b| {
        b.iter(|| black_box(solve(&stat, &utf).duration()))
    });
    let previous = solve(&dynamic, &utf);
    group.bench_function("utf_minco_e2_dynamic_warm", |b| {
        b.iter(|| black_box(warm_resolve(&dynamic, &utf, &previous)))
    });
    let previous = solve(&stat, &utf);
    group.bench_function("utf_minco_e2_static_warm", |b| {
        b.iter(|| black_box(warm_resolve(&stat, &utf, &previous)))
    });
    let kinds: [(&str, DrawScene); 2] = [
        ("utf_minco_random_dynamic_x8", random_e2_dynamic),
        ("utf_minco_random_static_x8", random_e2_static),
    ];
    for (name, draw) in kinds {
        let cases: Vec<E2Case> = (0..8)
            .map(|seed| draw(&mut ChaCha8Rng::seed_from_u64(seed)))
            .collect();
        group.bench_function(name, |b| {
            b.iter(|| {
                cases
                    .iter()
                    .map(|case| solve(case, &utf).duration())
                    .sum::<f64>()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_cost_eval, bench_solve);
criterion_main!(benches);

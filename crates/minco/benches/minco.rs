//! MINCO s = 3 micro-benchmarks on the reference family (`shared/reference/minco-lbfgs.md`):
//! head (0, 0, 1) and tail (2n, 0, 1) at rest, `q_i = (2i, 3 sin i, 1 + 0.5 cos i)`, `T_i = 0.5`.
//!
//! Groups (per n = 8, 16, 32, 64), matching the C++ anchor's table:
//! - `coefficients`: set + build + factorize + solve;
//! - `energy_grads_propagation`: energy, `∂E/∂c`, explicit `∂E/∂T`, and the adjoint propagation to
//!   waypoints, durations and head/tail (coefficients already solved);
//! - `whole_chain`: both of the above.
//! - `library_lu`: why we have our own banded LU — the same MINCO system `A(T) c = b` (6n × 6n,
//!   3 right-hand sides) factorized and solved by faer's dense partial-pivoting LU (the fastest
//!   pure-Rust dense LU we know; nalgebra has no banded solver either), against our general
//!   [`BandedMatrix`] and the structured elimination inside [`MincoS3`] (`coefficients`).

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use faer::Mat;
use faer::prelude::Solve;
use nalgebra::Vector3;
use trust_minco::BandedMatrix;
use trust_minco::minco::{BoundaryState, MincoGrad, MincoS3};

struct Problem {
    head: BoundaryState,
    tail: BoundaryState,
    waypoints: Vec<Vector3<f64>>,
    durations: Vec<f64>,
}

fn reference_problem(n: usize) -> Problem {
    let rest = |p: Vector3<f64>| [p, Vector3::zeros(), Vector3::zeros()];
    Problem {
        head: rest(Vector3::new(0.0, 0.0, 1.0)),
        tail: rest(Vector3::new(2.0 * n as f64, 0.0, 1.0)),
        waypoints: (1..n)
            .map(|i| {
                let x = i as f64;
                Vector3::new(2.0 * x, 3.0 * x.sin(), 1.0 + 0.5 * x.cos())
            })
            .collect(),
        durations: vec![0.5; n],
    }
}

/// Preallocated cost-evaluation buffers, as an optimizer would hold them.
struct Buffers {
    grad_c: Vec<Vector3<f64>>,
    grad_t: Vec<f64>,
    grad: MincoGrad,
}

impl Buffers {
    fn new(n: usize) -> Self {
        Self {
            grad_c: vec![Vector3::zeros(); 6 * n],
            grad_t: vec![0.0; n],
            grad: MincoGrad::new(n),
        }
    }
}

fn solve(minco: &mut MincoS3, p: &Problem) {
    minco
        .solve(
            black_box(&p.head),
            black_box(&p.tail),
            black_box(&p.waypoints),
            black_box(&p.durations),
        )
        .expect("reference problem solves");
}

fn energy_grads_propagation(minco: &mut MincoS3, b: &mut Buffers) -> f64 {
    b.grad_c.fill(Vector3::zeros());
    b.grad_t.fill(0.0);
    let energy = minco
        .accumulate_energy_grad(1.0, &mut b.grad_c, &mut b.grad_t)
        .expect("buffers sized");
    minco
        .propagate_grad(&b.grad_c, &b.grad_t, &mut b.grad)
        .expect("solved");
    energy
}

fn bench_minco(c: &mut Criterion) {
    let sizes = [8usize, 16, 32, 64];
    let mut group = c.benchmark_group("coefficients");
    for &n in &sizes {
        let p = reference_problem(n);
        let mut minco = MincoS3::new(n).expect("n >= 1");
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |bench, _| {
            bench.iter(|| {
                solve(&mut minco, &p);
                black_box(minco.coeffs()[6 * n - 1]);
            });
        });
    }
    group.finish();

    let mut group = c.benchmark_group("energy_grads_propagation");
    for &n in &sizes {
        let p = reference_problem(n);
        let mut minco = MincoS3::new(n).expect("n >= 1");
        solve(&mut minco, &p);
        let mut buffers = Buffers::new(n);
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |bench, _| {
            bench.iter(|| {
                black_box(energy_grads_propagation(&mut minco, &mut buffers));
                black_box(buffers.grad.durations[0]);
            });
        });
    }
    group.finish();

    let mut group = c.benchmark_group("whole_chain");
    for &n in &sizes {
        let p = reference_problem(n);
        let mut minco = MincoS3::new(n).expect("n >= 1");
        let mut buffers = Buffers::new(n);
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |bench, _| {
            bench.iter(|| {
                solve(&mut minco, &p);
                black_box(energy_grads_propagation(&mut minco, &mut buffers));
                black_box(buffers.grad.durations[0]);
            });
        });
    }
    group.finish();
}

fn bench_library_lu(c: &mut Criterion) {
    // Single-threaded, like our solver (and fair to faer: no thread-pool overhead on 96 × 96).
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = c.benchmark_group("library_lu");
    for &n in &[8usize, 16, 32] {
        let p = reference_problem(n);
        let mut minco = MincoS3::new(n).expect("n >= 1");
        solve(&mut minco, &p);
        let (banded, rhs): (BandedMatrix, Vec<Vector3<f64>>) = minco.system();
        let size = banded.size();
        let dense = Mat::from_fn(size, size, |i, j| banded.get(i, j).unwrap_or(0.0));
        let dense_rhs = Mat::from_fn(size, 3, |i, j| rhs[i][j]);
        group.bench_with_input(BenchmarkId::new("faer_dense_plu", n), &n, |bench, _| {
            bench.iter(|| {
                let lu = black_box(&dense).partial_piv_lu();
                black_box(lu.solve(black_box(&dense_rhs)));
            });
        });
        group.bench_with_input(
            BenchmarkId::new("ours_general_banded", n),
            &n,
            |bench, _| {
                bench.iter(|| {
                    let mut a = black_box(&banded).clone();
                    a.factorize().expect("MINCO system factorizes");
                    let mut x = rhs.clone();
                    a.solve_vec3(&mut x).expect("factorized");
                    black_box(x);
                });
            },
        );
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(std::time::Duration::from_millis(500))
        .measurement_time(std::time::Duration::from_secs(2));
    targets = bench_minco, bench_library_lu
}
criterion_main!(benches);

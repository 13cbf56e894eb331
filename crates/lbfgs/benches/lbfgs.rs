//! Solve time of the chained Rosenbrock function from the standard start, with default
//! parameters and a reused (preallocated) solver.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use trust_lbfgs::test_functions::{rosenbrock, rosenbrock_start};
use trust_lbfgs::{Lbfgs, LbfgsParams};

fn rosenbrock_solve(c: &mut Criterion) {
    let mut group = c.benchmark_group("rosenbrock_solve");
    for dimension in [2, 100] {
        let mut solver = Lbfgs::new(dimension, LbfgsParams::default()).expect("valid params");
        let start = rosenbrock_start(dimension);
        let mut x = start.clone();
        group.bench_function(format!("n={dimension}"), |b| {
            b.iter(|| {
                x.copy_from_slice(&start);
                let report = solver
                    .minimize(black_box(&mut x), rosenbrock, &mut ())
                    .expect("valid start");
                black_box(report)
            })
        });
    }
    group.finish();
}

/// One cost-and-gradient evaluation, to express solve times in evaluations.
fn rosenbrock_evaluation(c: &mut Criterion) {
    let x = rosenbrock_start(100);
    let mut g = vec![0.0; 100];
    c.bench_function("rosenbrock_evaluation/n=100", |b| {
        b.iter(|| rosenbrock(black_box(&x), &mut g))
    });
}

criterion_group!(benches, rosenbrock_solve, rosenbrock_evaluation);
criterion_main!(benches);

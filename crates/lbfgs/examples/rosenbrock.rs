//! Minimizes the chained Rosenbrock function in 2 and 100 dimensions and prints what happened.
//!
//! Run with `cargo run -p trust-lbfgs --release --example rosenbrock`.

use trust_lbfgs::test_functions::{rosenbrock, rosenbrock_start};
use trust_lbfgs::{Lbfgs, LbfgsError, LbfgsParams, Progress, monitor_fn};

fn main() -> Result<(), LbfgsError> {
    for dimension in [2, 100] {
        let mut solver = Lbfgs::new(dimension, LbfgsParams::default())?;
        let mut x = rosenbrock_start(dimension);

        // Print every 50th iteration; never cancel.
        let mut monitor = monitor_fn(|p: &Progress<'_>| {
            if p.iteration.is_multiple_of(50) {
                println!(
                    "  iteration {:3}: cost {:.3e}, ‖g‖∞ {:.3e}, step {:.3e}",
                    p.iteration, p.cost, p.grad_inf_norm, p.step
                );
            }
            true
        });
        println!("Rosenbrock, n = {dimension}");
        let report = solver.minimize(&mut x, rosenbrock, &mut monitor)?;

        let worst = x.iter().fold(0.0f64, |m, xi| m.max((xi - 1.0).abs()));
        println!(
            "  stopped: {:?} after {} iteration_count, {} evaluations; cost {:.3e}, ‖g‖∞ {:.3e}, \
             max |x − 1| {:.3e}",
            report.termination,
            report.iteration_count,
            report.evaluation_count,
            report.cost,
            report.grad_inf_norm,
            worst
        );
    }
    Ok(())
}

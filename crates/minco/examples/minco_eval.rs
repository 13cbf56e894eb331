//! Cross-check tool: reads ONE JSON object on stdin,
//! `{"head": [p, v, a], "tail": [p, v, a], "waypoints": [[x, y, z], …], "durations": [T_1, …]}`,
//! and prints ONE JSON object with the MINCO s = 3 coefficients, the jerk energy and its
//! gradients: `{"coeffs": [[c0, …, c5] per piece], "energy": E, "grad_waypoints": […],
//! "grad_durations": […], "grad_tail": [[pos], [vel], [acc]]}`.
//!
//! ```text
//! echo '{"head": [[0,0,0],[0,0,0],[0,0,0]], "tail": [[1,0,0],[0,0,0],[0,0,0]],
//!        "waypoints": [], "durations": [1]}' | cargo run -p trust-minco --example minco_eval
//! ```
//!
//! Errors (bad JSON, wrong lengths, invalid numbers) go to stderr with exit status 1.

use std::io::{Read, Write};
use std::process::ExitCode;

fn main() -> ExitCode {
    let mut input = String::new();
    if let Err(e) = std::io::stdin().read_to_string(&mut input) {
        eprintln!("minco_eval: cannot read stdin: {e}");
        return ExitCode::FAILURE;
    }
    match trust_minco::eval_json(&input) {
        Ok(output) => {
            // A closed pipe (`| head`) is not worth a panic backtrace.
            let mut stdout = std::io::stdout().lock();
            match writeln!(stdout, "{output}").and_then(|()| stdout.flush()) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("minco_eval: cannot write stdout: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Err(e) => {
            eprintln!("minco_eval: {e}");
            ExitCode::FAILURE
        }
    }
}

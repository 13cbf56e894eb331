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
//! Errors (bad JSON, wrong lengths, invalid numbers, more than `trust_minco::minco::MAX_PIECES`
//! pieces, input above 256 MiB) go to stderr with exit status 1; `--help` prints the usage.

use std::io::{Read, Write};
use std::process::ExitCode;

/// Largest accepted input (bytes): far above the JSON of `MAX_PIECES` pieces.
const MAX_INPUT_BYTES: u64 = 256 << 20;

fn usage() -> String {
    format!(
        "usage: minco_eval < problem.json\n\n\
         Reads one JSON object {{\"head\": [p, v, a], \"tail\": [p, v, a], \"waypoints\": [...], \
         \"durations\": [...]}} on stdin and prints the MINCO s = 3 coefficients, the jerk energy \
         and its gradients as one JSON object.\n\
         Limits: at most {} pieces (trust_minco::minco::MAX_PIECES), at most {} MiB of input; \
         numbers must be finite and durations > 0. Exit status 0 on success, 1 on any error \
         (message on stderr); outputs never contain NaN.",
        trust_minco::minco::MAX_PIECES,
        MAX_INPUT_BYTES >> 20
    )
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "--help" || a == "-h") {
        println!("{}", usage());
        return ExitCode::SUCCESS;
    }
    if let Some(a) = args.first() {
        eprintln!("minco_eval: unexpected argument `{a}`\n\n{}", usage());
        return ExitCode::FAILURE;
    }
    let mut input = String::new();
    let mut stdin = std::io::stdin().lock().take(MAX_INPUT_BYTES + 1);
    if let Err(e) = stdin.read_to_string(&mut input) {
        eprintln!("minco_eval: cannot read stdin: {e}");
        return ExitCode::FAILURE;
    }
    if input.len() as u64 > MAX_INPUT_BYTES {
        eprintln!(
            "minco_eval: input exceeds {} MiB; expected at most {} pieces",
            MAX_INPUT_BYTES >> 20,
            trust_minco::minco::MAX_PIECES
        );
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

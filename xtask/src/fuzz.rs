//! `cargo xtask fuzz`: builds the `trust-fuzz` driver in release mode and runs it; its exit code
//! (non-zero on any panic, hang, non-finite output, wrong answer or slow call) becomes ours.

use std::path::Path;

use anyhow::{Context, Result, bail};

/// Runs `trust-fuzz --cases N --seed S [--only API]` in release (`cargo run --release -p
/// trust-fuzz`, or the workspace build: [`crate::release`]).
pub fn run(root: &Path, cases: u64, seed: u64, only: Option<&str>) -> Result<()> {
    if cases == 0 {
        bail!("--cases must be at least 1");
    }
    let mut cmd = crate::release::command(
        root,
        crate::release::Program::Bin {
            package: "trust-fuzz",
            name: "trust-fuzz",
        },
    )?;
    cmd.args(["--cases", &cases.to_string(), "--seed", &seed.to_string()]);
    if let Some(only) = only {
        cmd.args(["--only", only]);
    }
    let status = cmd
        .status()
        .context("failed to start cargo for trust-fuzz")?;
    if !status.success() {
        bail!("trust-fuzz reported failures ({status}); see the table above");
    }
    Ok(())
}

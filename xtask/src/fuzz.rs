//! `cargo xtask fuzz`: builds the `trust-fuzz` driver in release mode and runs it; its exit code
//! (non-zero on any panic, hang, non-finite output, wrong answer or slow call) becomes ours.

use std::path::Path;
use std::process::Command;

use anyhow::{Context, Result, bail};

/// Runs `cargo run --release -p trust-fuzz -- --cases N --seed S [--only API]`.
pub fn run(root: &Path, cases: u64, seed: u64, only: Option<&str>) -> Result<()> {
    if cases == 0 {
        bail!("--cases must be at least 1");
    }
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.current_dir(root).args([
        "run",
        "--quiet",
        "--release",
        "-p",
        "trust-fuzz",
        "--",
        "--cases",
        &cases.to_string(),
        "--seed",
        &seed.to_string(),
    ]);
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

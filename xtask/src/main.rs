//! # xtask — automation for the TRUST-Planner workspace
//!
//! `cargo xtask <command>` (alias in `.cargo/config.toml`). Heavy work shells out to
//! `cargo run --release` so that it never runs in a debug build.
//!
//! Commands:
//! - `ci`: runs `.ci/run`, exactly what CI runs.

use std::process::Command;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "cargo xtask",
    about = "Automation for the TRUST-Planner workspace"
)]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run `.ci/run` (format, clippy, tests, rustdoc, benchmark smoke runs).
    Ci,
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    let root = workspace_root()?;
    match cli.command {
        Cmd::Ci => run(Command::new("bash")
            .arg(root.join(".ci/run"))
            .current_dir(&root)),
    }
}

fn workspace_root() -> Result<std::path::PathBuf> {
    let manifest_dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    manifest_dir
        .parent()
        .map(|p| p.to_path_buf())
        .context("xtask must live one level below the workspace root")
}

fn run(cmd: &mut Command) -> Result<()> {
    let status = cmd
        .status()
        .with_context(|| format!("failed to start {cmd:?}"))?;
    if !status.success() {
        bail!("{cmd:?} failed with {status}");
    }
    Ok(())
}

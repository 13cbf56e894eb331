//! How xtask starts the workspace's release programs (`trust-sim`, `trust-fuzz`, the
//! experiments' examples).
//!
//! By default each command is `cargo run --release -p PACKAGE [--example NAME]`: the smallest
//! build for the one program a user asked for. With [`WORKSPACE_BUILD_ENV`] set (`.ci/run` sets
//! it) every program comes from one `cargo build --release --workspace --bins --examples` and is
//! started from the target directory. Cargo resolves a dependency's features for the packages
//! a command selects, so every distinct `-p` selection rebuilds most of the dependency graph
//! with its own features (a cold CI run built `trust-core` seven times in release); the one
//! workspace selection builds it once, and `cargo bench --workspace` shares it (benchmarks and
//! examples both unify the dev-dependencies' features).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use anyhow::{Result, bail};

/// The environment variable that switches to the one workspace build.
pub const WORKSPACE_BUILD_ENV: &str = "TRUST_XTASK_WORKSPACE_BUILD";

/// A release program of the workspace.
#[derive(Debug, Clone, Copy)]
pub enum Program<'a> {
    /// The binary `name` of `package`.
    Bin { package: &'a str, name: &'a str },
    /// The example `name` of `package`.
    Example { package: &'a str, name: &'a str },
}

/// A command that runs `program` (its arguments still to add), built as the module docs say.
///
/// # Errors
/// The workspace build failed (workspace mode only).
pub fn command(root: &Path, program: Program<'_>) -> Result<Command> {
    if std::env::var_os(WORKSPACE_BUILD_ENV).is_some_and(|v| !v.is_empty()) {
        build_workspace_once(root)?;
        let release = target_dir(root).join("release");
        let exe =
            |dir: PathBuf, name: &str| dir.join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
        let path = match program {
            Program::Bin { name, .. } => exe(release, name),
            Program::Example { name, .. } => exe(release.join("examples"), name),
        };
        let mut cmd = Command::new(path);
        cmd.current_dir(root);
        return Ok(cmd);
    }
    let mut cmd = Command::new(cargo());
    cmd.current_dir(root)
        .args(["run", "--quiet", "--release", "-p"]);
    match program {
        Program::Bin { package, name } => cmd.args([package, "--bin", name]),
        Program::Example { package, name } => cmd.args([package, "--example", name]),
    };
    cmd.arg("--");
    Ok(cmd)
}

fn cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".into())
}

/// The target directory cargo uses for `root`: `CARGO_TARGET_DIR` (relative to `root`) or
/// `root/target`.
fn target_dir(root: &Path) -> PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(dir) if !dir.is_empty() => root.join(dir),
        _ => root.join("target"),
    }
}

/// Runs the workspace build at most once per xtask process.
fn build_workspace_once(root: &Path) -> Result<()> {
    static BUILT: OnceLock<Result<(), String>> = OnceLock::new();
    let built = BUILT.get_or_init(|| {
        let status = Command::new(cargo())
            .current_dir(root)
            .args([
                "build",
                "--quiet",
                "--release",
                "--workspace",
                "--bins",
                "--examples",
            ])
            .status()
            .map_err(|e| format!("failed to start cargo: {e}"))?;
        if status.success() {
            Ok(())
        } else {
            Err(format!(
                "cargo build --release --workspace failed with {status}"
            ))
        }
    });
    if let Err(e) = built {
        bail!("building the workspace's release programs: {e} ({WORKSPACE_BUILD_ENV} is set)");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_is_cargo_run_of_one_package() {
        // The environment variable is not set under `cargo test` unless a caller exported it.
        if std::env::var_os(WORKSPACE_BUILD_ENV).is_some() {
            return;
        }
        let cmd = command(
            Path::new("/w"),
            Program::Example {
                package: "trust-minco",
                name: "minco_eval",
            },
        )
        .unwrap();
        let args: Vec<_> = cmd
            .get_args()
            .map(|a| a.to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            args,
            [
                "run",
                "--quiet",
                "--release",
                "-p",
                "trust-minco",
                "--example",
                "minco_eval",
                "--"
            ]
        );
    }
}

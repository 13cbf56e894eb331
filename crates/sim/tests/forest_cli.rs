//! `trust-sim forest`: its argument errors name the option and the value, and a one-trial,
//! one-second smoke writes every output.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn sim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_trust-sim"))
        .current_dir(root())
        .arg("forest")
        .args(args)
        .output()
        .expect("trust-sim runs")
}

#[test]
fn forest_rejects_bad_arguments_with_their_names() {
    for (args, wanted) in [
        (&["--static", "sensed"][..], "--static: `sensed`"),
        (&["--tier", "extreme"], "--tier: `extreme`"),
        (&["--trials", "0"], "--trials: 0"),
        (&["--planner", "trust,trust"], "each planner at most once"),
        (&["--planner", "nope"], "unknown planner `nope`"),
        (&["--time-limit=-1"], "--time-limit"),
        (&["--real-time", "0"], "--real-time"),
        (
            &["--scenario", "scenarios/quickstart.toml", "--trials", "1"],
            "kind = \"dynamic-forest\"",
        ),
    ] {
        let out = sim(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(wanted), "{args:?}: {err}");
    }
}

#[test]
fn forest_smoke_writes_every_output() {
    let out_dir = std::env::temp_dir().join(format!("trust-sim-forest-{}", std::process::id()));
    let dir = out_dir.to_string_lossy().to_string();
    let out = sim(&[
        "--tier",
        "easy",
        "--trials",
        "1",
        "--seed",
        "2",
        "--jobs",
        "1",
        "--time-limit",
        "1",
        "--out",
        &dir,
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("## easy (50 obstacles)"), "{stdout}");
    assert!(
        stdout.contains("SANDO (dynamic), arXiv 2604.07599 | — |"),
        "{stdout}"
    );
    for f in [
        "forest.json",
        "runs.csv",
        "runs.json",
        "summary.json",
        "report.md",
    ] {
        assert!(out_dir.join(f).is_file(), "{f}");
    }
    let csv = std::fs::read_to_string(out_dir.join("runs.csv")).unwrap();
    let row = csv.lines().nth(1).unwrap();
    assert!(row.starts_with("easy,50,0,2,trust,timed_out,"), "{row}");
    assert!(out_dir.join("logs/easy/trust/trial-0000.jsonl").is_file());
    let _ = std::fs::remove_dir_all(&out_dir);
}

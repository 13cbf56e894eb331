//! The file groups end to end, through the binary: the supervisor counts a worker's panic, abort
//! (an allocation beyond the memory limit) and hang, names the case and goes on; every group runs
//! clean on a few cases; a case replays alone with its files kept.

use std::path::PathBuf;
use std::process::Command;

fn fuzz(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_trust-fuzz"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("trust-fuzz runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.code().unwrap_or(-1), text)
}

/// The numbers of the table row of `group`.
fn row(text: &str, group: &str) -> Vec<u64> {
    let line = text
        .lines()
        .find(|l| l.starts_with(group))
        .unwrap_or_else(|| panic!("no row {group} in:\n{text}"));
    line.split_whitespace()
        .skip(1)
        .filter_map(|x| x.parse::<f64>().ok())
        .map(|x| x as u64)
        .collect()
}

#[test]
fn the_supervisor_survives_panics_aborts_and_hangs() {
    let (code, text) = fuzz(&[
        "--only",
        "files::selftest",
        "--cases",
        "12",
        "--hang-ms",
        "300",
        "--mem-mb",
        "1024",
    ]);
    assert_eq!(code, 1, "{text}");
    // cases, accepted, heavy, panics, aborts, hangs, …
    let r = row(&text, "files::selftest");
    assert_eq!(r[0], 12, "{text}");
    assert!(r[3] >= 1 && r[4] >= 1 && r[5] >= 1, "{text}");
    assert_eq!(r[1] + r[3] + r[4] + r[5], 12, "{text}");
    assert!(
        text.contains("abort: the worker died: SIGABRT")
            && text.contains("memory allocation of 1099511627776 bytes failed"),
        "{text}"
    );
    assert!(text.contains("hang: no answer within 300 ms"), "{text}");
}

#[test]
fn every_file_group_runs_clean_on_a_few_cases() {
    let (code, text) = fuzz(&["--only", "files", "--cases", "50", "--seed", "3"]);
    assert_eq!(code, 0, "{text}");
    for group in [
        "files::scenario",
        "files::track",
        "files::points",
        "files::log",
        "files::tamper",
    ] {
        assert!(row(&text, group)[0] > 0, "{group}:\n{text}");
    }
}

#[test]
fn a_file_case_replays_alone_with_its_files() {
    let keep = std::env::temp_dir().join(format!("trust-fuzz-test-{}", std::process::id()));
    let (code, text) = fuzz(&[
        "--only",
        "files::track",
        "--replay",
        "12345",
        "--keep",
        &keep.display().to_string(),
    ]);
    assert_eq!(code, 0, "{text}");
    assert!(
        text.contains("files::track: ") && text.contains("what it did"),
        "{text}"
    );
    let case: PathBuf = keep.join("work/case");
    assert!(case.join("scenario.toml").is_file(), "{text}");
    assert!(case.join("data/walker_1.csv").is_file(), "{text}");
    std::fs::remove_dir_all(&keep).ok();
}

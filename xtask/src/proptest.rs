//! `cargo xtask proptest [--seeds K] [--cases N]`: every property test of the workspace under K
//! random seeds, so that a counterexample is not hidden behind the one seed CI pins.
//!
//! 1. Finds the property tests: the `#[test] fn` items inside every `proptest! { … }` block of
//!    the workspace's Rust sources (outside `target/`).
//! 2. Builds the test binaries once (`cargo test --workspace --no-run`, the test profile CI uses,
//!    or `--release`) and lists each binary's tests (`--list`), keeping those whose last path segment
//!    is a property test.
//! 3. For each seed, runs each binary on exactly those tests with `PROPTEST_RNG_SEED` = the seed,
//!    `PROPTEST_CASES` = N and failure persistence off (a failure found under one seed must not be
//!    replayed under the next, nor written into the source tree), from the package's directory as
//!    `cargo test` does.
//! 4. Prints one progress line per seed, then every failure with its shrunk input and the command
//!    that reproduces it; exits non-zero if any test failed under any seed.
//!
//! Blocks that set `cases` in their own `proptest_config` keep that count (it was chosen for their
//! run time); `PROPTEST_CASES` sets the others.

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use serde_json::Value;

/// What to run.
#[derive(Debug, Clone)]
pub struct Options {
    /// Number of random seeds (ignored when `seed` is set).
    pub seeds: u32,
    /// `PROPTEST_CASES` of every run.
    pub cases: u32,
    /// Base of the seed sequence; `None` draws one from the clock (printed, so the run can be
    /// repeated with `--base`).
    pub base: Option<u64>,
    /// Run exactly this seed once (CI's commit-derived seed).
    pub seed: Option<u64>,
    /// Build and run the tests with `--release` instead of the test profile.
    pub release: bool,
}

/// One test binary with the property tests it contains.
#[derive(Debug, Clone)]
struct Binary {
    executable: PathBuf,
    /// Directory of the package's manifest (`cargo test` runs tests from there).
    package_dir: PathBuf,
    package: String,
    /// `--lib`, `--test NAME` or `--bin NAME`: the `cargo test` selector of this binary.
    selector: String,
    tests: Vec<String>,
}

/// One failing test under one seed.
#[derive(Debug, Clone, PartialEq)]
struct Failure {
    seed: u64,
    test: String,
    /// proptest's "minimal failing input" line, or the first line of the panic message.
    detail: String,
    reproduce: String,
}

/// Runs the command.
pub fn run(root: &Path, opts: &Options) -> Result<()> {
    if opts.cases == 0 {
        bail!("--cases must be at least 1");
    }
    let seeds: Vec<u64> = match opts.seed {
        Some(s) => vec![s],
        None => {
            if opts.seeds == 0 {
                bail!("--seeds must be at least 1");
            }
            let base = opts.base.unwrap_or_else(clock_base);
            eprintln!(
                "seeds derived from base {base} (repeat this run with --base {base} --seeds {})",
                opts.seeds
            );
            derive_seeds(base, opts.seeds)
        }
    };
    let names = property_test_names(root)?;
    if names.is_empty() {
        bail!("no proptest! blocks found under {}", root.display());
    }
    let binaries = test_binaries(root, opts.release, &names)?;
    let total: usize = binaries.iter().map(|b| b.tests.len()).sum();
    let found: BTreeSet<&str> = binaries
        .iter()
        .flat_map(|b| b.tests.iter().map(|t| last_segment(t)))
        .collect();
    let missing: Vec<&String> = names
        .iter()
        .filter(|n| !found.contains(n.as_str()))
        .collect();
    eprintln!(
        "{total} property tests in {} binaries ({} proptest! fns in the sources{}); \
         {} seed(s) x PROPTEST_CASES={}",
        binaries.len(),
        names.len(),
        if missing.is_empty() {
            String::new()
        } else {
            format!(", not in any test binary: {missing:?}")
        },
        seeds.len(),
        opts.cases
    );
    let log_dir = root.join("target/proptest");
    std::fs::create_dir_all(&log_dir)
        .with_context(|| format!("cannot create {}", log_dir.display()))?;
    let started = Instant::now();
    let mut failures = Vec::new();
    for (i, &seed) in seeds.iter().enumerate() {
        let t0 = Instant::now();
        let mut failed_here = Vec::new();
        let mut log = String::new();
        for bin in &binaries {
            let output = Command::new(&bin.executable)
                .current_dir(&bin.package_dir)
                .env("PROPTEST_RNG_SEED", seed.to_string())
                .env("PROPTEST_CASES", opts.cases.to_string())
                .env("PROPTEST_DISABLE_FAILURE_PERSISTENCE", "1")
                .arg("--exact")
                .args(&bin.tests)
                .output()
                .with_context(|| format!("failed to start {}", bin.executable.display()))?;
            let stdout = String::from_utf8_lossy(&output.stdout);
            let stderr = String::from_utf8_lossy(&output.stderr);
            let mut failed = failed_tests(&stdout);
            if !output.status.success() && failed.is_empty() {
                // Crashed (abort, signal) before libtest could report: blame the whole binary.
                failed.push(format!("{} ({})", bin.selector, output.status));
            }
            if !failed.is_empty() {
                writeln!(
                    log,
                    "### {} {}\n{stdout}\n{stderr}",
                    bin.package, bin.selector
                )?;
            }
            for test in failed {
                failed_here.push(Failure {
                    seed,
                    detail: failure_detail(&stdout, &test),
                    reproduce: reproduce_command(seed, opts, bin, &test),
                    test,
                });
            }
        }
        let secs = t0.elapsed().as_secs_f64();
        if failed_here.is_empty() {
            eprintln!(
                "[{}/{}] seed {seed}: {total} passed ({secs:.1} s)",
                i + 1,
                seeds.len()
            );
        } else {
            let path = log_dir.join(format!("seed-{seed}.log"));
            std::fs::write(&path, &log)
                .with_context(|| format!("cannot write {}", path.display()))?;
            eprintln!(
                "[{}/{}] seed {seed}: {} of {total} FAILED ({secs:.1} s; output in {}): {}",
                i + 1,
                seeds.len(),
                failed_here.len(),
                path.display(),
                failed_here
                    .iter()
                    .map(|f| f.test.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        failures.extend(failed_here);
    }
    let minutes = started.elapsed().as_secs_f64() / 60.0;
    if failures.is_empty() {
        eprintln!(
            "all {total} property tests passed under {} seed(s) at PROPTEST_CASES={} ({minutes:.1} min)",
            seeds.len(),
            opts.cases
        );
        return Ok(());
    }
    eprintln!("\nfailures ({minutes:.1} min):");
    for f in &failures {
        eprintln!(
            "- seed {}: {}\n    {}\n    reproduce: {}",
            f.seed, f.test, f.detail, f.reproduce
        );
    }
    let bad_seeds: BTreeSet<u64> = failures.iter().map(|f| f.seed).collect();
    bail!(
        "{} failure(s) under {} of {} seed(s)",
        failures.len(),
        bad_seeds.len(),
        seeds.len()
    )
}

/// SplitMix64: a bijective mixer, so consecutive bases give unrelated, distinct seeds.
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The `count` seeds of a run with base `base`: `splitmix64(base + k)`, distinct for a given base.
fn derive_seeds(base: u64, count: u32) -> Vec<u64> {
    (0..u64::from(count))
        .map(|k| splitmix64(base.wrapping_add(k)))
        .collect()
}

/// A base seed from the clock (nanoseconds since the epoch).
fn clock_base() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
}

/// The names of the tests inside every `proptest! { … }` block of the workspace's `.rs` files
/// (skipping `target/`, hidden directories and `xtask/`, whose sources only quote the macro).
fn property_test_names(root: &Path) -> Result<BTreeSet<String>> {
    let mut names = BTreeSet::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in
            std::fs::read_dir(&dir).with_context(|| format!("cannot list {}", dir.display()))?
        {
            let path = entry?.path();
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if path.is_dir() {
                if !matches!(name, "target" | "xtask") && !name.starts_with('.') {
                    stack.push(path);
                }
            } else if name.ends_with(".rs") {
                let text = std::fs::read_to_string(&path)
                    .with_context(|| format!("cannot read {}", path.display()))?;
                names.extend(proptest_fns(&text));
            }
        }
    }
    Ok(names)
}

/// The names of the `#[test] fn` items inside the `proptest! { … }` blocks of one source text.
/// Comments and string literals are not parsed (a brace inside one shifts a block's end); a block
/// without its closing brace is ignored.
fn proptest_fns(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(at) = rest.find("proptest!") {
        let after = &rest[at + "proptest!".len()..];
        let Some(open) = after.find(|c: char| !c.is_whitespace()) else {
            break;
        };
        if !after[open..].starts_with('{') {
            rest = after;
            continue;
        }
        let body = &after[open + 1..];
        let mut depth = 1usize;
        let mut end = None;
        for (i, c) in body.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        end = Some(i);
                        break;
                    }
                }
                _ => {}
            }
        }
        let Some(end) = end else {
            break;
        };
        // Every test of a block carries `#[test]`; the next `fn` after it names the test.
        for piece in body[..end].split("#[test]").skip(1) {
            let mut words = piece
                .split(|c: char| !(c.is_alphanumeric() || c == '_'))
                .filter(|w| !w.is_empty())
                .skip_while(|w| *w != "fn")
                .skip(1);
            if let Some(name) = words.next() {
                out.push(name.to_string());
            }
        }
        rest = &body[end..];
    }
    out
}

/// Builds the workspace's test binaries and lists the property tests of each.
fn test_binaries(root: &Path, release: bool, names: &BTreeSet<String>) -> Result<Vec<Binary>> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.current_dir(root).args([
        "test",
        "--workspace",
        "--no-run",
        "--message-format=json-render-diagnostics",
    ]);
    if release {
        cmd.arg("--release");
    }
    eprintln!("building the test binaries ({cmd:?})");
    let output = cmd
        .stderr(std::process::Stdio::inherit())
        .output()
        .context("failed to start cargo test --no-run")?;
    if !output.status.success() {
        bail!("cargo test --no-run failed with {}", output.status);
    }
    let mut binaries = Vec::new();
    for line in String::from_utf8_lossy(&output.stdout).lines() {
        let Some(mut bin) = parse_artifact(line) else {
            continue;
        };
        let listing = Command::new(&bin.executable)
            .current_dir(&bin.package_dir)
            .arg("--list")
            .output()
            .with_context(|| format!("failed to list {}", bin.executable.display()))?;
        if !listing.status.success() {
            bail!(
                "{} --list failed with {}",
                bin.executable.display(),
                listing.status
            );
        }
        bin.tests = listed_tests(&String::from_utf8_lossy(&listing.stdout))
            .into_iter()
            .filter(|t| names.contains(last_segment(t)))
            .collect();
        if !bin.tests.is_empty() {
            binaries.push(bin);
        }
    }
    Ok(binaries)
}

/// A test binary from one line of `cargo test --no-run --message-format=json` (`None` for other
/// messages and non-test artifacts). `tests` is left empty.
fn parse_artifact(line: &str) -> Option<Binary> {
    let v: Value = serde_json::from_str(line).ok()?;
    if v["reason"] != "compiler-artifact" || v["profile"]["test"] != true {
        return None;
    }
    let executable = PathBuf::from(v["executable"].as_str()?);
    let manifest = PathBuf::from(v["manifest_path"].as_str()?);
    let target = &v["target"];
    let name = target["name"].as_str()?;
    let kinds: Vec<&str> = target["kind"]
        .as_array()?
        .iter()
        .filter_map(Value::as_str)
        .collect();
    let selector = if kinds.contains(&"test") {
        format!("--test {name}")
    } else if kinds.contains(&"bin") {
        format!("--bin {name}")
    } else {
        "--lib".to_string()
    };
    let package = package_name(v["package_id"].as_str()?, &manifest)?;
    Some(Binary {
        executable,
        package_dir: manifest.parent()?.to_path_buf(),
        package,
        selector,
        tests: Vec::new(),
    })
}

/// The package name of a cargo package id: `path+file:///…/dir#name@1.0` names it, `…/name#1.0`
/// leaves it to the directory.
fn package_name(id: &str, manifest: &Path) -> Option<String> {
    let (path, fragment) = id.rsplit_once('#')?;
    if let Some((name, _version)) = fragment.split_once('@') {
        return Some(name.to_string());
    }
    let dir = path.rsplit('/').next().filter(|d| !d.is_empty());
    dir.map(str::to_string)
        .or_else(|| manifest.parent()?.file_name()?.to_str().map(str::to_string))
}

/// The test names of a libtest `--list` output (`path: test` lines).
fn listed_tests(listing: &str) -> Vec<String> {
    listing
        .lines()
        .filter_map(|l| l.strip_suffix(": test"))
        .map(str::to_string)
        .collect()
}

fn last_segment(path: &str) -> &str {
    path.rsplit("::").next().unwrap_or(path)
}

/// The failed tests of a libtest run (`test PATH ... FAILED` lines).
fn failed_tests(stdout: &str) -> Vec<String> {
    stdout
        .lines()
        .filter_map(|l| l.strip_prefix("test ")?.strip_suffix(" ... FAILED"))
        .map(str::to_string)
        .collect()
}

/// proptest's shrunk input for `test` from libtest's `---- TEST stdout ----` section (the
/// "minimal failing input" line), else the section's first panic line.
fn failure_detail(stdout: &str, test: &str) -> String {
    let header = format!("---- {test} stdout ----");
    let Some(start) = stdout.find(&header) else {
        return "(no output captured)".into();
    };
    let section = &stdout[start + header.len()..];
    let section = section.find("\n---- ").map_or(section, |e| &section[..e]);
    if let Some(i) = section.find("minimal failing input") {
        // The input may be pretty-printed over several lines, up to proptest's `\tsuccesses:`.
        let input = &section[i..];
        let input = input.find("\n\t").map_or(input, |e| &input[..e]);
        return input.split_whitespace().collect::<Vec<_>>().join(" ");
    }
    let line = section
        .lines()
        .find(|l| l.contains("panicked at"))
        .or_else(|| section.lines().find(|l| !l.trim().is_empty()))
        .unwrap_or("");
    line.trim().to_string()
}

/// The command that reruns one failing test under its seed.
fn reproduce_command(seed: u64, opts: &Options, bin: &Binary, test: &str) -> String {
    format!(
        "PROPTEST_RNG_SEED={seed} PROPTEST_CASES={} cargo test{} -p {} {} -- --exact {test}",
        opts.cases,
        if opts.release { " --release" } else { "" },
        bin.package,
        bin.selector
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeds_are_deterministic_and_distinct() {
        let a = derive_seeds(7, 50);
        assert_eq!(a, derive_seeds(7, 50));
        assert_eq!(a.len(), 50);
        assert_eq!(a.iter().collect::<BTreeSet<_>>().len(), 50);
        assert_eq!(derive_seeds(7, 3)[..], a[..3]);
        assert_ne!(derive_seeds(8, 1)[0], a[0]);
        // Bases that differ by one share all but one seed, shifted: the mixer makes each seed look
        // unrelated to its index, not the sequences unrelated.
        assert_eq!(derive_seeds(8, 2)[0], a[1]);
        assert!(derive_seeds(u64::MAX, 2).iter().all(|&s| s != 0));
    }

    #[test]
    fn proptest_fns_are_found_in_blocks_only() {
        let src = r#"
            fn helper() {}
            proptest! {
                #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]
                #[test]
                fn first(x in 0..3u8) { if x > 1 { prop_assert!(true); } }

                #[test]
                fn second_one(v in prop::collection::vec(0.0..1.0f64, 1..4)) {}
            }
            fn after() {}
            proptest::proptest! {
                #[test] fn third(_x in 0..1u8) {}
            }
            // proptest! without a block is skipped
            macro_rules! m { () => { proptest!(x) } }
        "#;
        assert_eq!(proptest_fns(src), vec!["first", "second_one", "third"]);
        assert!(proptest_fns("proptest! {").is_empty());
        assert!(proptest_fns("no tests here").is_empty());
    }

    #[test]
    fn listing_and_failures_are_parsed() {
        let listing = "uvd::tests::a: test\nuvd::tests::b: test\nsome_bench: benchmark\n\n2 tests, 1 benchmark\n";
        assert_eq!(
            listed_tests(listing),
            vec!["uvd::tests::a", "uvd::tests::b"]
        );
        assert_eq!(last_segment("uvd::tests::a"), "a");
        assert_eq!(last_segment("top_level"), "top_level");
        let out = "\nrunning 2 tests\ntest m::ok_one ... ok\ntest m::bad ... FAILED\n\nfailures:\n\n\
                   ---- m::bad stdout ----\nproptest: Saving this and future failures in x\n\
                   thread 'm::bad' panicked at src/m.rs:10:5:\nTest failed: assertion failed: \
                   `(left == right)`; minimal failing input: x = 3, y = [0.5]\n\tsuccesses: 7\n\n\
                   ---- m::multi stdout ----\nTest failed: x; minimal failing input: p = [\n    1.5,\n]\n\
                   \tsuccesses: 2\n\n\
                   ---- m::other stdout ----\nthread 'm::other' panicked at src/m.rs:20:5:\nboom\n\n\
                   failures:\n    m::bad\n\ntest result: FAILED. 1 passed; 1 failed\n";
        assert_eq!(failed_tests(out), vec!["m::bad"]);
        assert_eq!(
            failure_detail(out, "m::bad"),
            "minimal failing input: x = 3, y = [0.5]"
        );
        assert_eq!(
            failure_detail(out, "m::multi"),
            "minimal failing input: p = [ 1.5, ]"
        );
        assert_eq!(
            failure_detail(out, "m::other"),
            "thread 'm::other' panicked at src/m.rs:20:5:"
        );
        assert_eq!(failure_detail(out, "m::none"), "(no output captured)");
    }

    #[test]
    fn artifacts_give_binaries_and_reproduce_commands() {
        let line = r#"{"reason":"compiler-artifact","package_id":"path+file:///w/crates/topo-prm#trust-topo-prm@0.1.0","manifest_path":"/w/crates/topo-prm/Cargo.toml","target":{"kind":["lib"],"name":"trust_topo_prm"},"profile":{"test":true},"executable":"/w/target/debug/deps/trust_topo_prm-1"}"#;
        let bin = parse_artifact(line).unwrap();
        assert_eq!(bin.package, "trust-topo-prm");
        assert_eq!(bin.selector, "--lib");
        assert_eq!(bin.package_dir, PathBuf::from("/w/crates/topo-prm"));
        let opts = Options {
            seeds: 1,
            cases: 512,
            base: None,
            seed: None,
            release: false,
        };
        assert_eq!(
            reproduce_command(42, &opts, &bin, "uvd::tests::a"),
            "PROPTEST_RNG_SEED=42 PROPTEST_CASES=512 cargo test -p trust-topo-prm --lib -- \
             --exact uvd::tests::a"
        );
        let line = r#"{"reason":"compiler-artifact","package_id":"path+file:///w/xtask#0.1.0","manifest_path":"/w/xtask/Cargo.toml","target":{"kind":["test"],"name":"api"},"profile":{"test":true},"executable":"/w/target/debug/deps/api-2"}"#;
        let bin = parse_artifact(line).unwrap();
        assert_eq!(
            (bin.package.as_str(), bin.selector.as_str()),
            ("xtask", "--test api")
        );
        // Not a test binary: a library built for a test's dependencies, a build script message.
        let lib = r#"{"reason":"compiler-artifact","package_id":"p#a@1","manifest_path":"/a/Cargo.toml","target":{"kind":["lib"],"name":"a"},"profile":{"test":false},"executable":null}"#;
        assert!(parse_artifact(lib).is_none());
        assert!(parse_artifact(r#"{"reason":"build-finished","success":true}"#).is_none());
        assert!(parse_artifact("not json").is_none());
    }
}

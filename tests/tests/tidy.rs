//! Tidy rules, enforced as ordinary tests (rust-analyzer style): the dependency direction of
//! ARCHITECTURE.md, crate-level docs, and workspace lint inheritance.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[path = "tidy/modules.rs"]
mod modules;

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests crate lives one level below the workspace root")
        .to_path_buf()
}

/// One workspace member: its manifest and where it lives.
struct Member {
    dir: PathBuf,
    manifest: toml::Table,
}

impl Member {
    fn name(&self) -> &str {
        self.manifest["package"]["name"]
            .as_str()
            .expect("package.name")
    }

    /// Names of our own crates (`trust-*`) this member depends on, in any dependency table.
    fn internal_deps(&self, table: &str) -> Vec<String> {
        self.manifest
            .get(table)
            .and_then(|t| t.as_table())
            .map(|t| {
                t.keys()
                    .filter(|k| k.starts_with("trust-"))
                    .cloned()
                    .collect()
            })
            .unwrap_or_default()
    }
}

fn members() -> Vec<Member> {
    let root = workspace_root();
    let text = std::fs::read_to_string(root.join("Cargo.toml")).expect("root Cargo.toml");
    let root_manifest: toml::Table = text.parse().expect("root Cargo.toml parses");
    root_manifest["workspace"]["members"]
        .as_array()
        .expect("workspace.members")
        .iter()
        .map(|m| {
            let dir = root.join(m.as_str().expect("member path"));
            let text = std::fs::read_to_string(dir.join("Cargo.toml")).expect("member manifest");
            Member {
                dir,
                manifest: text.parse().expect("member manifest parses"),
            }
        })
        .collect()
}

/// The allowed internal dependencies of each crate (design.md §2, ARCHITECTURE.md "Dependency
/// order"): the planning libraries
/// `geometry ← predict ← core ← {lbfgs, minco, topo-prm} ← manager ← planner`, then the simulator
/// along its data path `{plot, vehicle, runlog} ; world (+ runlog) ← flight (+ plot, planner) ←
/// experiments ← sim (the binary)`. `world` depends on no planner crate ([`PLANNER_CRATES`]: the
/// scenario's `[planner]` section is a type parameter it never looks inside); `overrides` (the
/// derive) sits under `core`, `scenes` (the paper's experiment scenes) on `core` under `minco`,
/// `topo-prm` and `world`. `lbfgs` depends on nothing of ours; `minco` and `topo-prm` never depend on each other;
/// `plot` knows no simulator or planner type (the flight summary uses its `quantile_sorted`);
/// `runlog` knows none of the simulator's types either (a log is read without building a world;
/// the scenario's static shapes are its `StaticShape`); `vehicle` knows nothing of the planner;
/// `route` (the global route, issue 19) sits beside `minco`/`topo-prm` on `geometry` (and may use
/// `core`); `replay` (issue 20) reads run logs and draws with `plot`, and only the binary uses it;
/// `export` (MCAP, issue 20) reads logs only (`runlog`), and only `sim` uses it;
/// `flightstack` (PX4/Crazyflie outputs, issue 35) reads the planner's trajectory type (`core`)
/// and knows no simulator type, its tests build MINCO trajectories (`minco`); `sensing`
/// (simulated sensors and the online map, issue 34) sits on `geometry` alone; `ros2` (the ROS 2
/// node, issue 35) sits under `sim`: the planner and map of a scenario file (`world`,
/// `planner`) and the PX4 setpoints of `flightstack`; its simulated ROS world (`dds_world`,
/// issue 35 item 3) writes run logs with `flight`'s header and clearances, and `sim` runs it
/// (`trust-sim dds-world`). `numdiff` (the finite differences every gradient test uses, issue
/// 33) depends on nothing and any crate may use it ([`ANYWHERE`]).
fn allowed() -> BTreeMap<&'static str, &'static [&'static str]> {
    const PLANNING: &[&str] = &[
        "trust-overrides",
        "trust-geometry",
        "trust-predict",
        "trust-core",
        "trust-scenes",
        "trust-lbfgs",
        "trust-minco",
        "trust-topo-prm",
        "trust-route",
        "trust-manager",
        "trust-planner",
    ];
    fn with(extra: &[&'static str]) -> &'static [&'static str] {
        let mut v: Vec<&'static str> = PLANNING.to_vec();
        v.extend_from_slice(extra);
        Vec::leak(v)
    }
    BTreeMap::from([
        ("trust-numdiff", &[][..]),
        ("trust-overrides", &[][..]),
        ("trust-geometry", &[][..]),
        ("trust-predict", &["trust-geometry"][..]),
        ("trust-sensing", &["trust-geometry"][..]),
        (
            "trust-core",
            &["trust-geometry", "trust-predict", "trust-overrides"][..],
        ),
        ("trust-scenes", &["trust-geometry", "trust-core"][..]),
        ("trust-lbfgs", &[][..]),
        ("trust-route", &["trust-geometry", "trust-core"][..]),
        (
            "trust-minco",
            &[
                "trust-geometry",
                "trust-predict",
                "trust-core",
                "trust-scenes",
                "trust-lbfgs",
            ][..],
        ),
        (
            "trust-topo-prm",
            &[
                "trust-geometry",
                "trust-predict",
                "trust-core",
                "trust-scenes",
            ][..],
        ),
        (
            "trust-manager",
            &[
                "trust-geometry",
                "trust-predict",
                "trust-core",
                "trust-lbfgs",
                "trust-minco",
                "trust-topo-prm",
                "trust-route",
            ][..],
        ),
        (
            "trust-planner",
            &[
                "trust-geometry",
                "trust-predict",
                "trust-core",
                "trust-lbfgs",
                "trust-minco",
                "trust-topo-prm",
                "trust-route",
                "trust-manager",
            ][..],
        ),
        // The fuzz driver is a tool at the top, like the simulator: it drives the library APIs
        // and the file-facing surfaces (scenarios, tracks, run logs, replay, export).
        (
            "trust-fuzz",
            with(&[
                "trust-vehicle",
                "trust-world",
                "trust-runlog",
                "trust-export",
                "trust-flight",
                "trust-plot",
                "trust-replay",
            ]),
        ),
        ("trust-plot", &[][..]),
        ("trust-runlog", &[][..]),
        ("trust-export", &["trust-runlog"][..]),
        ("trust-vehicle", &["trust-core"][..]),
        (
            "trust-world",
            &[
                "trust-geometry",
                "trust-predict",
                "trust-core",
                "trust-scenes",
                "trust-vehicle",
                "trust-runlog",
                "trust-sensing",
            ][..],
        ),
        (
            "trust-flight",
            with(&[
                "trust-vehicle",
                "trust-world",
                "trust-runlog",
                "trust-plot",
                "trust-sensing",
            ]),
        ),
        (
            "trust-experiments",
            with(&[
                "trust-vehicle",
                "trust-world",
                "trust-runlog",
                "trust-flight",
                "trust-plot",
            ]),
        ),
        ("trust-replay", &["trust-runlog", "trust-plot"][..]),
        ("trust-flightstack", &["trust-core", "trust-minco"][..]),
        (
            "trust-ros2",
            with(&[
                "trust-vehicle",
                "trust-world",
                "trust-runlog",
                "trust-flight",
                "trust-flightstack",
                // The node's online map from point clouds (`trust_ros2::sensing`).
                "trust-sensing",
            ]),
        ),
        (
            "trust-sim",
            with(&[
                "trust-vehicle",
                "trust-world",
                "trust-runlog",
                "trust-export",
                "trust-flight",
                "trust-plot",
                "trust-experiments",
                "trust-replay",
                "trust-ros2",
            ]),
        ),
    ])
}

/// Crates below every layer that any crate may depend on: they depend on nothing of ours.
const ANYWHERE: &[&str] = &["trust-numdiff"];

/// The crates that plan (frontends, backends, the manager, the route, the assembled planner):
/// `trust-world` may depend on none of them, in any dependency table.
const PLANNER_CRATES: &[&str] = &[
    "trust-lbfgs",
    "trust-minco",
    "trust-topo-prm",
    "trust-route",
    "trust-manager",
    "trust-planner",
];

#[test]
fn the_world_depends_on_no_planner_crate() {
    let allowed = allowed();
    let world = allowed["trust-world"];
    let listed: Vec<&&str> = PLANNER_CRATES
        .iter()
        .filter(|c| world.contains(c))
        .collect();
    assert!(
        listed.is_empty(),
        "the layering lets trust-world use {listed:?}"
    );
    let m = members()
        .into_iter()
        .find(|m| m.name() == "trust-world")
        .expect("trust-world is a member");
    for table in ["dependencies", "build-dependencies", "dev-dependencies"] {
        for dep in m.internal_deps(table) {
            assert!(
                !PLANNER_CRATES.contains(&dep.as_str()),
                "trust-world [{table}] depends on {dep}: the scenario's [planner] section is read \
                 where the planner is known (trust_flight::scenario), not in the world"
            );
        }
    }
}

/// Every workspace member is either in [`allowed`] or one of the automation crates, so that a new
/// crate cannot escape the layering rules by not being listed.
#[test]
fn every_crate_has_a_layer() {
    let allowed = allowed();
    let unlisted: Vec<String> = members()
        .iter()
        .map(|m| m.name().to_string())
        .filter(|n| !allowed.contains_key(n.as_str()) && n != "xtask" && n != "trust-tests")
        .collect();
    assert!(
        unlisted.is_empty(),
        "crates without a place in the dependency order of tidy.rs: {unlisted:?}"
    );
}

#[test]
fn library_crates_respect_the_dependency_direction() {
    let allowed = allowed();
    let mut violations = Vec::new();
    for m in members() {
        let Some(ok) = allowed.get(m.name()) else {
            continue; // xtask and the tests crate may use anything (`every_crate_has_a_layer`).
        };
        // Normal and build dependencies define the architecture; dev-dependencies may not break it
        // either (a test of minco must not pull in topo-prm), except that crates may test against
        // crates further down the chain.
        for table in ["dependencies", "build-dependencies", "dev-dependencies"] {
            for dep in m.internal_deps(table) {
                if !ok.contains(&dep.as_str()) && !ANYWHERE.contains(&dep.as_str()) {
                    violations.push(format!("{} [{table}] depends on {dep}", m.name()));
                }
            }
        }
    }
    assert!(
        violations.is_empty(),
        "dependency rules of ARCHITECTURE.md broken:\n{}",
        violations.join("\n")
    );
}

#[test]
fn every_crate_inherits_workspace_lints() {
    let offenders: Vec<String> = members()
        .iter()
        .filter(|m| {
            m.manifest
                .get("lints")
                .and_then(|l| l.get("workspace"))
                .and_then(|w| w.as_bool())
                != Some(true)
        })
        .map(|m| m.name().to_string())
        .collect();
    assert!(
        offenders.is_empty(),
        "crates without `[lints] workspace = true`: {offenders:?}"
    );
}

#[test]
fn library_crates_have_crate_docs_and_warn_on_missing_docs() {
    let mut offenders = Vec::new();
    for m in members() {
        let lib = m.dir.join("src/lib.rs");
        let Ok(text) = std::fs::read_to_string(&lib) else {
            continue; // binary-only crate
        };
        let doc_lines = text
            .lines()
            .take_while(|l| l.starts_with("//!") || l.trim().is_empty())
            .filter(|l| l.starts_with("//!"))
            .count();
        if doc_lines < 3 {
            offenders.push(format!(
                "{}: crate docs must say what it is, when to use it and which paper section it implements ({doc_lines} lines of `//!`)",
                m.name()
            ));
        }
        if !text.contains("#![warn(missing_docs)]") && !text.contains("#![deny(missing_docs)]") {
            offenders.push(format!("{}: lacks #![warn(missing_docs)]", m.name()));
        }
    }
    assert!(offenders.is_empty(), "{}", offenders.join("\n"));
}

#[test]
fn dependency_versions_come_from_the_workspace() {
    let mut offenders = Vec::new();
    for m in members() {
        for table in ["dependencies", "dev-dependencies", "build-dependencies"] {
            let Some(deps) = m.manifest.get(table).and_then(|t| t.as_table()) else {
                continue;
            };
            for (name, spec) in deps {
                let inherited = spec
                    .get("workspace")
                    .and_then(|w| w.as_bool())
                    .unwrap_or(false);
                if !inherited {
                    offenders.push(format!("{} [{table}] {name}", m.name()));
                }
            }
        }
    }
    assert!(
        offenders.is_empty(),
        "dependencies must use `name.workspace = true` (versions live in the root Cargo.toml): {offenders:?}"
    );
}

#[test]
fn no_todo_or_unimplemented_in_sources() {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                if p.file_name().is_some_and(|n| n == "target") {
                    continue;
                }
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    let mut files = Vec::new();
    for m in members() {
        walk(&m.dir, &mut files);
    }
    let this_file = Path::new(file!()).file_name().unwrap();
    let needles = [concat!("todo", "!("), concat!("unimplemented", "!(")];
    let offenders: Vec<String> = files
        .iter()
        .filter(|f| f.file_name() != Some(this_file))
        .filter_map(|f| {
            let text = std::fs::read_to_string(f).ok()?;
            needles
                .iter()
                .any(|n| text.contains(n))
                .then(|| f.display().to_string())
        })
        .collect();
    assert!(offenders.is_empty(), "placeholders left in: {offenders:?}");
}

/// No crate's modules import each other in a circle, at any depth: not the top-level modules
/// (issue 17: the simulator's error ↔ scenario ↔ planner ↔ world cycles), nor the children of any
/// module (issue 33: `world::scenario::generator ↔ sections`). The graph is drawn from every
/// path the sources name ([`modules`]: `use` trees, `crate::`/`super::` paths in code and macro
/// calls, re-exports followed); a failure names the crate root and the cycle.
#[test]
fn no_module_cycles_at_any_depth() {
    let root = workspace_root();
    let mut offenders = Vec::new();
    let mut crates = 0;
    for m in members() {
        for file in modules::crate_roots(&m.dir) {
            crates += 1;
            let krate = modules::Crate::parse(&file);
            let at = file
                .strip_prefix(&root)
                .unwrap_or(&file)
                .display()
                .to_string();
            for cycle in modules::module_cycles(&krate) {
                offenders.push(format!("{} ({at}): {cycle}", m.name()));
            }
        }
    }
    assert!(crates > 20, "only {crates} crate roots found");
    assert!(
        offenders.is_empty(),
        "module cycles (move the shared items to a module both may use):\n{}",
        offenders.join("\n")
    );
}

/// Prints the module graph under one module, with the reference behind each edge, to help
/// break a cycle: `TIDY_GRAPH=crates/world/src/lib.rs:scenario cargo test -p trust-tests --test
/// tidy -- --ignored print_module_graph --nocapture` (`crate` for the top level).
#[test]
#[ignore = "a tool: set TIDY_GRAPH=<crate root>:<module>"]
fn print_module_graph() {
    let spec =
        std::env::var("TIDY_GRAPH").unwrap_or_else(|_| "crates/world/src/lib.rs:crate".into());
    let (file, parent) = spec
        .split_once(':')
        .expect("TIDY_GRAPH=<crate root>:<module>");
    let krate = modules::Crate::parse(&workspace_root().join(file));
    let levels = krate.sibling_graphs();
    let level = levels
        .get(parent)
        .unwrap_or_else(|| panic!("{parent}: not a module with children"));
    for (from, tos) in &level.graph {
        println!("{from}");
        for to in tos {
            println!("  -> {to}: {}", level.why[&(from.clone(), to.clone())]);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Docs stay short and true (issue 33): README as a front page, ARCHITECTURE as a map, crate roots
// that say what a crate is, no commit hashes where a reader looks first. History belongs in
// CHANGELOG.md, reasons in docs/decisions/, numbers in docs/results.md (`cargo xtask results`).

const README_MAX_LINES: usize = 150;
const README_MAX_WORDS: usize = 1_200;
const README_MAX_TABLE_ROWS: usize = 12;
const TABLE_CELL_MAX_CHARS: usize = 120;
const ARCHITECTURE_MAX_LINES: usize = 350;
const CRATE_ROOT_MAX_DOC_LINES: usize = 60;
const DECISION_RECORD_MAX_LINES: usize = 60;

fn read_root_file(name: &str) -> String {
    std::fs::read_to_string(workspace_root().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The cells of a Markdown table row (`| a | b |`), split at `|` outside code spans and not
/// escaped as `\|`; `None` for a line that is not a table row.
fn table_cells(line: &str) -> Option<Vec<String>> {
    let row = line.trim();
    if !row.starts_with('|') {
        return None;
    }
    let mut cells = Vec::new();
    let (mut cell, mut in_code, mut escaped) = (String::new(), false, false);
    for c in row[1..].chars() {
        match c {
            '|' if !in_code && !escaped => cells.push(std::mem::take(&mut cell)),
            _ => {
                if c == '`' {
                    in_code = !in_code;
                }
                cell.push(c);
            }
        }
        escaped = c == '\\';
    }
    if !cell.trim().is_empty() {
        cells.push(cell);
    }
    Some(cells.into_iter().map(|c| c.trim().to_string()).collect())
}

/// Whether a table row is the header separator (`|---|:--:|`).
fn is_separator(cells: &[String]) -> bool {
    cells
        .iter()
        .all(|c| !c.is_empty() && c.chars().all(|ch| matches!(ch, '-' | ':' | ' ')))
}

/// What breaks the README's front-page rules.
fn readme_problems(text: &str) -> Vec<String> {
    let mut problems = Vec::new();
    let lines = text.lines().count();
    if lines > README_MAX_LINES {
        problems.push(format!(
            "README.md has {lines} lines (at most {README_MAX_LINES})"
        ));
    }
    let words = text.split_whitespace().count();
    if words > README_MAX_WORDS {
        problems.push(format!(
            "README.md has {words} words (at most {README_MAX_WORDS})"
        ));
    }
    let mut rows = 0;
    for (i, line) in text.lines().enumerate() {
        let Some(cells) = table_cells(line) else {
            continue;
        };
        if is_separator(&cells) {
            continue;
        }
        rows += 1;
        for cell in cells
            .iter()
            .filter(|c| c.chars().count() > TABLE_CELL_MAX_CHARS)
        {
            problems.push(format!(
                "README.md:{}: a table cell of {} characters (at most {TABLE_CELL_MAX_CHARS}): {cell:?}",
                i + 1,
                cell.chars().count()
            ));
        }
    }
    if rows > README_MAX_TABLE_ROWS {
        problems.push(format!(
            "README.md has {rows} table rows, headers included (at most {README_MAX_TABLE_ROWS}): \
             the full tables belong in docs/results.md"
        ));
    }
    problems
}

/// The words of `text` that look like commit hashes: 7–40 hex digits with at least one digit and
/// one letter a–f (so `1234567`, `deadbeef`, `f64` and `e4` are not), with line numbers.
fn commit_hashes(text: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    for (i, line) in text.lines().enumerate() {
        for word in line.split(|c: char| !c.is_ascii_alphanumeric()) {
            let hex = word.chars().all(|c| c.is_ascii_hexdigit());
            let digit = word.chars().any(|c| c.is_ascii_digit());
            let letter = word.chars().any(|c| c.is_ascii_alphabetic());
            if hex && digit && letter && (7..=40).contains(&word.len()) {
                found.push((i + 1, word.to_string()));
            }
        }
    }
    found
}

/// What breaks the rules of a crate root: more than [`CRATE_ROOT_MAX_DOC_LINES`] lines of `//!`,
/// or a changelog heading among them.
fn crate_root_problems(name: &str, text: &str) -> Vec<String> {
    let doc: Vec<&str> = text
        .lines()
        .filter(|l| l.trim_start().starts_with("//!"))
        .collect();
    let mut problems = Vec::new();
    if doc.len() > CRATE_ROOT_MAX_DOC_LINES {
        problems.push(format!(
            "{name}: {} lines of crate docs (at most {CRATE_ROOT_MAX_DOC_LINES}): what it is, when \
             to use it, the paper section and an example; move history to CHANGELOG.md and \
             reasons to docs/decisions/",
            doc.len()
        ));
    }
    for line in &doc {
        let body = line.trim_start().trim_start_matches("//!").trim();
        if body.starts_with('#') && body.to_lowercase().contains("changelog") {
            problems.push(format!(
                "{name}: a changelog in the crate docs ({body:?}): it belongs in CHANGELOG.md"
            ));
        }
    }
    problems
}

#[test]
fn the_docs_checks_find_what_they_look_for() {
    // Table rows and cells.
    assert_eq!(
        table_cells("| a | `x|y` | b\\|c |"),
        Some(vec!["a".into(), "`x|y`".into(), "b\\|c".into()])
    );
    assert_eq!(table_cells("not | a row"), None);
    assert!(is_separator(&table_cells("|---|:--:|").unwrap()));
    let wide = format!("| what | ours |\n|---|---|\n| E4 | {} |\n", "x".repeat(121));
    assert_eq!(
        readme_problems(&wide).len(),
        1,
        "{:?}",
        readme_problems(&wide)
    );
    let many: String = std::iter::once("| h |\n|---|\n".to_string())
        .chain((0..12).map(|i| format!("| {i} |\n")))
        .collect();
    assert!(readme_problems(&many)[0].contains("13 table rows"));
    let long = "word\n".repeat(151);
    assert!(readme_problems(&long)[0].contains("151 lines"));
    let wordy = "word ".repeat(1_201);
    assert!(readme_problems(&wordy)[0].contains("1201 words"));
    assert!(readme_problems("# Title\n\n| a | b |\n|---|---|\n| 1 | 2 |\n").is_empty());
    // Commit hashes.
    let hashes = commit_hashes("commit 737472e, fa354d2f; 1234567 deadbeef f64 e4 0x1f 2c88551\n");
    let words: Vec<&str> = hashes.iter().map(|(_, w)| w.as_str()).collect();
    assert_eq!(words, ["737472e", "fa354d2f", "2c88551"]);
    assert!(
        commit_hashes("1e6 m, 2.5e-3, u64::MAX, 961ed1843997ed5c6dd2d5dbd2b5e925f958c1544")
            .is_empty()
    );
    // Crate roots.
    let root = format!("{}#![warn(missing_docs)]\n", "//! text\n".repeat(61));
    assert!(crate_root_problems("x", &root)[0].contains("61 lines"));
    assert!(
        crate_root_problems("x", "//! # x\n//!\n//! # Changelog\n//! - y\n")[0]
            .contains("changelog")
    );
    assert!(crate_root_problems("x", "//! # x\n//! See the changelog.\n").is_empty());
}

#[test]
fn readme_is_a_front_page() {
    let problems = readme_problems(&read_root_file("README.md"));
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn architecture_is_a_map_not_a_log() {
    let lines = read_root_file("ARCHITECTURE.md").lines().count();
    assert!(
        lines <= ARCHITECTURE_MAX_LINES,
        "ARCHITECTURE.md has {lines} lines (at most {ARCHITECTURE_MAX_LINES}): experiment logs \
         belong in docs/decisions/ and CHANGELOG.md"
    );
}

#[test]
fn no_commit_hashes_in_readme_or_architecture() {
    let mut offenders = Vec::new();
    for name in ["README.md", "ARCHITECTURE.md"] {
        for (line, word) in commit_hashes(&read_root_file(name)) {
            offenders.push(format!("{name}:{line}: {word}"));
        }
    }
    assert!(
        offenders.is_empty(),
        "commit hashes (results go to docs/results.md, stamped by `cargo xtask results`):\n{}",
        offenders.join("\n")
    );
}

#[test]
fn crate_roots_are_short_and_keep_no_changelog() {
    let mut problems = Vec::new();
    for m in members() {
        for root in ["src/lib.rs", "src/main.rs"] {
            if let Ok(text) = std::fs::read_to_string(m.dir.join(root)) {
                problems.extend(crate_root_problems(&format!("{} {root}", m.name()), &text));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn decision_records_are_short_and_indexed_in_architecture() {
    let architecture = read_root_file("ARCHITECTURE.md");
    let dir = workspace_root().join("docs/decisions");
    let mut records: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("docs/decisions")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    records.sort();
    assert!(!records.is_empty(), "no decision records in docs/decisions");
    let mut problems = Vec::new();
    for path in &records {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let lines = std::fs::read_to_string(path).unwrap().lines().count();
        if lines > DECISION_RECORD_MAX_LINES {
            problems.push(format!(
                "docs/decisions/{name}: {lines} lines (at most {DECISION_RECORD_MAX_LINES})"
            ));
        }
        if !architecture.contains(&format!("docs/decisions/{name}")) {
            problems.push(format!(
                "docs/decisions/{name} is not in ARCHITECTURE.md's index of decision records"
            ));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

//! Regression tests of the file fuzzer (`cargo xtask fuzz`, groups `files::…`; issue 32 item 6):
//! each test is named after a defect the fuzzer found in the scenario checks — a number printed
//! with 16 digits, a placeholder count printed as 19 digits, a parse error quoting a 3 500-
//! character line or a float as 309 digits, a real-time scenario that validated and then failed
//! to set up, and tracks whose totals were unbounded.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use trust_flight::scenario::Scenario;

const ROOM: &str = "name = \"fuzz\"\n[world]\nbounds = { min = [0, 0, 0], max = [40, 15, 8] }\n\
                    [mission]\nstart = [1, 7, 4]\ngoal = [39, 7, 4]\n";

/// A fresh folder for one test's files.
fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("trust-file-fuzz-{}-{name}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `trust-sim validate`'s message for `text` written as `dir/scenario.toml` (it must fail).
fn refusal(dir: &Path, text: &str) -> String {
    let path = dir.join("scenario.toml");
    std::fs::write(&path, text).unwrap();
    match trust_flight::scenario::load_checked(&path) {
        Ok(_) => panic!("validated:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// The longest run of digits in `message` (a readable number has at most 6 significant digits;
/// file names and line numbers stay well below 10).
fn longest_digits(message: &str) -> usize {
    message
        .split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0)
}

#[test]
fn an_obstacle_speed_outside_its_maneuvers_prints_a_readable_speed() {
    // The speed was printed with `{}`: "(speed 9999999.000000041)".
    let dir = folder("speed");
    let text = format!(
        "{ROOM}[[obstacles]]\nshape = \"sphere\"\nradius_m = 0.5\nposition = [20, 7, 4]\n\
         velocity = [-0.9, 1e7, 0]\nmotion = {{ kind = \"random-maneuvers\", speed_m_s = [0.5, 2] }}\n"
    );
    let m = refusal(&dir, &text);
    assert!(m.contains("(speed 1e7)"), "{m}");
    assert!(longest_digits(&m) <= 10, "{m}");
}

#[test]
fn a_voxel_size_of_1e_minus_300_prints_readable_grid_counts() {
    // The grid's counts were esdf_dims' placeholder for a huge count: 4611686018427387903.
    let dir = folder("voxels");
    for cloud in [
        "[static.point_cloud]\nsource = \"shapes\"\nesdf_voxel_m = 1e-300\n",
        "[static.point_cloud]\nsource = \"shapes\"\nesdf_voxel_m = 0.5\nspacing_m = 1e-300\n",
    ] {
        let text = format!(
            "{ROOM}[[static.shapes]]\nkind = \"sphere\"\ncenter = [20, 3, 4]\nradius = 1\n{cloud}"
        );
        let m = refusal(&dir, &text);
        assert!(m.contains("4e301 x 1.5e301 x 8e300"), "{m}");
        assert!(longest_digits(&m) <= 10, "{m}");
    }
}

#[test]
fn a_parse_error_on_a_long_line_quotes_a_window_of_it() {
    // toml quotes the offending line whole: a scenario written by a serializer has 3 500-
    // character lines (arrays of inline tables).
    let dir = folder("long_line");
    let shapes: Vec<String> = (0..60)
        .map(|i| {
            format!(
                "{{ kind = \"sphere\", center = [{}, 3, 4], radius = 0.2 }}",
                1 + i % 38
            )
        })
        .collect();
    let mut line = format!("shapes = [{}", shapes.join(", "));
    line.push_str(", 42]");
    let text = format!("{ROOM}[static]\n{line}\n");
    let m = refusal(&dir, &text);
    assert!(line.len() > 3000);
    assert!(
        m.lines().all(|l| l.chars().count() < 300),
        "a line of the message is too long:\n{m}"
    );
    assert!(m.contains("42"), "{m}");
}

#[test]
fn a_wrong_float_in_a_parse_error_prints_readably() {
    // serde writes a float of the wrong type in full: 309 digits for 1e308.
    let dir = folder("float");
    let m = refusal(&dir, &format!("{ROOM}[static]\nshapes = [1e308]\n"));
    assert!(m.contains("1e308"), "{m}");
    assert!(longest_digits(&m) <= 10, "{m}");
}

#[test]
fn a_fourier_obstacle_leaving_its_region_prints_a_readable_time() {
    // The time of the first sample outside the region was printed with `{}`
    // ("at t = 879.8828133798829 s").
    let dir = folder("fourier");
    let text = format!(
        "{ROOM}[[obstacles]]\nshape = \"box\"\nhalf_extents = [0.3, 0.3, 0.3]\n\
         motion = {{ kind = \"fourier\", period_s = 33.333333333333336, center = [5, 5, 1.5], \
         cos = [[4.9, 0, 0]] }}\n"
    );
    let m = refusal(&dir, &text);
    assert!(m.contains("motion at t = "), "{m}");
    assert!(longest_digits(&m) <= 10, "{m}");
}

#[test]
fn real_time_budgets_beyond_the_planner_ranges_are_refused_by_validate() {
    // In real time the loop divides the planner's budgets by the CPU scale; at 1e-5 the
    // frontend's budget became 2e7 ms, beyond its range: `validate` accepted the file, and
    // `run` failed to set up the planner.
    let dir = folder("real_time");
    let m = refusal(
        &dir,
        &format!("{ROOM}[sim]\nlatency = {{ kind = \"measured\", cpu_scale = 1e-5 }}\n"),
    );
    assert!(
        m.contains("sim.latency.cpu_scale: 1e-5") && m.contains("planner.frontend.budget_ms"),
        "{m}"
    );
    // The budgets are the planner's: the world builds, and the planner's checks `run` makes
    // first refuse it with the same problems.
    let s = Scenario::parse_file(&dir.join("scenario.toml")).unwrap();
    assert!(trust_world::World::build(&s).is_ok());
    assert_eq!(
        trust_flight::scenario::problems(&s),
        trust_flight::scenario::check(&s)
    );
    // A scale that keeps the budgets in range is accepted.
    let path = dir.join("ok.toml");
    std::fs::write(
        &path,
        format!("{ROOM}[sim]\nlatency = {{ kind = \"measured\", cpu_scale = 0.5 }}\n"),
    )
    .unwrap();
    trust_flight::scenario::load_checked(&path).unwrap();
}

/// A scenario of `n` obstacles naming `data/track.csv`.
fn crowd(n: usize) -> String {
    let mut text = ROOM.to_string();
    for _ in 0..n {
        text.push_str(
            "[[obstacles]]\nshape = \"sphere\"\nradius_m = 0.2\n\
             motion = { kind = \"samples\", file = \"data/track.csv\" }\n",
        );
    }
    text
}

#[test]
fn obstacles_naming_one_large_track_are_refused_by_the_track_totals() {
    // Each track was capped, not their sum: 10 000 obstacles naming one 16 MiB track read
    // 160 GB and held 10⁹ samples (the fuzzer's 9 999 pedestrians took 12 s).
    let dir = folder("track_totals");
    std::fs::create_dir_all(dir.join("data")).unwrap();
    let mut track = String::from("t,x,y,z\n");
    for i in 0..100_000 {
        track.push_str(&format!(
            "{},{},7,4\n",
            f64::from(i) * 0.01,
            5.0 + f64::from(i) * 1e-4
        ));
    }
    std::fs::write(dir.join("data/track.csv"), &track).unwrap();
    let t = Instant::now();
    let m = refusal(&dir, &crowd(11));
    assert!(t.elapsed() < Duration::from_secs(20), "{:?}", t.elapsed());
    assert!(
        m.contains("obstacles[10].motion.file") && m.contains("1000000 samples in all"),
        "{m}"
    );
    // Bytes count too: a track of 2 samples padded with comments to 15 MiB, named 5 times.
    let mut padded = String::from("0,5,7,4\n100,6,7,4\n");
    while padded.len() < 15 << 20 {
        padded.push_str(&format!("#{}\n", "x".repeat(98)));
    }
    std::fs::write(dir.join("data/track.csv"), &padded).unwrap();
    let m = refusal(&dir, &crowd(5));
    assert!(
        m.contains("obstacles[4].motion.file") && m.contains("64 MiB of track files"),
        "{m}"
    );
    // Within the totals, the same file may be named many times.
    std::fs::write(dir.join("data/track.csv"), "0,5,7,4\n100,6,7,4\n").unwrap();
    let path = dir.join("many.toml");
    std::fs::write(&path, crowd(50)).unwrap();
    let problems = trust_flight::scenario::check(&Scenario::parse_file(&path).unwrap());
    assert!(
        !problems
            .iter()
            .any(|p| p.expected.contains("in all obstacles' tracks")),
        "{problems:?}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn values_of_other_sections_print_readably() {
    // A probability printed with `{}` (9223372036854776000), and a parameter value the planning
    // crates write with `{:?}` (-1.7976931348623157e308).
    let dir = folder("values");
    let m = refusal(
        &dir,
        &format!(
            "{ROOM}[sensing]\ndropout_probability = 9223372036854775807\n\
             [planner]\nfrontend = {{ kind = \"dev-prm\", budget_ms = -1.7976931348623157e308 }}\n"
        ),
    );
    assert!(
        m.contains("sensing.dropout_probability: 9.22337e18")
            && m.contains("planner.frontend.budget_ms: -1.79769e308"),
        "{m}"
    );
    assert!(longest_digits(&m) <= 10, "{m}");
}

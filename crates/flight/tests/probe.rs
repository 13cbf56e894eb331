//! Regression tests of the scenario probe (issue 32): hand-made files that validated and then
//! failed to fly, panicked before validation, ran without bounds, read without bounds, or printed
//! unreadable numbers. Each case is a file in `tests/data/probe/` (with `# expect:` lines where a
//! message is pinned) and a test named after it; `validate_and_build_agree` checks that
//! `trust-sim validate` ([`trust_world::check`]) and the world build plus the flight's set-up
//! reject exactly the same files with the same problems.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use trust_flight::scenario::Scenario;
use trust_planner as planner;
use trust_world::World;
use trust_world::error::WorldError;

fn probe(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/probe")
        .join(name)
}

fn dir_files(dir: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    files
}

/// `trust-sim validate`'s message for a probe file (it must fail), and how long it took.
fn validate(name: &str) -> (String, Duration) {
    let t = Instant::now();
    let e = trust_flight::scenario::load_checked(&probe(name))
        .err()
        .unwrap_or_else(|| panic!("{name} validated"));
    (e.to_string(), t.elapsed())
}

/// The problems `validate` reports on `field` (exact field name).
fn problems_on(name: &str, field: &str) -> Vec<String> {
    match trust_flight::scenario::load_checked(&probe(name)) {
        Err(WorldError::Invalid { problems, .. }) => problems
            .iter()
            .filter(|p| p.field == field)
            .map(|p| p.to_string())
            .collect(),
        other => panic!("{name}: expected problems, got {other:?}"),
    }
}

fn assert_one_on(name: &str, field: &str, fragment: &str) {
    let found = problems_on(name, field);
    assert!(
        found.iter().any(|p| p.contains(fragment)),
        "{name}: no problem on {field} containing {fragment:?}: {found:?}\n{}",
        validate(name).0
    );
}

/// Every number in a message has at most 7 characters of digits in a row (readable).
fn assert_readable(message: &str) {
    let longest = message
        .split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0);
    assert!(longest <= 10, "a {longest}-digit number in: {message}");
}

#[test]
fn bounds_max_1e7_is_refused_on_world_bounds() {
    assert_one_on("bounds_max_1e7.toml", "world.bounds.max", "[1e7, 20, 10]");
}

#[test]
fn box_max_z_1e7_is_refused_on_the_shape() {
    assert_one_on("box_max_z_1e7.toml", "static.shapes[0].max", "1e7");
}

#[test]
fn obstacle_velocity_1e7_is_refused_on_the_velocity() {
    assert_one_on(
        "obstacle_velocity_1e7.toml",
        "obstacles[0].velocity",
        "1000 m/s",
    );
}

#[test]
fn v_max_1e7_is_blamed_on_v_max_not_the_goal_radius() {
    assert_one_on("v_max_1e7.toml", "vehicle.limits.v_max", "[0.01, 100] m/s");
    assert!(!validate("v_max_1e7.toml").0.contains("goal_radius"));
}

#[test]
fn a_max_1e308_is_blamed_on_a_max_not_the_clearance() {
    assert_one_on("a_max_1e308.toml", "vehicle.limits.a_max", "1e308");
    assert!(!validate("a_max_1e308.toml").0.contains("clearance"));
}

#[test]
fn position_noise_1e7_is_blamed_on_the_noise_not_the_measurement() {
    assert_one_on(
        "position_noise_1e7.toml",
        "sensing.position_noise_m",
        "diagonal",
    );
    assert!(
        !validate("position_noise_1e7.toml")
            .0
            .contains("measurement")
    );
}

#[test]
fn fourier_period_1e_minus_6_is_below_the_physics_step() {
    assert_one_on(
        "fourier_period_1e-6.toml",
        "obstacles[0].motion.period_s",
        "sim.physics_dt_s = 0.002 s",
    );
}

#[test]
fn random_mission_in_1e308_bounds_does_not_panic() {
    // Parsing drew the endpoints with `unwrap` on a non-finite range.
    let s = Scenario::parse_file(&probe("random_mission_in_huge_bounds.toml")).unwrap();
    assert!(World::build(&s).is_err());
    assert_one_on(
        "random_mission_in_huge_bounds.toml",
        "world.bounds.min",
        "1e308",
    );
}

#[test]
fn a_billion_random_obstacles_are_refused_before_allocating() {
    let (message, took) = validate("random_obstacles_count_1e9.toml");
    assert!(took < Duration::from_secs(2), "{took:?}");
    assert_one_on(
        "random_obstacles_count_1e9.toml",
        "random_obstacles[0].count",
        "at most 10000 moving obstacles",
    );
    assert_readable(&message);
    assert_one_on(
        "random_obstacles_count_max.toml",
        "random_obstacles[0].count",
        "9.22337e18",
    );
}

#[test]
fn cloud_spacing_of_2_mm_is_refused_before_sampling() {
    let (message, took) = validate("cloud_spacing_2mm.toml");
    assert!(took < Duration::from_secs(2), "{took:?}");
    assert!(
        message.contains("static.point_cloud.spacing_m: 0.002"),
        "{message}"
    );
}

#[test]
fn many_static_spheres_with_an_unmeetable_random_mission_stay_fast() {
    // 20 000 spheres: above the shape cap, refused at once.
    let mut text = String::from(
        "name = \"crowd\"\n[world]\nbounds = { min = [0, 0, 0], max = [200, 200, 10] }\n\
         [mission]\nrandom = { min_distance_m = 1000 }\n",
    );
    let sphere = |i: usize| {
        format!(
            "[[static.shapes]]\nkind = \"sphere\"\ncenter = [{}, {}, 5]\nradius = 0.2\n",
            1 + i % 198,
            1 + i / 198 % 198
        )
    };
    let mut crowd = text.clone();
    for i in 0..20_000 {
        crowd.push_str(&sphere(i));
    }
    let t = Instant::now();
    let s = Scenario::from_toml_str(&crowd, Path::new("crowd.toml")).unwrap();
    let problems = trust_flight::scenario::check(&s);
    assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
    assert!(
        problems
            .iter()
            .any(|p| p.field == "static.shapes" && p.expected.contains("at most 10000")),
        "{problems:?}"
    );
    // 5 000 spheres: within the cap; the draw gives up after its budget of draws × shapes.
    for i in 0..5_000 {
        text.push_str(&sphere(i));
    }
    let t = Instant::now();
    let s = Scenario::from_toml_str(&text, Path::new("crowd.toml")).unwrap();
    let problems = trust_flight::scenario::check(&s);
    assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
    let p = problems
        .iter()
        .find(|p| p.field == "mission.random.min_distance_m")
        .unwrap_or_else(|| panic!("{problems:?}"));
    assert!(p.expected.contains("800 draws"), "{p}");
}

#[test]
fn devices_are_not_read_as_tracks_or_points() {
    for name in ["track_dev_zero.toml", "points_dev_zero.toml"] {
        let (message, took) = validate(name);
        assert!(took < Duration::from_secs(2), "{took:?}");
        assert!(message.contains("not a regular file"), "{message}");
    }
}

#[test]
fn a_relative_track_path_may_not_leave_the_scenarios_folder() {
    let (message, _) = validate("track_outside_folder.toml");
    assert!(
        message.contains("obstacles[0].motion.file") && message.contains("may not leave it"),
        "{message}"
    );
    // Nothing of the file outside is read or echoed.
    assert!(!message.contains("2.0,2.0,1.0"), "{message}");
}

#[test]
fn a_track_with_only_a_header_says_so() {
    let (message, _) = validate("header_only_track.toml");
    assert!(message.contains("only a header"), "{message}");
    assert!(!message.contains("not loaded"), "{message}");
}

#[test]
fn huge_numbers_print_in_scientific_notation() {
    let (message, _) = validate("readable_numbers.toml");
    assert_readable(&message);
    for fragment in [
        "mission.goal: [1e308, 10, 5]",
        "vehicle.radius_m: 1e308",
        "obstacles[0].half_extents: [1e308, 0.4, 0.4]",
        "obstacles[0].motion.period_s: 1e308",
    ] {
        assert!(message.contains(fragment), "{fragment} not in:\n{message}");
    }
}

#[test]
fn every_probe_file_is_refused() {
    for path in dir_files("tests/data/probe") {
        assert!(
            trust_flight::scenario::load_checked(&path).is_err(),
            "{} validated",
            path.display()
        );
    }
}

/// One validation: for every bad file (broken and probe), `trust-sim validate`'s checks and what
/// `run` does before flying — the planner's section, `World::build`, then the traffic, the
/// sensor and `planner::build` — agree: both refuse, with the same problems. For every shipped scenario
/// both accept (`tests/scenario.rs` builds them).
#[test]
fn validate_and_build_agree() {
    let mut files = dir_files("tests/data/broken");
    files.extend(dir_files("tests/data/probe"));
    for path in files {
        let Ok(s) = Scenario::parse_file(&path) else {
            // Syntax, unknown names: refused by the parser, before either.
            assert!(trust_flight::scenario::load_checked(&path).is_err());
            continue;
        };
        let checked = trust_flight::scenario::check(&s);
        // `run` checks the planner's section, builds the world (which checks the rest), then
        // sets up the traffic, the sensor and the planner.
        let planner_problems = trust_flight::scenario::problems(&s);
        let run = match World::build(&s) {
            Err(WorldError::Invalid { mut problems, .. }) => {
                problems.extend(planner_problems);
                Err(problems)
            }
            Err(e) => panic!("{}: run fails outside validation: {e}", path.display()),
            Ok(_) if !planner_problems.is_empty() => Err(planner_problems),
            Ok(w) => {
                w.traffic().unwrap();
                w.sensing().unwrap();
                let ctx = trust_flight::scenario::planner_context(&w);
                let resolved = trust_flight::scenario::resolve_planner(&s);
                if let Err(e) = planner::build(&resolved, &ctx) {
                    panic!("{}: run fails outside validation: {e}", path.display());
                }
                Ok(())
            }
        };
        match run {
            Err(problems) => assert_eq!(problems, checked, "{}", path.display()),
            Ok(()) => panic!(
                "{}: run starts but validate says {checked:?}",
                path.display()
            ),
        }
    }
}

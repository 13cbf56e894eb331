//! Flying where the static map is not given (issue 34): a small scene sensed by a coarse depth
//! camera, flown closed loop. The vehicle must arrive without touching the wall it only learns
//! about on the way, and every cycle must log the online map's time.

use std::path::Path;

use trust_flight::map_sensing::MapSensing;
use trust_flight::scenario::Scenario;
use trust_flight::{FlightError, RunOptions, fly};
use trust_runlog::{RunLog, Status};
use trust_world::World;
use trust_world::error::WorldError;

/// A 10 × 6 × 3 m room, a full-height wall across most of it 4 m ahead of the start (the way
/// round is its open end at y > 4), a 48 × 36 depth camera reaching 4 m into 0.15 m voxels, and
/// a slow vehicle of radius 0.1 m.
const SCENE: &str = r#"
name = "unknown_small_wall"
description = "A wall learnt on the way: 10 x 6 x 3 m, depth camera, known-free commitment."
seed = 3
time_limit_s = 30.0

[world]
bounds = { min = [0, 0, 0], max = [10, 6, 3] }

[[static.shapes]]
kind = "box"
min = [4.0, 0.0, 0.0]
max = [4.3, 4.0, 3.0]

[mission]
start = [1.0, 2.0, 1.5]
goal = [8.0, 2.0, 1.5]
goal_tolerance_m = 0.3

[vehicle]
radius_m = 0.1
limits = { v_max = 1.5, a_max = 3.0 }

[planner]
name = "trust"

[sensing]
static = { depth = { width = 48, height = 36, max_depth_m = 4.0, rate_hz = 10.0, map = { resolution_m = 0.15 } } }
"#;

fn scene() -> Scenario {
    Scenario::from_toml_str(SCENE, Path::new("unknown_map.rs")).expect("the scene parses")
}

#[test]
fn a_wall_sensed_on_the_way_is_flown_round_without_contact() {
    let s = scene();
    assert!(s.validate().is_empty(), "{:?}", s.validate());
    let world = World::build(&s).expect("world");
    let dir = std::env::temp_dir().join(format!("trust-flight-unknown-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let log_path = dir.join("run.jsonl");
    let options = RunOptions {
        log_path: Some(log_path.clone()),
        ..RunOptions::default()
    };
    let flight = fly(
        &world,
        &trust_flight::scenario::resolve_planner(&s),
        &options,
        |_| {},
    )
    .expect("flight");
    let outcome = &flight.summary.outcome;
    assert_eq!(outcome.status, Status::Arrived, "{outcome:?}");
    assert!(outcome.min_clearance_static_m > 0.0, "{outcome:?}");
    let log = RunLog::read(&log_path).expect("log reads");
    assert!(log.cycles.iter().all(|c| c.map_ms.is_some()));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_sensing_values_are_problems_naming_the_field_and_typed_errors_in_flight() {
    let mut s = scene();
    s.sensing.static_map = toml::from_str::<Wrap>("static = { depth = { rate_hz = 0.0 } }")
        .expect("parses")
        .s;
    let problems = s.validate();
    assert!(
        problems
            .iter()
            .any(|p| p.field == "sensing.static.depth.rate_hz"),
        "{problems:?}"
    );
    assert!(rejected(&s), "a 0 Hz camera was accepted");
    for bad in [
        "static = { depth = { map = { resolution_m = -0.1 } } }",
        "static = { depth = { map = { dims = [1, 10, 10] } } }",
        "static = { lidar = { channels = 0 } }",
        "static = { depth = { vfov_rad = 4.0 } }",
    ] {
        s.sensing.static_map = toml::from_str::<Wrap>(bad).expect("parses").s;
        assert!(!s.validate().is_empty(), "{bad}");
        assert!(rejected(&s), "{bad}");
    }
    // Known: no online map.
    s.sensing.static_map = Default::default();
    assert!(
        MapSensing::new(&World::build(&s).expect("world"))
            .unwrap()
            .is_none()
    );
}

/// Whether building the world or its online map refuses `s` with a typed error (never a panic).
fn rejected(s: &Scenario) -> bool {
    match World::build(s) {
        Err(WorldError::Invalid { problems, .. }) => problems
            .iter()
            .any(|p| p.field.starts_with("sensing.static")),
        Err(_) => false,
        Ok(world) => matches!(MapSensing::new(&world), Err(FlightError::Sensing(_))),
    }
}

#[derive(serde::Deserialize)]
struct Wrap {
    #[serde(rename = "static")]
    s: trust_world::map_sensing::StaticSensing,
}

/// Decision 0050: after each scan only the voxels wholly inside the vehicle's body count as
/// free without a measurement. A ball as large as the commit check's reach (0.52 m for r =
/// 0.3 m) let a vehicle hovering 0.3 m above a slab its camera never saw creep down onto it.
#[test]
fn a_scan_assumes_free_only_what_the_body_fills() {
    use trust_core::{Aabb, Vec3};
    use trust_flight::map_sensing::OnlineMap;
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(20.0, 20.0, 10.0)).unwrap();
    let params = trust_sensing::LocalMapParams::default();
    let (start, vehicle) = (Vec3::new(10.0, 10.0, 5.0), Vec3::new(4.0, 4.0, 3.0));
    let mut online = OnlineMap::new(params, &start, bounds, 0.3, 0.54).unwrap();
    online
        .insert(&trust_sensing::Scan::default(), &vehicle)
        .unwrap();
    let map = online.map();
    for (d, free) in [
        (Vec3::zeros(), true),
        (Vec3::new(0.1, 0.0, 0.0), true),
        (Vec3::new(0.0, 0.0, -0.3), false),
        (Vec3::new(0.0, 0.0, 0.3), false),
        (Vec3::new(0.3, 0.0, 0.0), false),
        (Vec3::new(0.0, -0.35, 0.0), false),
    ] {
        assert_eq!(
            map.is_known_free(&(vehicle + d)),
            free,
            "{d:?} from the centre"
        );
    }
}

/// Decision 0051: the commit check counts the body as free point by point. A vehicle among
/// unseen voxels may hold its place, and may not leave it: its tube pokes out of the body into
/// voxels nobody has observed. Seen free space ahead lets it go.
#[test]
fn the_commit_check_lets_a_vehicle_hold_its_place_and_not_creep() {
    use trust_core::{Aabb, Vec3};
    use trust_flight::map_sensing::OnlineMap;
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(20.0, 20.0, 10.0)).unwrap();
    let params = trust_sensing::LocalMapParams::default();
    let (start, vehicle) = (Vec3::new(10.0, 10.0, 5.0), Vec3::new(4.03, 4.02, 3.01));
    let mut online = OnlineMap::new(params, &start, bounds, 0.3, 0.54).unwrap();
    online
        .insert(&trust_sensing::Scan::default(), &vehicle)
        .unwrap();
    let check = online.commit_check();
    assert!(check.segment_free(&vehicle, &vehicle), "holding its place");
    let drift = vehicle + Vec3::new(0.002, -0.001, 0.001);
    assert!(check.segment_free(&drift, &drift), "its tracking error");
    for step in [
        Vec3::new(0.0, 0.0, -0.02),
        Vec3::new(0.05, 0.0, 0.0),
        Vec3::new(0.0, 0.3, 0.0),
    ] {
        assert!(
            !check.segment_free(&vehicle, &(vehicle + step)),
            "{step:?} into unseen space"
        );
    }
    // The take-off ball is observed free space: from the start, the vehicle may move in it.
    let check = {
        let mut online = OnlineMap::new(params, &start, bounds, 0.3, 0.54).unwrap();
        online
            .insert(&trust_sensing::Scan::default(), &start)
            .unwrap();
        online.commit_check()
    };
    assert!(check.segment_free(&start, &(start + Vec3::new(0.3, 0.0, 0.0))));
    assert!(!check.segment_free(&start, &(start + Vec3::new(2.0, 0.0, 0.0))));
}

/// The commit margin: a plan may approach unseen space no nearer than the radius plus the
/// margin, and a vehicle may still hold its place beside it.
#[test]
fn the_commit_margin_keeps_plans_off_unseen_space_they_approach() {
    use trust_core::{Aabb, Vec3};
    use trust_flight::map_sensing::OnlineMap;
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(20.0, 20.0, 10.0)).unwrap();
    let params = trust_sensing::LocalMapParams::default();
    let start = Vec3::new(10.0, 10.0, 5.0);
    let check = |margin: f64| {
        let mut online = OnlineMap::new(params, &start, bounds, 0.3, 0.54)
            .unwrap()
            .with_commit_margin(margin)
            .unwrap();
        online
            .insert(&trust_sensing::Scan::default(), &start)
            .unwrap();
        online.commit_check()
    };
    // The take-off ball (1.01 m) holds a 0.3 m tube 0.5 m out, not one of 0.55 m.
    let out = start + Vec3::new(0.5, 0.0, 0.0);
    assert!(check(0.0).segment_free(&start, &out));
    assert!(!check(0.25).segment_free(&start, &out));
    assert!(check(0.25).segment_free(&start, &start));
    for bad in [-0.01, f64::NAN, f64::INFINITY] {
        assert!(
            OnlineMap::new(params, &start, bounds, 0.3, 0.54)
                .unwrap()
                .with_commit_margin(bad)
                .is_err(),
            "{bad}"
        );
    }
}

/// A camera whose vehicle's every plan has been refused for a second turns to look around;
/// otherwise it looks toward the goal (no branch yet).
#[test]
fn a_camera_held_before_refused_space_looks_around() {
    use trust_core::Vec3;
    let s = scene();
    let world = World::build(&s).expect("world");
    let manager = trust_flight::set_up(&world, &trust_flight::scenario::resolve_planner(&s))
        .expect("set up")
        .manager;
    let sensing = || MapSensing::new(&world).expect("sensing").expect("sensed");
    let (p, goal) = (Vec3::new(1.0, 2.0, 1.5), Vec3::new(1.0, 5.0, 1.5));
    // Toward the goal (+y, 90°), turned at 45°/s for 4 s.
    let fly = |m: &mut MapSensing, refused: &dyn Fn(f64) -> bool| {
        let mut yaw = 0.0;
        for k in 0..400 {
            let t = 0.01 * f64::from(k);
            if k % 10 == 0 {
                m.aim(t, &p, &goal, &manager, refused(t));
            }
            yaw = m.turn(0.01);
        }
        yaw
    };
    let toward = fly(&mut sensing(), &|_| false);
    assert!(
        (toward - std::f64::consts::FRAC_PI_2).abs() < 1e-9,
        "{toward}"
    );
    // Refused throughout: toward the goal for the first second, then on round: past it.
    let around = fly(&mut sensing(), &|_| true);
    assert!(!(-1.0..=2.0).contains(&around), "{around}");
    // Refused only now and then: never a second in a row, so it looks toward the goal.
    let blinking = fly(&mut sensing(), &|t| (t * 10.0).round() as i64 % 5 == 0);
    assert!(
        (blinking - std::f64::consts::FRAC_PI_2).abs() < 1e-9,
        "{blinking}"
    );
}

/// `scenarios/unknown-variants/` is the suite's static variants sensed: each file is its
/// `scenarios/variants/` namesake, a two-line header before it and the depth camera after it.
#[test]
fn the_unknown_variants_are_the_variants_sensed() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios");
    let mut count = 0;
    for entry in std::fs::read_dir(root.join("unknown-variants")).unwrap() {
        let path = entry.unwrap().path();
        let sensed = std::fs::read_to_string(&path).unwrap();
        let name = path.file_name().unwrap();
        let known = std::fs::read_to_string(root.join("variants").join(name)).unwrap();
        let body: String = sensed.lines().skip(2).map(|l| format!("{l}\n")).collect();
        assert_eq!(
            body,
            format!("{known}\n[sensing]\nstatic = {{ depth = {{}} }}\n"),
            "{}",
            path.display()
        );
        count += 1;
    }
    assert_eq!(count, 24);
}

//! Regression tests for the failure classes of issue 19, flown end to end with the default
//! planner on the suite's scenario files (`scenarios/suite/`), each log re-checked by the audit:
//!
//! 1. a wall wider than the frontend's sampling box ahead: the vehicle never left the start
//!    (every cycle `dropped_collision` + `fallback`); without the route it now falls back until
//!    the progress monitor widens the search, with the global route it leaves at once and arrives;
//! 2. a flight that stalls (people in a small room block the way): the progress monitor says
//!    `stalled`, the manager escalates, the flight progresses again (`escaped`) and arrives;
//! 3. people faster than the vehicle crossing a small room (a variant file): with forecasts grown
//!    for a quarter of the horizon the vehicle dodged in front of their lanes until the time
//!    limit (7 of seeds 200–259); with the default growth stop it crosses behind them;
//! 4. a person setting off from a pause across the vehicle's path, faster than the vehicle (a
//!    variant file): the constant-velocity forecasts lagged behind them and the fallback fled
//!    along their path; now the EKF compensates its lag and the fallback steps out of the
//!    person's likely path;
//! 5. the paper's real-world setting — a Crazyflie-class room with thin pillars at 1 m/s: the
//!    vehicle brushed a pillar (clearance −0.06 mm) or hovered short of the goal; now it arrives
//!    with positive clearance, within 1.3 × distance / v_max, without exceeding a_max by 5 %.
//!
//! (Braking at a wall with the quadrotor model is `crates/flight/tests/braking.rs`.)

use std::path::{Path, PathBuf};

use trust_flight::scenario::Scenario;
use trust_flight::{Flight, RunOptions, fly};
use trust_runlog::audit::audit;
use trust_runlog::{RunLog, Status};
use trust_world::World;

fn suite(name: &str) -> Scenario {
    load("suite", name)
}

fn load(folder: &str, name: &str) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenarios")
        .join(folder)
        .join(format!("{name}.toml"));
    trust_flight::scenario::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("trust-mission-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Flies `s`, audits its log and returns the flight and the log's event tags in order.
fn fly_audited(s: &Scenario, tag: &str) -> (Flight, Vec<String>) {
    let dir = temp_dir(tag);
    let log_path = dir.join("run.jsonl");
    let options = RunOptions {
        log_path: Some(log_path.clone()),
        zero_timing: true,
        progress_every_s: None,
        log_branches: false,
    };
    let world = World::build(s).unwrap();
    let flight = fly(
        &world,
        &trust_flight::scenario::resolve_planner(s),
        &options,
        |_| {},
    )
    .unwrap();
    let log = RunLog::read(&log_path).unwrap();
    let a = audit(&log, &dir).unwrap();
    assert!(a.passed(), "{tag}: {:?}", a.findings);
    let events = log.cycles.iter().flat_map(|c| c.events.clone()).collect();
    let _ = std::fs::remove_dir_all(&dir);
    (flight, events)
}

#[test]
fn a_wall_ahead_the_vehicle_leaves_the_start_and_arrives() {
    // The paper's setting (no route) finds nothing in front of the 30 m wall: its first cycles
    // drop every candidate and fall back (before issue 19 it did so for ever). Only the
    // progress monitor's escalation (`stalled`: a wider sampling box) gets it round.
    let mut paper = suite("wide_wall");
    paper.planner.route.enabled = false;
    let (paper_flight, paper_events) = fly_audited(&paper, "wall-paper");
    let stalled = paper_events.iter().position(|e| e == "stalled");
    let first_fallback = paper_events.iter().position(|e| e == "fallback");
    assert!(
        matches!((first_fallback, stalled), (Some(f), Some(s)) if f < s),
        "expected fallbacks before `stalled` without the route: {first_fallback:?} {stalled:?}"
    );
    // The default planner holds its place for the few cycles its first route takes, then
    // routes around the wall: no fallback, sooner.
    let (f, events) = fly_audited(&suite("wide_wall"), "wall-route");
    let o = &f.summary.outcome;
    assert_eq!(o.status, Status::Arrived, "{o:?}");
    assert!(o.min_clearance_static_m > 0.0, "{o:?}");
    let cycles = &f.record.cycles;
    let routed = cycles
        .iter()
        .position(|c| c.events.iter().any(|e| e == "rerouted"))
        .expect("a route");
    assert!(routed < 10, "the first route took {routed} cycles");
    assert!(
        cycles[..routed]
            .iter()
            .all(|c| c.events.iter().any(|e| e == "awaiting_route"))
    );
    assert!(!events.iter().any(|e| e == "fallback"), "{events:?}");
    let paper_o = &paper_flight.summary.outcome;
    assert!(
        paper_o.status != Status::Arrived || paper_o.flight_time_s > o.flight_time_s,
        "the route should arrive sooner: {} s against {} s without it",
        o.flight_time_s,
        paper_o.flight_time_s
    );
}

#[test]
fn a_stalled_flight_says_so_then_progresses_and_arrives() {
    // Seed 63 of the room with people stalls and escapes (seeds 63, 86, 87, 109 and 129 of
    // 60–140 do, since the cold solves are spread over cycles; 65 did before). The penetration
    // room's seeds 1, 106 and 65 stalled in turn until the forecasts' growth stopped earlier and
    // the start from rest got faster; seeds 0–99 of it no longer stall at all.
    let (f, events) = fly_audited(&suite("room_people").with_seed(63), "stall");
    let o = &f.summary.outcome;
    assert_eq!(o.status, Status::Arrived, "{o:?}");
    let stalled = events.iter().position(|e| e == "stalled");
    let escaped = events.iter().position(|e| e == "escaped");
    assert!(
        matches!((stalled, escaped), (Some(s), Some(e)) if s < e),
        "expected `stalled` then `escaped`: {stalled:?} {escaped:?}"
    );
    assert!(o.min_clearance_dynamic_m > 0.0, "{o:?}");
}

#[test]
fn people_faster_than_the_vehicle_are_crossed_behind() {
    // Two people cross the room's length at 1.1 and 1.2 m/s, the vehicle flies at 0.7 m/s.
    // Seeds 202 and 204 timed out (50 s) with the growth stopped after a quarter of the horizon.
    for seed in [202, 204] {
        let s = load("variants", "room_penetration_small_fast_people").with_seed(seed);
        let (f, _) = fly_audited(&s, &format!("fast-people-{seed}"));
        let o = &f.summary.outcome;
        assert_eq!(o.status, Status::Arrived, "seed {seed}: {o:?}");
        assert!(o.min_clearance_dynamic_m > 0.0, "seed {seed}: {o:?}");
        assert!(o.flight_time_s < 20.0, "seed {seed}: {o:?}");
    }
}

#[test]
fn a_person_setting_off_across_the_vehicles_path_is_not_run_into() {
    // A person paces across the room with pauses and sets off faster than a constant-velocity
    // filter follows (0 → 1.3 m/s in 2 s; the vehicle flies at 0.8 m/s). Seeds 26 and 28
    // collided with the forecasts lagging behind the pacer and the fallback fleeing along the
    // pacer's path; seed 28 still did with the fallback alone, without the EKF's lag
    // compensation (`trust_predict::EkfParams::accel_smoothing_s`).
    for seed in [26, 28] {
        let s = load("variants", "room_penetration_pacing_person").with_seed(seed);
        let (f, _) = fly_audited(&s, &format!("pacer-{seed}"));
        let o = &f.summary.outcome;
        assert_eq!(o.status, Status::Arrived, "seed {seed}: {o:?}");
        assert!(o.min_clearance_dynamic_m > 0.0, "seed {seed}: {o:?}");
    }
}

#[test]
fn a_crazyflie_room_with_pillars_arrives_with_positive_clearance() {
    for seed in [0, 3] {
        let s = suite("room_static").with_seed(seed);
        let (f, _) = fly_audited(&s, &format!("room-{seed}"));
        let o = &f.summary.outcome;
        assert_eq!(o.status, Status::Arrived, "seed {seed}: {o:?}");
        assert!(o.min_clearance_static_m > 0.0, "seed {seed}: {o:?}");
        let (a, b) = (s.mission.start, s.mission.goal);
        let distance =
            ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt();
        let ideal = distance / s.vehicle.limits.v_max;
        assert!(
            o.flight_time_s <= 1.3 * ideal,
            "seed {seed}: {} s against 1.3 × {ideal} s",
            o.flight_time_s
        );
        assert!(
            o.max_accel <= 1.05 * s.vehicle.limits.a_max,
            "seed {seed}: {o:?}"
        );
    }
}

/// Issue 31: a goal sealed inside a closed box. The route search proves it within the first
/// cycles (the goal's side is a few thousand cells), the manager says why and holds a stop at
/// the reachable point nearest the goal, and the flight ends `unreachable` after the settling
/// time, long before the time limit, with no collision; the log passes the audit.
#[test]
fn a_sealed_goal_is_said_unreachable_within_a_second() {
    let s = load("unreachable", "sealed_goal");
    let (flight, events) = fly_audited(&s, "sealed");
    let o = &flight.summary.outcome;
    assert_eq!(o.status, Status::Unreachable, "{o:?}");
    assert!(
        o.reason.as_deref().is_some_and(|r| r.contains("sealed")),
        "{o:?}"
    );
    let first = flight
        .record
        .cycles
        .iter()
        .find(|c| c.events.iter().any(|e| e == "goal_unreachable"))
        .expect("a goal_unreachable event");
    assert!(first.t <= 1.0, "verdict at {} s", first.t);
    assert!(
        o.t <= first.t + trust_flight::UNREACHABLE_SETTLE_S + 0.2,
        "ended at {}",
        o.t
    );
    assert!(o.min_clearance_static_m > 0.0);
    assert!(!events.iter().any(|e| e == "route_failed"), "{events:?}");
}

/// Issue 31: a goal inside an obstacle (a generated column, also without a global route): the
/// verdict in the first cycle, a stop held short of the column, the flight ended `unreachable`
/// after the settling time, no collision, an audited log.
#[test]
fn a_goal_inside_an_obstacle_is_said_unreachable_at_once() {
    for route in [true, false] {
        let mut s = load("unreachable", "goal_in_column");
        s.planner.route.enabled = route;
        let (flight, _) = fly_audited(
            &s,
            if route {
                "in_column"
            } else {
                "in_column_no_route"
            },
        );
        let o = &flight.summary.outcome;
        assert_eq!(o.status, Status::Unreachable, "{o:?}");
        assert!(
            o.reason
                .as_deref()
                .is_some_and(|r| r.contains("inside an obstacle")),
            "{o:?}"
        );
        let first = flight.record.cycles[0]
            .events
            .iter()
            .any(|e| e == "goal_unreachable");
        assert!(first, "the verdict in the first cycle");
        assert!(o.t <= trust_flight::UNREACHABLE_SETTLE_S + 0.5, "{o:?}");
        assert!(o.min_clearance_static_m > 0.0, "{o:?}");
    }
}

/// Issue 31: a full wall whose one slot (0.4 m) is narrower than the vehicle (0.5 m): the route
/// search exhausts the start's side of the wall (a few hundred thousand units, sliced over the
/// cycles while the vehicle holds its place) and the verdict is "sealed off", not a time-out.
#[test]
fn a_slot_narrower_than_the_vehicle_is_said_unreachable() {
    let s = load("unreachable", "narrow_slot");
    let (flight, _) = fly_audited(&s, "narrow");
    let o = &flight.summary.outcome;
    assert_eq!(o.status, Status::Unreachable, "{o:?}");
    assert!(
        o.reason.as_deref().is_some_and(|r| r.contains("sealed")),
        "{o:?}"
    );
    assert!(o.t < s.time_limit_s, "{o:?}");
    assert!(o.min_clearance_static_m > 0.0);
}

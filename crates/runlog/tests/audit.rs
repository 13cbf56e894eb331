//! The audit and the reader against hand-made logs: each test is named after a defect an
//! independent probe found (a tampered state passing, a slow point cloud, unbounded reads).

use std::path::{Path, PathBuf};
use std::time::Instant;

use trust_runlog::audit::{AuditOptions, audit, audit_file};
use trust_runlog::{
    Bounds, CycleRecord, Dropped, Header, LimitsInfo, LogError, LogWriter, ObstacleInfo,
    ObstacleKind, Outcome, Record, RunLog, SCHEMA, StateRecord, Status, VehicleInfo,
};

/// A fresh folder for one test.
fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("trust-runlog-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn header(points_file: Option<&str>) -> Header {
    Header {
        schema: SCHEMA.into(),
        scenario: "probe".into(),
        seed: 1,
        planner: "trust".into(),
        bounds: Bounds {
            min: [0.0; 3],
            max: [100.0, 20.0, 10.0],
        },
        vehicle: VehicleInfo {
            radius: 0.3,
            model: None,
        },
        limits: LimitsInfo {
            v_max: 5.0,
            a_max: 10.0,
        },
        start: [1.0, 10.0, 2.0],
        goal: [90.0, 10.0, 2.0],
        goal_tolerance: 0.5,
        static_shapes: Vec::new(),
        static_points_file: points_file.map(str::to_string),
        obstacles: vec![ObstacleInfo {
            id: 0,
            shape: ObstacleKind::Sphere,
            radius: 0.5,
            half_height: None,
            half_extents: None,
        }],
        sim: None,
    }
}

/// A flight along x at a speed that rises smoothly (so every state's velocity and acceleration
/// matter), `n` states at 50 Hz, a sphere obstacle circling nearby.
fn states(n: usize) -> Vec<StateRecord> {
    (0..n)
        .map(|k| {
            let t = k as f64 * 0.02;
            // x = t²/4 + t: v = t/2 + 1, a = 1/2.
            StateRecord {
                t,
                p: [1.0 + t + 0.25 * t * t, 10.0, 2.0],
                v: [1.0 + 0.5 * t, 0.0, 0.0],
                a: [0.5, 0.0, 0.0],
                obstacles: vec![[5.0 + t.cos(), 13.0 + t.sin(), 2.0]],
            }
        })
        .collect()
}

fn cycle(t: f64) -> CycleRecord {
    CycleRecord {
        t,
        wall_ms: 1.0,
        main: Some(1),
        branches: 1,
        events: Vec::new(),
        frontend_ms: 0.0,
        backend_ms: 0.0,
        checker_ms: 0.0,
        solve_count: 0,
        effective_t: t,
        branch_j: Vec::new(),
        fallback_collision_free: None,
        fallback_shortfall_m: None,
        fallback_along: None,
        dropped: Dropped::default(),
        route: None,
        route_ms: None,
        branch_samples: None,
        forecasts: None,
        charged_ms: None,
        overrun_ticks: None,
        worker_ms: None,
        waited_ms: None,
        map_ms: None,
    }
}

/// A log whose outcome is what its states say (the audit's recomputation of an untampered copy).
fn consistent_log(header: Header, states: Vec<StateRecord>, dir: &Path) -> RunLog {
    let cycles = states
        .iter()
        .step_by(5)
        .map(|s| cycle(s.t))
        .collect::<Vec<_>>();
    let mut log = RunLog {
        header,
        states,
        cycles,
        outcome: Outcome {
            status: Status::TimedOut,
            t: 0.0,
            flight_time_s: 0.0,
            path_length_m: 0.0,
            min_clearance_static_m: 1e9,
            min_clearance_dynamic_m: 1e9,
            max_speed: 0.0,
            max_accel: 0.0,
            with: None,
            reason: None,
            cycle_count: 0,
            forecast_warning_s: None,
        },
    };
    let r = audit(&log, dir).unwrap().recomputed;
    let finite = |x: f64| if x.is_finite() { x } else { 1e9 };
    log.outcome = Outcome {
        status: r.status,
        t: log.states.last().unwrap().t,
        flight_time_s: r.flight_time_s,
        path_length_m: r.path_length_m,
        min_clearance_static_m: finite(r.min_clearance_static_m),
        min_clearance_dynamic_m: finite(r.min_clearance_dynamic_m),
        max_speed: r.max_speed,
        max_accel: r.max_accel,
        with: r.with,
        ..log.outcome
    };
    log
}

fn write(log: &RunLog, path: &Path) {
    let mut w = LogWriter::create(path).unwrap();
    w.write(&Record::Header(log.header.clone())).unwrap();
    let mut cycles = log.cycles.iter().peekable();
    for s in &log.states {
        w.write(&Record::State(s.clone())).unwrap();
        while let Some(c) = cycles.next_if(|c| c.t <= s.t) {
            w.write(&Record::Cycle(c.clone())).unwrap();
        }
    }
    for c in cycles {
        w.write(&Record::Cycle(c.clone())).unwrap();
    }
    w.write(&Record::Outcome(log.outcome.clone())).unwrap();
    w.finish().unwrap();
}

#[test]
fn an_untampered_log_passes_in_memory_and_streamed() {
    let dir = folder("clean");
    let log = consistent_log(header(None), states(500), &dir);
    let a = audit(&log, &dir).unwrap();
    assert!(a.passed(), "{:?}", a.findings);
    write(&log, &dir.join("run.jsonl"));
    let a = audit_file(&dir.join("run.jsonl"), AuditOptions { cycles: true }).unwrap();
    assert!(a.passed(), "{:?}", a.findings);
    assert_eq!((a.state_count, a.cycle_count), (500, 100));
    assert_eq!(a.recomputed.status, Status::TimedOut);
}

#[test]
fn with_cycles_a_dropped_or_duplicated_cycle_line_is_flagged() {
    let dir = folder("cycle-count");
    let mut log = consistent_log(header(None), states(500), &dir);
    log.outcome.cycle_count = log.cycles.len();
    let path = dir.join("run.jsonl");
    write(&log, &path);
    let a = audit_file(&path, AuditOptions { cycles: true }).unwrap();
    assert!(a.passed(), "{:?}", a.findings);
    for tamper in [0, 1] {
        let mut bad = log.clone();
        if tamper == 0 {
            bad.cycles.remove(40);
        } else {
            let c = bad.cycles[40].clone();
            bad.cycles.insert(40, c);
        }
        write(&bad, &path);
        let a = audit_file(&path, AuditOptions { cycles: true }).unwrap();
        assert!(
            a.findings.iter().any(|f| f.field == "outcome.cycle_count"),
            "{:?}",
            a.findings
        );
        // Without `--cycles` the cycle records are not judged.
        let a = audit_file(&path, AuditOptions { cycles: false }).unwrap();
        assert!(a.passed(), "{:?}", a.findings);
    }
}

#[test]
fn a_velocity_of_1e300_is_flagged() {
    let dir = folder("v1e300");
    let mut log = consistent_log(header(None), states(200), &dir);
    log.states[100].v = [1e300, 0.0, 0.0];
    let a = audit(&log, &dir).unwrap();
    assert!(!a.passed());
    let f = a.findings.iter().find(|f| f.field == "state.v").unwrap();
    assert!(f.to_string().contains("1e300"), "{f}");
    // Numbers in findings are readable: no 309-digit expansion anywhere.
    for f in &a.findings {
        assert!(f.to_string().len() < 300, "{f}");
    }
}

#[test]
fn a_teleport_of_one_state_is_flagged() {
    let dir = folder("teleport");
    let clean = consistent_log(header(None), states(200), &dir);
    // Out to 1e300 and back, and a plausible 2 m hop out and back.
    for jump in [1e300, 2.0] {
        let mut log = clean.clone();
        log.states[120].p[0] += jump;
        let a = audit(&log, &dir).unwrap();
        assert!(!a.passed(), "a jump of {jump} m passed");
        let flagged: Vec<String> = a
            .findings
            .iter()
            .filter(|f| f.field.starts_with("state."))
            .map(ToString::to_string)
            .collect();
        assert!(
            flagged.iter().any(|f| f.contains("state 120")),
            "{flagged:?}"
        );
    }
}

#[test]
fn every_tampered_state_is_flagged() {
    let dir = folder("every");
    let clean = consistent_log(header(None), states(60), &dir);
    for k in 0..clean.states.len() {
        for tamper in 0..3 {
            let mut log = clean.clone();
            let s = &mut log.states[k];
            match tamper {
                0 => s.p[1] += 0.05,
                1 => s.v[2] += 0.2,
                _ => s.p[0] = -1e300,
            }
            let a = audit(&log, &dir).unwrap();
            let names_it = a.findings.iter().any(|f| {
                f.logged.starts_with(&format!("state {k} "))
                    || f.logged.contains(&format!("after state {k}:"))
            });
            assert!(
                !a.passed() && names_it,
                "state {k}, tamper {tamper}: {:?}",
                a.findings
            );
        }
    }
}

#[test]
fn a_far_point_in_the_cloud_does_not_slow_the_audit() {
    let dir = folder("far-point");
    let mut cloud = String::from("# a wall and one point 1000 m away\n");
    for i in 0..2000 {
        cloud.push_str(&format!(
            "{} 15 {}\n",
            i as f64 * 0.05,
            (i % 10) as f64 * 0.5
        ));
    }
    cloud.push_str("1000 1000 0\n");
    std::fs::write(dir.join("static_points.xyz"), cloud).unwrap();
    let log = consistent_log(header(Some("static_points.xyz")), states(3000), &dir);
    let started = Instant::now();
    let a = audit(&log, &dir).unwrap();
    assert!(a.passed(), "{:?}", a.findings);
    // The shell-scanning grid took seconds per thousand states here; the tree, milliseconds.
    assert!(
        started.elapsed().as_secs_f64() < 2.0,
        "{:?}",
        started.elapsed()
    );
    // The wall is 5 m to the side (its points 5 cm apart along x), the vehicle's radius 0.3 m.
    assert!((a.recomputed.min_clearance_static_m - 4.7).abs() < 1e-3);
}

#[cfg(unix)]
#[test]
fn a_points_file_at_dev_zero_is_refused() {
    let dir = folder("dev-zero");
    std::os::unix::fs::symlink("/dev/zero", dir.join("static_points.xyz")).unwrap();
    let log = consistent_log(header(None), states(10), &dir);
    let log = RunLog {
        header: header(Some("static_points.xyz")),
        ..log
    };
    let e = audit(&log, &dir).unwrap_err();
    assert!(e.contains("not a regular file"), "{e}");
    // The log itself, too.
    let e = RunLog::read(Path::new("/dev/zero")).unwrap_err();
    assert!(matches!(e, LogError::NotAFile { .. }), "{e}");
    let e = audit_file(Path::new("/dev/zero"), AuditOptions::default()).unwrap_err();
    assert!(e.to_string().contains("not a regular file"), "{e}");
}

#[test]
fn a_points_file_outside_the_logs_folder_is_refused() {
    let dir = folder("outside");
    std::fs::create_dir_all(dir.join("run")).unwrap();
    std::fs::write(dir.join("cloud.xyz"), "1 2 3\n").unwrap();
    std::fs::write(dir.join("run/cloud.xyz"), "1 2 3\n").unwrap();
    let clean = consistent_log(header(None), states(10), &dir);
    for (name, ok) in [
        ("../cloud.xyz", false),
        ("/etc/hostname", false),
        ("cloud.xyz", true),
        ("sub/../cloud.xyz", true),
    ] {
        let log = RunLog {
            header: header(Some(name)),
            ..clean.clone()
        };
        let r = audit(&log, &dir.join("run"));
        assert_eq!(r.is_ok(), ok, "{name}: {r:?}");
    }
}

#[test]
fn a_points_file_with_only_a_header_is_named() {
    let dir = folder("only-header");
    let clean = consistent_log(header(None), states(10), &dir);
    for (text, expected) in [
        ("x,y,z\n", "only a header"),
        ("# nothing\n\n", "no points"),
        ("x y z\n1 2 3\n", ""),
        ("1, 2, 3\n", ""),
    ] {
        std::fs::write(dir.join("cloud.csv"), text).unwrap();
        let log = RunLog {
            header: header(Some("cloud.csv")),
            ..clean.clone()
        };
        match audit(&log, &dir) {
            Ok(_) => assert!(expected.is_empty(), "{text:?} was accepted"),
            Err(e) => assert!(
                !expected.is_empty() && e.contains(expected),
                "{text:?}: {e}"
            ),
        }
    }
}

#[test]
fn a_long_bad_line_is_not_echoed_whole() {
    let dir = folder("long-line");
    let secret = "s".repeat(10_000);
    std::fs::write(dir.join("cloud.xyz"), format!("1 2 3\n1 2 {secret}\n")).unwrap();
    let log = RunLog {
        header: header(Some("cloud.xyz")),
        ..consistent_log(header(None), states(10), &dir)
    };
    let e = audit(&log, &dir).unwrap_err();
    assert!(e.contains(":2:") && e.len() < 300, "{e}");
    // A log line: serde quotes the offending string; the message is cut.
    let path = dir.join("run.jsonl");
    let clean = consistent_log(header(None), states(10), &dir);
    write(&clean, &path);
    let text = std::fs::read_to_string(&path).unwrap();
    let bad = text.replacen("\"probe\"", &format!("\"probe\",\"seed\":\"{secret}\""), 1);
    std::fs::write(&path, bad).unwrap();
    let e = RunLog::read(&path).unwrap_err().to_string();
    assert!(e.contains(":1:") && e.len() < 600, "{e}");
}

#[test]
fn a_log_over_a_cap_is_refused_while_reading() {
    let dir = folder("cap");
    let path = dir.join("big.xyz");
    // A line longer than the cap on a line: read up to the cap, then refused.
    let f = std::fs::File::create(&path).unwrap();
    f.set_len(trust_runlog::files::MAX_LINE_BYTES as u64 + 10)
        .unwrap();
    let e = trust_runlog::files::read_points(&path).unwrap_err();
    assert!(e.contains("cap"), "{e}");
    std::fs::remove_file(&path).ok();
}

#[test]
fn cycles_are_checked_against_the_contract_on_request() {
    let dir = folder("cycles");
    let mut log = consistent_log(header(None), states(100), &dir);
    log.cycles[3].wall_ms = -1.0;
    log.cycles.push(cycle(50.0));
    let path = dir.join("run.jsonl");
    write(&log, &path);
    // A cycle without `main` (reads as `null` in memory; the file tells).
    let text = std::fs::read_to_string(&path).unwrap();
    let text = text.replacen("\"main\":1,", "", 1);
    std::fs::write(&path, text).unwrap();
    let plain = audit_file(&path, AuditOptions::default()).unwrap();
    assert!(plain.passed(), "{:?}", plain.findings);
    let a = audit_file(&path, AuditOptions { cycles: true }).unwrap();
    let fields: Vec<&str> = a.findings.iter().map(|f| f.field).collect();
    assert_eq!(
        fields,
        ["cycle.main", "cycle.wall_ms", "cycle.t"],
        "{:?}",
        a.findings
    );
}

#[test]
fn an_unreachable_outcome_passes_when_the_flight_timed_out() {
    let dir = folder("unreachable");
    let mut log = consistent_log(header(None), states(50), &dir);
    log.outcome.status = Status::Unreachable;
    assert!(audit(&log, &dir).unwrap().passed());
    log.outcome.status = Status::Arrived;
    assert!(!audit(&log, &dir).unwrap().passed());
}

#[test]
fn an_outcome_of_1e300_is_a_disagreement_not_an_infinite_tolerance() {
    let dir = folder("outcome-1e300");
    let mut log = consistent_log(header(None), states(50), &dir);
    log.outcome.max_speed = 1e300;
    log.outcome.path_length_m = 1e300;
    let a = audit(&log, &dir).unwrap();
    let fields: Vec<&str> = a.findings.iter().map(|f| f.field).collect();
    assert_eq!(fields, ["path_length_m", "max_speed"]);
}

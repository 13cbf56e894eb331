//! Writes a synthetic run log of a long flight, to time the tools that read logs on it:
//! `cargo run --release -p trust-runlog --example hour_log -- OUT.jsonl [STATES] [OBSTACLES]`
//! (default 180 000 states, one hour at 50 Hz, and 100 moving obstacles). The vehicle circles,
//! the obstacles drift; a cycle every 0.1 s carries two sampled branches and one forecast per
//! obstacle (as branch logging does); the header names a points file (`OUT.xyz`: a wall and one
//! point 1000 m away). The outcome is the audit's own recomputation, so the log audits clean.

use std::f64::consts::TAU;
use std::io::Write;
use std::path::PathBuf;

use trust_runlog::audit::{AuditOptions, audit_file};
use trust_runlog::{
    Bounds, BranchSamples, CycleRecord, Dropped, ForecastRecord, ForecastShape, Header, LimitsInfo,
    LogWriter, ObstacleInfo, ObstacleKind, Outcome, Record, SCHEMA, StateRecord, Status,
    VehicleInfo,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = PathBuf::from(
        args.first()
            .ok_or("usage: hour_log OUT.jsonl [STATES] [OBSTACLES]")?,
    );
    let n: usize = args.get(1).map_or(Ok(180_000), |a| a.parse())?;
    let k: usize = args.get(2).map_or(Ok(100), |a| a.parse())?;
    let points_name = format!(
        "{}.xyz",
        out.file_stem().and_then(|s| s.to_str()).unwrap_or("run")
    );
    let mut cloud =
        std::io::BufWriter::new(std::fs::File::create(out.with_file_name(&points_name))?);
    for i in 0..20_000 {
        writeln!(
            cloud,
            "{} 70 {}",
            f64::from(i % 2000) * 0.1,
            f64::from(i / 2000) * 0.5
        )?;
    }
    writeln!(cloud, "1000 1000 0")?;
    cloud.flush()?;

    let header = Header {
        schema: SCHEMA.into(),
        scenario: "hour".into(),
        seed: 0,
        planner: "synthetic".into(),
        bounds: Bounds {
            min: [0.0; 3],
            max: [250.0, 75.0, 20.0],
        },
        vehicle: VehicleInfo {
            radius: 0.3,
            model: None,
        },
        limits: LimitsInfo {
            v_max: 10.0,
            a_max: 15.0,
        },
        start: [150.0, 37.5, 5.0],
        goal: [248.0, 37.5, 5.0],
        goal_tolerance: 0.5,
        static_shapes: Vec::new(),
        static_points_file: Some(points_name),
        obstacles: (0..k)
            .map(|id| ObstacleInfo {
                id,
                shape: ObstacleKind::Cylinder,
                radius: 0.4,
                half_height: Some(1.5),
                half_extents: None,
            })
            .collect(),
        sim: None,
    };
    // The vehicle circles (radius 30 m, 5 m/s); obstacle i drifts along x in its own lane.
    let (centre, r, w) = ([100.0, 37.5, 5.0], 30.0, 5.0 / 30.0);
    let obstacle = |i: usize, t: f64| {
        let lane = 2.0 + 70.0 * i as f64 / k.max(1) as f64;
        [125.0 + 100.0 * (0.01 * t + i as f64).sin(), lane, 1.5]
    };
    let mut log = LogWriter::create(&out)?;
    log.write(&Record::Header(header.clone()))?;
    for step in 0..n {
        let t = step as f64 * 0.02;
        let (s, c) = (w * t).sin_cos();
        let p = [centre[0] + r * c, centre[1] + r * s, centre[2]];
        log.write(&Record::State(StateRecord {
            t,
            p,
            v: [-r * w * s, r * w * c, 0.0],
            a: [-r * w * w * c, -r * w * w * s, 0.0],
            obstacles: (0..k).map(|i| obstacle(i, t)).collect(),
        }))?;
        if step % 5 == 0 {
            let branch = |id: u64, turn: f64| BranchSamples {
                id,
                samples: (0..15)
                    .map(|j| {
                        let tj = t + 0.2 * f64::from(j);
                        let (s, c) = (w * tj + turn * f64::from(j)).sin_cos();
                        [tj, centre[0] + r * c, centre[1] + r * s, centre[2]]
                    })
                    .collect(),
            };
            log.write(&Record::Cycle(CycleRecord {
                t,
                wall_ms: 2.0,
                main: Some(1),
                branches: 2,
                events: if step % 500 == 0 {
                    vec!["switched".into()]
                } else {
                    vec![]
                },
                frontend_ms: 0.5,
                backend_ms: 1.0,
                checker_ms: 0.5,
                solve_count: 2,
                effective_t: t + 0.1,
                branch_j: vec![1.0, 2.0],
                fallback_collision_free: None,
                fallback_shortfall_m: None,
                fallback_along: None,
                dropped: Dropped::default(),
                route: None,
                route_ms: None,
                branch_samples: Some(vec![branch(1, 0.0), branch(2, 0.01 * TAU)]),
                forecasts: Some(
                    (0..k)
                        .map(|i| ForecastRecord {
                            id: i,
                            p0: obstacle(i, t),
                            v0: [1.0, 0.0, 0.0],
                            t0: t,
                            r0: 0.7,
                            mu: 0.3,
                            shape: ForecastShape::Cylinder { half_height: 1.8 },
                            growth_s: Some(1.0),
                            walls: None,
                        })
                        .collect(),
                ),
                charged_ms: None,
                overrun_ticks: None,
                worker_ms: None,
                waited_ms: None,
                map_ms: None,
            }))?;
        }
    }
    let outcome_at = |status| Outcome {
        status,
        t: (n - 1) as f64 * 0.02,
        flight_time_s: 0.0,
        path_length_m: 0.0,
        min_clearance_static_m: 1e9,
        min_clearance_dynamic_m: 1e9,
        max_speed: 0.0,
        max_accel: 0.0,
        with: None,
        reason: None,
        cycle_count: n.div_ceil(5),
        forecast_warning_s: None,
    };
    // A stand-in outcome, then the audit's figures in its place.
    log.write(&Record::Outcome(outcome_at(Status::TimedOut)))?;
    log.finish()?;
    let r = audit_file(&out, AuditOptions::default())?.recomputed;
    let text_len = std::fs::metadata(&out)?.len();
    let tail_start = {
        use std::io::{Read, Seek, SeekFrom};
        let mut f = std::fs::File::open(&out)?;
        let back = text_len.min(4096);
        f.seek(SeekFrom::Start(text_len - back))?;
        let mut tail = String::new();
        f.read_to_string(&mut tail)?;
        let last = tail.trim_end().rfind('\n').map_or(0, |i| i + 1);
        text_len - back + last as u64
    };
    let file = std::fs::OpenOptions::new().write(true).open(&out)?;
    file.set_len(tail_start)?;
    drop(file);
    let finite = |x: f64| if x.is_finite() { x } else { 1e9 };
    let outcome = Outcome {
        status: r.status,
        flight_time_s: r.flight_time_s,
        path_length_m: r.path_length_m,
        min_clearance_static_m: finite(r.min_clearance_static_m),
        min_clearance_dynamic_m: finite(r.min_clearance_dynamic_m),
        max_speed: r.max_speed,
        max_accel: r.max_accel,
        with: r.with,
        ..outcome_at(r.status)
    };
    let mut f = std::fs::OpenOptions::new().append(true).open(&out)?;
    writeln!(f, "{}", serde_json::to_string(&Record::Outcome(outcome))?)?;
    println!(
        "wrote {} ({} states, {} obstacles, {:.0} MB)",
        out.display(),
        n,
        k,
        std::fs::metadata(&out)?.len() as f64 / 1e6
    );
    Ok(())
}

//! The replay's public API on a synthetic run log: the page (self-contained, valid embedded JSON),
//! the GIF (frames and size, decoded with the `gif` crate), bad input, old logs, and — when
//! Chromium is installed — the page in a headless browser.

use std::path::{Path, PathBuf};

use trust_replay::{GifParams, ReplayError, ReplayParams, browser, write_replay};
use trust_runlog::{
    Bounds, BranchSamples, CycleRecord, Dropped, ForecastRecord, ForecastShape, Header, LimitsInfo,
    LogWriter, ObstacleInfo, ObstacleKind, Outcome, Record, SCHEMA, StateRecord, StaticShape,
    Status, VehicleInfo,
};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("trust-replay-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn header() -> Header {
    Header {
        schema: SCHEMA.into(),
        scenario: "synthetic </script><!-- x".into(),
        seed: 3,
        planner: "trust".into(),
        bounds: Bounds {
            min: [0.0, 0.0, 0.0],
            max: [20.0, 10.0, 4.0],
        },
        vehicle: VehicleInfo {
            radius: 0.2,
            model: None,
        },
        limits: LimitsInfo {
            v_max: 3.0,
            a_max: 6.0,
        },
        start: [1.0, 5.0, 1.0],
        goal: [19.0, 5.0, 1.0],
        goal_tolerance: 0.5,
        static_shapes: vec![
            StaticShape::Sphere {
                center: [6.0, 2.0, 1.0],
                radius: 0.8,
            },
            StaticShape::Cylinder {
                center: [10.0, 8.0],
                radius: 0.5,
                z_min: 0.0,
                z_max: 4.0,
            },
            StaticShape::Box {
                min: [14.0, 1.0, 0.0],
                max: [15.0, 3.0, 2.0],
            },
        ],
        static_points_file: None,
        obstacles: vec![
            ObstacleInfo {
                id: 0,
                shape: ObstacleKind::Cylinder,
                radius: 0.4,
                half_height: Some(1.0),
                half_extents: None,
            },
            ObstacleInfo {
                id: 1,
                shape: ObstacleKind::Sphere,
                radius: 0.3,
                half_height: None,
                half_extents: None,
            },
        ],
        sim: None,
    }
}

/// The vehicle flies along x at 2 m/s from t = 0 to `t_end`; obstacle 0 crosses its path.
fn obstacle_at(t: f64) -> Vec<[f64; 3]> {
    vec![[10.0, 9.0 - 0.8 * t, 1.0], [4.0 + 0.5 * t, 2.0, 2.0]]
}

fn write_log(path: &Path, t_end: f64, with_branches: bool) {
    let mut w = LogWriter::create(path).unwrap();
    w.write(&Record::Header(header())).unwrap();
    let steps = (t_end / 0.02).round() as usize;
    for k in 0..=steps {
        let t = k as f64 * 0.02;
        w.write(&Record::State(StateRecord {
            t,
            p: [1.0 + 2.0 * t, 5.0, 1.0],
            v: [2.0, 0.0, 0.0],
            a: [0.0; 3],
            obstacles: obstacle_at(t),
        }))
        .unwrap();
        if k % 5 == 0 && k < steps {
            let branch = |dy: f64| -> Vec<[f64; 4]> {
                (0..=10)
                    .map(|i| {
                        let s = t + 0.2 * i as f64;
                        [s, 1.0 + 2.0 * s, 5.0 + dy * i as f64 / 10.0, 1.0]
                    })
                    .collect()
            };
            let events = match k {
                25 => vec!["switched".to_string()],
                50 => vec!["fallback".to_string(), "stalled".to_string()],
                _ => vec![],
            };
            w.write(&Record::Cycle(CycleRecord {
                t,
                wall_ms: 1.0,
                main: if k == 50 { None } else { Some(1) },
                branches: 2,
                events,
                frontend_ms: 0.0,
                backend_ms: 0.0,
                checker_ms: 0.0,
                solve_count: 2,
                effective_t: t + 0.02,
                branch_j: vec![1.0, 2.0],
                fallback_collision_free: (k == 50).then_some(true),
                fallback_shortfall_m: None,
                fallback_along: None,
                dropped: Dropped::default(),
                route: None,
                route_ms: None,
                branch_samples: with_branches.then(|| {
                    vec![
                        BranchSamples {
                            id: 1,
                            samples: branch(0.0),
                        },
                        BranchSamples {
                            id: 2,
                            samples: branch(1.5),
                        },
                    ]
                }),
                forecasts: with_branches.then(|| {
                    vec![
                        ForecastRecord {
                            id: 0,
                            p0: obstacle_at(t)[0],
                            v0: [0.0, -0.8, 0.0],
                            t0: t,
                            r0: 0.5,
                            mu: 0.2,
                            shape: ForecastShape::Cylinder { half_height: 1.1 },
                            growth_s: Some(1.0),
                            walls: Some([[2.0, 0.0, 0.0], [8.0, 8.0, 3.0]]),
                        },
                        ForecastRecord {
                            id: 1,
                            p0: obstacle_at(t)[1],
                            v0: [0.5, 0.0, 0.0],
                            t0: t,
                            r0: 0.4,
                            mu: 0.2,
                            shape: ForecastShape::Sphere,
                            growth_s: None,
                            walls: None,
                        },
                    ]
                }),
                charged_ms: None,
                overrun_ticks: None,
                worker_ms: None,
                waited_ms: None,
                map_ms: None,
            }))
            .unwrap();
        }
    }
    w.write(&Record::Outcome(Outcome {
        status: Status::TimedOut,
        t: t_end,
        flight_time_s: t_end,
        path_length_m: 2.0 * t_end,
        min_clearance_static_m: 1.0,
        min_clearance_dynamic_m: 1.0,
        max_speed: 2.0,
        max_accel: 0.0,
        with: None,
        reason: None,
        cycle_count: steps / 5,
        forecast_warning_s: None,
    }))
    .unwrap();
    w.finish().unwrap();
}

/// The text of the page's embedded data element.
fn embedded_json(html: &str) -> &str {
    let open = "<script id=\"replay-data\" type=\"application/json\">";
    let start = html.find(open).expect("data element") + open.len();
    let end = html[start..]
        .find("</script>")
        .expect("end of data element");
    &html[start..start + end]
}

#[test]
fn the_page_is_self_contained_and_embeds_valid_json() {
    let dir = temp_dir("page");
    let log = dir.join("run.jsonl");
    write_log(&log, 3.0, true);
    let files = write_replay(&log, &dir, &ReplayParams::default()).unwrap();
    assert_eq!(files.html, dir.join("run.replay.html"));
    let html = std::fs::read_to_string(&files.html).unwrap();
    assert_eq!(html.len(), files.html_bytes);
    // Nothing fetched: no http(s) address anywhere, no external script, style or image.
    for bad in [
        "http://",
        "https://",
        "<script src",
        "<link",
        "<img",
        "@import",
    ] {
        assert!(!html.contains(bad), "the page contains {bad:?}");
    }
    assert!(!html.contains("{{"), "a template placeholder is left");
    // The data parses, and the scenario name with `</script>` in it did not end the element.
    let data: serde_json::Value = serde_json::from_str(embedded_json(&html)).unwrap();
    assert_eq!(data["header"]["scenario"], "synthetic </script><!-- x");
    let states = data["states"]["t"].as_array().unwrap();
    // 10 Hz of 3 s, first and last included.
    assert_eq!(states.len(), 31, "{}", states.len());
    assert_eq!(data["states"]["p"][30][0], 7.0);
    let cycles = data["cycles"].as_array().unwrap();
    assert_eq!(cycles.len(), 30);
    assert_eq!(cycles[5]["events"][0], "switched");
    // Main first; the straight main branch is simplified to its two ends.
    assert_eq!(cycles[0]["ids"], serde_json::json!([1, 2]));
    assert_eq!(
        cycles[0]["branches"][0],
        serde_json::json!([[1.0, 5.0, 1.0], [5.0, 5.0, 1.0]])
    );
    // [id, p0, v0, t0, r0, mu, half_height, growth_s, walls]; obstacle 1 (4 m from the vehicle
    // at t = 0) is near.
    assert_eq!(cycles[0]["forecasts"][0][10], 1.1);
    assert_eq!(cycles[0]["forecasts"][0][11], 1.0);
    assert_eq!(
        cycles[0]["forecasts"][0][12],
        serde_json::json!([[2.0, 0.0, 0.0], [8.0, 8.0, 3.0]])
    );
    assert_eq!(cycles[0]["forecasts"][1][0], 1);
    assert!(cycles[0]["forecasts"][1][11].is_null());
    assert!(cycles[0]["forecasts"][1][12].is_null());
    // Clearances recomputed from the states, both finite and positive at the start.
    assert!(data["states"]["clear"][0][0].as_f64().unwrap() > 0.0);
    assert!(data["states"]["clear"][0][1].as_f64().unwrap() > 0.0);
    // Same log, same bytes.
    let again = trust_replay::page_html(
        &trust_runlog::RunLog::read(&log).unwrap(),
        &dir,
        &ReplayParams::default(),
    )
    .unwrap();
    assert!(again == html);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_gif_has_the_expected_frames_and_size() {
    let dir = temp_dir("gif");
    let log = dir.join("flight.jsonl");
    write_log(&log, 3.0, true);
    let params = ReplayParams {
        gif: GifParams {
            frame_step_s: 0.5,
            max_frames: 48,
            width_px: 400,
            frame_delay_ms: 100,
        },
        ..ReplayParams::default()
    };
    let files = write_replay(&log, &dir, &params).unwrap();
    assert_eq!(files.gif.path, dir.join("flight.replay.gif"));
    // 0, 0.5, …, 3.0 s.
    assert_eq!(files.gif.frame_count, 7);
    // MapView's width is the plot's plus its axis labels: about the width asked for.
    assert!((400..=480).contains(&files.gif.width_px), "{:?}", files.gif);

    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options
        .read_info(std::fs::File::open(&files.gif.path).unwrap())
        .unwrap();
    assert_eq!(u32::from(decoder.width()), files.gif.width_px);
    assert_eq!(u32::from(decoder.height()), files.gif.height_px);
    let mut frames = Vec::new();
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        assert_eq!(frame.delay, 10, "100 ms in hundredths");
        frames.push(frame.buffer.to_vec());
    }
    assert_eq!(frames.len(), 7);
    // The vehicle moves: the first and last frames differ.
    assert!(frames[0] != frames[6]);

    // A long flight is capped at max_frames.
    let long = dir.join("long.jsonl");
    write_log(&long, 9.0, false);
    let capped = ReplayParams {
        gif: GifParams {
            max_frames: 5,
            ..params.gif.clone()
        },
        ..params
    };
    let files = write_replay(&long, &dir, &capped).unwrap();
    assert_eq!(files.gif.frame_count, 5);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_log_without_branches_still_replays() {
    let dir = temp_dir("old");
    let log = dir.join("run.jsonl");
    write_log(&log, 1.0, false);
    let files = write_replay(&log, &dir, &ReplayParams::default()).unwrap();
    let html = std::fs::read_to_string(&files.html).unwrap();
    let data: serde_json::Value = serde_json::from_str(embedded_json(&html)).unwrap();
    assert!(data["cycles"][0].get("branches").is_none());
    assert!(data["cycles"][0].get("forecasts").is_none());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_input_is_a_typed_error_naming_the_file() {
    let dir = temp_dir("bad");
    let p = ReplayParams::default();
    let missing = dir.join("missing.jsonl");
    let e = write_replay(&missing, &dir, &p).unwrap_err();
    assert!(matches!(e, ReplayError::Log(_)), "{e:?}");
    assert!(e.to_string().contains("missing.jsonl"), "{e}");

    let empty = dir.join("empty.jsonl");
    std::fs::write(&empty, "").unwrap();
    let e = write_replay(&empty, &dir, &p).unwrap_err().to_string();
    assert!(e.contains("empty.jsonl") && e.contains("no header"), "{e}");

    let not_a_log = dir.join("notes.jsonl");
    std::fs::write(&not_a_log, "{\"type\": \"header\"}\nhello\n").unwrap();
    let e = write_replay(&not_a_log, &dir, &p).unwrap_err().to_string();
    assert!(e.contains("notes.jsonl:1:"), "{e}");

    let log = dir.join("run.jsonl");
    write_log(&log, 1.0, true);
    let bad = ReplayParams {
        gif: GifParams {
            width_px: 10,
            ..GifParams::default()
        },
        ..ReplayParams::default()
    };
    let e = write_replay(&log, &dir, &bad).unwrap_err().to_string();
    assert!(e.contains("gif.width_px"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Whether this is a CI run: the environment variable `CI` is set (`.ci/run` exports `CI=1`, as
/// hosted CI services do), and not to an empty string, `0` or `false`.
fn under_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !matches!(v.trim(), "" | "0" | "false"))
}

/// Opens the page in headless Chromium, moves the slider (through `#t=`) and checks that the
/// vehicle moved, with no script or console error. CI installs Chromium (`.ci/run`), and under
/// CI a missing Chromium fails the test; in a local run without it the test says SKIPPED and
/// passes.
#[test]
fn the_page_plays_in_headless_chromium() {
    let Some(chromium) = browser::find_chromium() else {
        assert!(
            !under_ci(),
            "no chromium on the PATH under CI (CI={:?}): .ci/run installs the Debian packages \
             chromium and chromium-driver, or set TRUST_CHROMIUM",
            std::env::var("CI").unwrap_or_default()
        );
        eprintln!(
            "SKIPPED: no chromium on the PATH (set TRUST_CHROMIUM or install the Debian packages \
             chromium and chromium-driver; CI does, and fails here without it)"
        );
        return;
    };
    let dir = temp_dir("browser");
    let log = dir.join("run.jsonl");
    write_log(&log, 3.0, true);
    let files = write_replay(&log, &dir, &ReplayParams::default()).unwrap();
    let check = browser::check_page(&chromium, &files.html, 2.5, &dir.join("shots")).unwrap();
    assert_eq!(check.start.t, 0.0);
    assert!((check.later.t - 2.5).abs() < 1e-6, "{:?}", check.later);
    // The vehicle flies 5 m along x in 2.5 s.
    assert!(
        (check.later.vehicle[0] - 6.0).abs() < 1e-3,
        "{:?}",
        check.later
    );
    assert!(check.moved_px > 20.0, "{check:?}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_static_point_cloud_is_drawn_and_a_missing_one_is_named() {
    let dir = temp_dir("points");
    let log = dir.join("run.jsonl");
    write_log(&log, 1.0, true);
    let text = std::fs::read_to_string(&log).unwrap();
    assert!(text.contains("\"static_points_file\":null"));
    std::fs::write(
        &log,
        text.replacen(
            "\"static_points_file\":null",
            "\"static_points_file\":\"pts.xyz\"",
            1,
        ),
    )
    .unwrap();
    let e = write_replay(&log, &dir, &ReplayParams::default()).unwrap_err();
    assert!(matches!(e, ReplayError::Points { .. }), "{e:?}");
    assert!(e.to_string().contains("pts.xyz"), "{e}");

    let points: String = (0..50)
        .map(|i| format!("{} 8.0 {}\n", 0.2 * f64::from(i), 0.05 * f64::from(i)))
        .collect();
    std::fs::write(dir.join("pts.xyz"), format!("# a wall\n{points}")).unwrap();
    let params = ReplayParams {
        max_points: 20,
        ..ReplayParams::default()
    };
    let files = write_replay(&log, &dir, &params).unwrap();
    let html = std::fs::read_to_string(&files.html).unwrap();
    let data: serde_json::Value = serde_json::from_str(embedded_json(&html)).unwrap();
    // 50 points thinned to every third: 17 ≤ 20.
    assert_eq!(data["points"].as_array().unwrap().len(), 17);
    assert_eq!(data["points"][1], serde_json::json!([0.6, 8.0, 0.15]));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_long_flight_is_decimated_with_every_clearance_minimum_kept() {
    let dir = temp_dir("decimated");
    let log = dir.join("run.jsonl");
    write_log(&log, 3.0, true);
    let params = ReplayParams {
        max_states: 8,
        max_cycles: 4,
        ..ReplayParams::default()
    };
    let files = write_replay(&log, &dir, &params).unwrap();
    let html = std::fs::read_to_string(&files.html).unwrap();
    let data: serde_json::Value = serde_json::from_str(embedded_json(&html)).unwrap();
    let t = data["states"]["t"].as_array().unwrap();
    assert!(t.len() <= 9, "{}", t.len());
    assert_eq!(t.last().unwrap(), 3.0, "the last state is kept");
    let cycles = data["cycles"].as_array().unwrap();
    assert!(cycles.len() <= 4, "{}", cycles.len());
    // Every event of the 30 cycles is still on the timeline.
    let events = |v: &[serde_json::Value]| -> usize {
        v.iter()
            .map(|c| c["events"].as_array().unwrap().len())
            .sum()
    };
    let full = write_replay(&log, &dir, &ReplayParams::default()).unwrap();
    let all: serde_json::Value =
        serde_json::from_str(embedded_json(&std::fs::read_to_string(&full.html).unwrap())).unwrap();
    assert_eq!(events(cycles), events(all["cycles"].as_array().unwrap()));
    // The smallest clearance of the flight survives the decimation.
    let smallest = |d: &serde_json::Value, k: usize| {
        d["states"]["clear"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|c| c[k].as_f64())
            .fold(f64::INFINITY, f64::min)
    };
    let exact =
        trust_runlog::audit::state_clearances(&trust_runlog::RunLog::read(&log).unwrap(), &dir)
            .unwrap()
            .iter()
            .map(|c| c[1])
            .fold(f64::INFINITY, f64::min);
    assert!((smallest(&data, 1) - exact).abs() < 0.01, "{exact}");
    std::fs::remove_dir_all(&dir).ok();
}

#[cfg(unix)]
#[test]
fn a_points_file_at_dev_zero_is_refused() {
    let dir = temp_dir("dev-zero");
    let log = dir.join("run.jsonl");
    write_log(&log, 1.0, false);
    let text = std::fs::read_to_string(&log).unwrap();
    std::fs::write(
        &log,
        text.replacen(
            "\"static_points_file\":null",
            "\"static_points_file\":\"zero.xyz\"",
            1,
        ),
    )
    .unwrap();
    std::os::unix::fs::symlink("/dev/zero", dir.join("zero.xyz")).unwrap();
    let e = write_replay(&log, &dir, &ReplayParams::default()).unwrap_err();
    assert!(e.to_string().contains("not a regular file"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

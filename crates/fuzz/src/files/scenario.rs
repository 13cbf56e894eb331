//! The scenario-side groups: mutated scenario files (`files::scenario`), the CSV tracks they
//! name (`files::track`) and points files (`files::points`), each case written to the case
//! folder and passed through what `trust-sim validate` calls ([`trust_world::load_checked`]) and
//! what `trust-sim run` does before its first step ([`run_set_up`]).
//!
//! Oracles, beyond the harness's (no panic, abort or hang):
//!
//! * **agreement**: `validate` accepts ⇔ `run` sets up; when both refuse, with the same message
//!   (the same checks run in both);
//! * **readable**: every message passes [`super::readable::problem`].
//!
//! A case that validates but whose planner map has more than `--max-voxels` ESDF voxels is
//! counted as heavy and not set up (a build of up to `trust_geometry::MAX_VOXELS` voxels is
//! legitimate and takes seconds and gigabytes; the smoke run cannot afford it).

use std::fmt::Write as _;
use std::path::Path;

use trust_flight::scenario::Scenario;
use trust_flight::{Clock, LoopParams, header, real_time_planner, set_up};
use trust_runlog::{LogWriter, Record};
use trust_vehicle::{ControlledQuadrotor, PerfectTracking, Reference};
use trust_world::scenario::VehicleModel;
use trust_world::{World, WorldError};

use super::corpus::{CaseDir, esdf_voxels};
use super::mutate::{Rng, chance, float_edge, int_edge, number_text, pick, raw_edit, special_path};
use super::{Ctx, Flag, Verdict};

/// The scenario file of every case, in the case folder.
const SCENARIO: &str = "scenario.toml";

// ---------------------------------------------------------------- the entry points

/// What `trust-sim run` does with a scenario file before its first physics step: parse, check
/// every section ([`trust_flight::scenario::check`]), build the world, resolve the planner (real time as the loop would), set up the traffic, sensor and
/// planner ([`trust_flight::set_up`]), the vehicle model at rest on the start, and write the
/// log header.
///
/// # Errors
/// The first error, as `run` would print it.
pub fn run_set_up(path: &Path, log: &Path) -> Result<(), String> {
    let s = Scenario::parse_file(path).map_err(|e| e.to_string())?;
    let problems = trust_flight::scenario::check(&s);
    if !problems.is_empty() {
        return Err(WorldError::Invalid {
            path: s.origin(),
            problems,
        }
        .to_string());
    }
    let world = World::build(&s).map_err(|e| e.to_string())?;
    let planner = trust_flight::scenario::resolve_planner(&s);
    let params = LoopParams::new(&world, &planner);
    let planner = match params.clock {
        Clock::RealTime { cpu_scale } => real_time_planner(&planner, cpu_scale),
        Clock::Fixed { .. } => planner,
    };
    set_up(&world, &planner).map_err(|e| e.to_string())?;
    let hover = Reference::hover(world.start());
    let scenario = world.scenario();
    match scenario.vehicle.model {
        VehicleModel::Quadrotor => {
            let mut gains = scenario.vehicle.gains;
            gains.max_accel_m_s2 = gains.max_accel_m_s2.or(Some(scenario.vehicle.limits.a_max));
            ControlledQuadrotor::starting_on(scenario.vehicle.quadrotor, gains, 0.0, &hover)
                .map(|_| ())
                .map_err(|e| e.to_string())?;
        }
        VehicleModel::Perfect => {
            PerfectTracking::new(0.0, &hover)
                .map(|_| ())
                .map_err(|e| e.to_string())?;
        }
    }
    let mut w = LogWriter::create(log).map_err(|e| e.to_string())?;
    w.write(&Record::Header(header(&world, &planner.label, None)))
        .map_err(|e| e.to_string())?;
    w.finish().map_err(|e| e.to_string())
}

/// Validates and sets up the scenario of the case folder, and judges both (module docs);
/// `input` is every file the case wrote (for the readability oracle).
fn judge(ctx: &Ctx, dir: &CaseDir, input: &str, v: &mut Verdict) {
    let path = dir.case.join(SCENARIO);
    let validate = trust_flight::scenario::load_checked(&path);
    if let Err(e) = &validate {
        v.readable(&e.to_string(), input);
    }
    v.accepted = validate.is_ok();
    if let Ok(s) = &validate
        && esdf_voxels(s) > ctx.max_voxels
    {
        v.heavy = true;
        return;
    }
    let run = run_set_up(&path, &dir.out.join("header.jsonl"));
    if let Err(e) = &run {
        v.readable(e, input);
    }
    match (&validate, &run) {
        (Ok(_), Err(e)) => v.flag(Flag::Disagree, format!("validate accepts, run fails: {e}")),
        (Err(e), Ok(())) => v.flag(Flag::Disagree, format!("run sets up, validate says: {e}")),
        (Err(a), Err(b)) if a.to_string() != *b => v.flag(
            Flag::Disagree,
            format!("validate says: {a} | run says: {b}"),
        ),
        _ => {}
    }
    if let Err(WorldError::Invalid { problems, .. }) = &validate
        && problems.is_empty()
    {
        v.flag(Flag::Wrong, "refused without a problem".into());
    }
}

// ---------------------------------------------------------------- TOML structure

/// A step of a path into a TOML document.
#[derive(Debug, Clone, PartialEq)]
enum Step {
    Key(String),
    Index(usize),
}

/// Every node of `v` below the root for which `keep` holds, by path.
fn collect(
    v: &toml::Value,
    path: &mut Vec<Step>,
    keep: &dyn Fn(&toml::Value) -> bool,
    out: &mut Vec<Vec<Step>>,
) {
    let mut visit = |step: Step, x: &toml::Value, path: &mut Vec<Step>| {
        path.push(step);
        if keep(x) {
            out.push(path.clone());
        }
        collect(x, path, keep, out);
        path.pop();
    };
    match v {
        toml::Value::Table(t) => {
            for (k, x) in t {
                visit(Step::Key(k.clone()), x, path);
            }
        }
        toml::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                visit(Step::Index(i), x, path);
            }
        }
        _ => {}
    }
}

fn node_mut<'a>(v: &'a mut toml::Value, path: &[Step]) -> Option<&'a mut toml::Value> {
    let Some((first, rest)) = path.split_first() else {
        return Some(v);
    };
    let next = match (v, first) {
        (toml::Value::Table(t), Step::Key(k)) => t.get_mut(k)?,
        (toml::Value::Array(a), Step::Index(i)) => a.get_mut(*i)?,
        _ => return None,
    };
    node_mut(next, rest)
}

fn show(path: &[Step]) -> String {
    let mut s = String::new();
    for step in path {
        match step {
            Step::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(k);
            }
            Step::Index(i) => {
                let _ = write!(s, "[{i}]");
            }
        }
    }
    s
}

fn all_nodes(doc: &toml::Value) -> Vec<Vec<Step>> {
    nodes_where(doc, |_| true)
}

/// The nodes of `doc` for which `keep` holds.
fn nodes_where(doc: &toml::Value, keep: impl Fn(&toml::Value) -> bool) -> Vec<Vec<Step>> {
    let mut out = Vec::new();
    collect(doc, &mut Vec::new(), &keep, &mut out);
    out
}

fn is_number(v: &toml::Value) -> bool {
    matches!(v, toml::Value::Integer(_) | toml::Value::Float(_))
}

/// A value of another type than `v`'s.
fn other_type(rng: &mut Rng, v: &toml::Value) -> toml::Value {
    loop {
        let x = match pick(rng, 9) {
            0 => toml::Value::String(number_text(rng)),
            1 => toml::Value::String(["", "1e308", "NaN", "sphere", "-0"][pick(rng, 5)].into()),
            2 => toml::Value::Boolean(true),
            3 => toml::Value::Array(Vec::new()),
            4 => toml::Value::Array(vec![toml::Value::Integer(1), "a".into()]),
            5 => toml::Value::Table(toml::Table::new()),
            6 => toml::Value::Integer(int_edge(rng, None)),
            7 => toml::Value::Float(float_edge(rng, None)),
            _ => "1979-05-27T07:32:00Z"
                .parse::<toml::value::Datetime>()
                .map_or(toml::Value::Boolean(false), toml::Value::Datetime),
        };
        if std::mem::discriminant(&x) != std::mem::discriminant(v) {
            return x;
        }
    }
}

/// Sets `path` in `doc`, creating the tables on the way (over whatever was there).
fn set_path(doc: &mut toml::Value, path: &[Step], value: toml::Value) {
    let Some((last, parents)) = path.split_last() else {
        return;
    };
    let mut cur = doc;
    for step in parents {
        let next = match (cur, step) {
            (toml::Value::Table(t), Step::Key(k)) => t
                .entry(k.clone())
                .or_insert_with(|| toml::Value::Table(toml::Table::new())),
            (toml::Value::Array(a), Step::Index(i)) if *i < a.len() => &mut a[*i],
            _ => return,
        };
        if !matches!(next, toml::Value::Table(_) | toml::Value::Array(_)) {
            *next = toml::Value::Table(toml::Table::new());
        }
        cur = next;
    }
    match (cur, last) {
        (toml::Value::Table(t), Step::Key(k)) => {
            t.insert(k.clone(), value);
        }
        (toml::Value::Array(a), Step::Index(i)) => {
            if *i < a.len() {
                a[*i] = value;
            } else {
                a.push(value);
            }
        }
        _ => {}
    }
}

fn remove_path(doc: &mut toml::Value, path: &[Step]) {
    let Some((last, parents)) = path.split_last() else {
        return;
    };
    match (node_mut(doc, parents), last) {
        (Some(toml::Value::Table(t)), Step::Key(k)) => {
            t.remove(k);
        }
        (Some(toml::Value::Array(a)), Step::Index(i)) if *i < a.len() => {
            a.remove(*i);
        }
        _ => {}
    }
}

fn table(pairs: &[(&str, toml::Value)]) -> toml::Value {
    toml::Value::Table(
        pairs
            .iter()
            .map(|(k, v)| ((*k).to_string(), v.clone()))
            .collect(),
    )
}

fn floats(xs: &[f64]) -> toml::Value {
    toml::Value::Array(xs.iter().map(|&x| toml::Value::Float(x)).collect())
}

/// A feature the file may not have, with values at their edges: a random obstacle group of an
/// edge count, a sampled point cloud of an edge spacing, a random mission, a real-time clock, a
/// scripted obstacle (Fourier with up to 65 harmonics, or inline samples), a generator.
fn add_feature(rng: &mut Rng, doc: &mut toml::Value) -> String {
    let key = |k: &str| Step::Key(k.to_string());
    match pick(rng, 7) {
        0 => {
            let count = int_edge(rng, Some(4));
            let group = table(&[
                ("count", toml::Value::Integer(count)),
                ("speed_m_s", floats(&[0.5, float_edge(rng, Some(2.0))])),
                ("motion", table(&[("kind", "random-maneuvers".into())])),
            ]);
            let groups = toml::Value::Array(vec![group]);
            set_path(doc, &[key("random_obstacles")], groups);
            format!("random_obstacles count {count}")
        }
        1 => {
            let voxel = if chance(rng, 0.5) {
                float_edge(rng, Some(0.5))
            } else {
                0.5
            };
            let spacing = float_edge(rng, Some(0.5));
            set_path(
                doc,
                &[key("static"), key("point_cloud")],
                table(&[
                    ("source", "shapes".into()),
                    ("esdf_voxel_m", toml::Value::Float(voxel)),
                    ("spacing_m", toml::Value::Float(spacing)),
                ]),
            );
            format!("sampled cloud voxel {voxel:e}, spacing {spacing:e}")
        }
        2 => {
            let d = float_edge(rng, Some(5.0));
            set_path(
                doc,
                &[key("mission"), key("random")],
                table(&[
                    ("min_distance_m", toml::Value::Float(d)),
                    (
                        "clearance_m",
                        toml::Value::Float(float_edge(rng, Some(0.3))),
                    ),
                ]),
            );
            format!("random mission, min distance {d:e}")
        }
        3 => {
            let scale = float_edge(rng, Some(1.0));
            set_path(
                doc,
                &[key("sim"), key("latency")],
                table(&[
                    ("kind", "measured".into()),
                    ("cpu_scale", toml::Value::Float(scale)),
                ]),
            );
            format!("real time, cpu_scale {scale:e}")
        }
        4 => {
            let n = [1, 2, 63, 64, 65, 1000][pick(rng, 6)];
            let coef = floats(&[float_edge(rng, Some(1.0)), 0.0, 0.0]);
            let fourier = table(&[
                ("kind", "fourier".into()),
                ("period_s", toml::Value::Float(float_edge(rng, Some(10.0)))),
                ("center", floats(&[5.0, 5.0, 1.5])),
                ("cos", toml::Value::Array(vec![coef; n])),
                ("phase_s", toml::Value::Float(float_edge(rng, Some(0.0)))),
            ]);
            push_obstacle(doc, fourier);
            format!("fourier obstacle, {n} harmonics")
        }
        5 => {
            let n = [0, 1, 2, 3, 1000][pick(rng, 5)];
            let rows: Vec<toml::Value> = (0..n)
                .map(|i| {
                    let t = f64::from(i) * 0.5;
                    let mut row = [t, 2.0 + 0.01 * t, 2.0, 1.0];
                    if chance(rng, 0.05) {
                        row[pick(rng, 4)] = float_edge(rng, Some(row[0]));
                    }
                    floats(&row)
                })
                .collect();
            let samples = table(&[
                ("kind", "samples".into()),
                ("samples", toml::Value::Array(rows)),
                ("end", ["hold", "loop", "bogus"][pick(rng, 3)].into()),
            ]);
            push_obstacle(doc, samples);
            format!("inline samples obstacle, {n} samples")
        }
        _ => {
            let kind = ["e1", "e3", "e4", "e2-static", "e2-dynamic"][pick(rng, 5)];
            let mut g = vec![("kind", toml::Value::from(kind))];
            let count_key = match kind {
                "e4" => ["pillar_count", "wall_count", "block_count", "moving_count"][pick(rng, 4)],
                _ => "obstacle_count",
            };
            let count = int_edge(rng, Some(10));
            if kind != "e2-static" && kind != "e2-dynamic" {
                g.push((count_key, toml::Value::Integer(count)));
            }
            if kind == "e4" {
                for k in ["pillar_count", "wall_count", "block_count", "moving_count"] {
                    if k != count_key {
                        g.push((k, toml::Value::Integer(2)));
                    }
                }
            }
            set_path(doc, &[key("world"), key("generator")], table(&g));
            if chance(rng, 0.7) {
                remove_path(doc, &[key("world"), key("bounds")]);
            }
            format!("generator {kind}, {count_key} {count}")
        }
    }
}

/// Appends a scripted box obstacle with `motion`.
fn push_obstacle(doc: &mut toml::Value, motion: toml::Value) {
    let obstacle = table(&[
        ("shape", "box".into()),
        ("half_extents", floats(&[0.3, 0.3, 0.3])),
        ("motion", motion),
    ]);
    if let toml::Value::Table(t) = doc {
        let list = t
            .entry("obstacles")
            .or_insert_with(|| toml::Value::Array(Vec::new()));
        if let toml::Value::Array(a) = list {
            a.push(obstacle);
        } else {
            *list = toml::Value::Array(vec![obstacle]);
        }
    }
}

/// One structure-aware edit of a scenario document; returns what it did.
fn edit_scenario(rng: &mut Rng, ctx: &Ctx, dir: &CaseDir, doc: &mut toml::Value) -> String {
    let all = all_nodes(doc);
    if all.is_empty() {
        return add_feature(rng, doc);
    }
    match pick(rng, 20) {
        0..=6 => {
            let numbers = nodes_where(doc, is_number);
            let Some(p) = numbers.get(pick(rng, numbers.len().max(1))) else {
                return add_feature(rng, doc);
            };
            let Some(v) = node_mut(doc, p) else {
                return String::new();
            };
            *v = match *v {
                toml::Value::Integer(i) if chance(rng, 0.75) => {
                    toml::Value::Integer(int_edge(rng, Some(i)))
                }
                toml::Value::Float(x) if chance(rng, 0.9) => {
                    toml::Value::Float(float_edge(rng, Some(x)))
                }
                toml::Value::Integer(i) => toml::Value::Float(float_edge(rng, Some(i as f64))),
                _ => toml::Value::Integer(int_edge(rng, None)),
            };
            format!("{} = {}", show(p), v)
        }
        7..=8 => {
            let p = &all[pick(rng, all.len())];
            let Some(v) = node_mut(doc, p) else {
                return String::new();
            };
            *v = other_type(rng, v);
            format!("{} retyped", show(p))
        }
        9..=10 => {
            let p = all[pick(rng, all.len())].clone();
            remove_path(doc, &p);
            format!("{} deleted", show(&p))
        }
        11 => {
            let tables = nodes_where(doc, |v| v.is_table());
            let mut p = tables
                .get(pick(rng, tables.len().max(1)))
                .cloned()
                .unwrap_or_default();
            p.push(Step::Key("fuzz_unknown_key".into()));
            set_path(doc, &p, toml::Value::Integer(1));
            format!("{} added", show(&p))
        }
        12..=14 => {
            // Cross-over: a node of another corpus file, at its own path.
            let other = &ctx.corpus.scenarios[pick(rng, ctx.corpus.scenarios.len())];
            let other_doc = toml::Value::Table(other.doc.clone());
            let theirs = all_nodes(&other_doc);
            let Some(p) = theirs.get(pick(rng, theirs.len().max(1))) else {
                return String::new();
            };
            let mut src = other_doc.clone();
            let value = node_mut(&mut src, p)
                .cloned()
                .unwrap_or(toml::Value::Integer(0));
            set_path(doc, p, value);
            format!("{} from {}", show(p), other.name)
        }
        15 => {
            let arrays = nodes_where(doc, |v| v.as_array().is_some_and(|a| !a.is_empty()));
            let Some(p) = arrays.get(pick(rng, arrays.len().max(1))) else {
                return add_feature(rng, doc);
            };
            let n = if chance(rng, 0.1) {
                [1_000, 9_999, 10_001][pick(rng, 3)]
            } else {
                [2, 3, 10][pick(rng, 3)]
            };
            let Some(toml::Value::Array(a)) = node_mut(doc, p) else {
                return String::new();
            };
            let items = a.clone();
            a.clear();
            for i in 0..n {
                a.push(items[i % items.len()].clone());
            }
            format!("{} replicated to {n}", show(p))
        }
        16..=17 => {
            let paths = nodes_where(doc, |v| v.is_str());
            let named: Vec<&Vec<Step>> = paths
                .iter()
                .filter(|p| matches!(p.last(), Some(Step::Key(k)) if k == "file" || k == "path"))
                .collect();
            let special = special_path(rng, &dir.case, "data/walker_1.csv", "csv");
            match named.get(pick(rng, named.len().max(1))) {
                Some(p) => {
                    let p = (*p).clone();
                    set_path(doc, &p, special.clone().into());
                    format!("{} = {special:?}", show(&p))
                }
                None => {
                    let motion =
                        table(&[("kind", "samples".into()), ("file", special.clone().into())]);
                    push_obstacle(doc, motion);
                    format!("track file {special:?}")
                }
            }
        }
        _ => add_feature(rng, doc),
    }
}

/// Serializes `doc`; a document TOML cannot write (a mutation's doing) falls back to a line.
fn to_text(doc: &toml::Value) -> Vec<u8> {
    match doc {
        toml::Value::Table(t) => toml::to_string(t).unwrap_or_else(|e| format!("# {e}\n")),
        _ => String::new(),
    }
    .into_bytes()
}

/// Writes the corpus tracks and points file into the case folder (a case may name them).
fn write_fixtures(ctx: &Ctx, dir: &CaseDir) -> std::io::Result<()> {
    for (name, text) in &ctx.corpus.tracks {
        dir.write(&format!("data/{name}"), text)?;
    }
    dir.write("cloud.xyz", &ctx.corpus.points)?;
    Ok(())
}

fn io_failed(e: &std::io::Error) -> Verdict {
    let mut v = Verdict::default();
    v.flag(
        Flag::Wrong,
        format!("the harness could not write the case: {e}"),
    );
    v
}

/// `files::scenario`: one to three structure-aware edits of a corpus scenario, sometimes a
/// byte-level edit of its text.
pub fn scenario_case(ctx: &Ctx, rng: &mut Rng, dir: &CaseDir) -> Verdict {
    if let Err(e) = write_fixtures(ctx, dir) {
        return io_failed(&e);
    }
    let base = ctx.pick_scenario(rng);
    let mut v = Verdict::default();
    let _ = write!(v.note, "{}:", base.name);
    let mut doc = toml::Value::Table(base.doc.clone());
    // Mostly one edit, so that most files still parse and the deeper checks see them.
    let edits = [1, 1, 1, 2, 3][pick(rng, 5)];
    for _ in 0..edits {
        let what = edit_scenario(rng, ctx, dir, &mut doc);
        let _ = write!(v.note, " {what};");
    }
    let mut text = to_text(&doc);
    if chance(rng, 0.1) {
        let what = raw_edit(rng, &mut text);
        let _ = write!(v.note, " text: {what}");
    }
    if let Err(e) = dir.write(SCENARIO, &text) {
        return io_failed(&e);
    }
    judge(ctx, dir, &String::from_utf8_lossy(&text), &mut v);
    v
}

// ---------------------------------------------------------------- CSV tracks and points files

/// A number as a file may write it: plain (`1e308` as 309 digits), scientific, or a word.
fn number_as_text(rng: &mut Rng, x: f64) -> String {
    match pick(rng, 8) {
        0 => format!("{x:e}"),
        1 => ["nan", "NaN", "inf", "-inf", "infinity", "+1", ".5", "1_0"][pick(rng, 8)].into(),
        _ => format!("{x}"),
    }
}

/// One structure-aware edit of a table of numbers (a CSV track with `columns` = `t,x,y,z`, or a
/// points file with `x y z`); returns what it did. Rows are the lines that parse as numbers.
fn edit_rows(rng: &mut Rng, text: &mut Vec<u8>, header: &str, timed: bool) -> String {
    let s = String::from_utf8_lossy(text).into_owned();
    let mut lines: Vec<String> = s.lines().map(str::to_string).collect();
    let rows: Vec<usize> = lines
        .iter()
        .enumerate()
        .filter(|(_, l)| {
            l.split([',', ' ', '\t'])
                .filter(|f| !f.is_empty())
                .all(|f| f.parse::<f64>().is_ok())
                && !l.trim().is_empty()
        })
        .map(|(i, _)| i)
        .collect();
    let sep = if timed { "," } else { " " };
    let what = match (pick(rng, 14), rows.is_empty()) {
        (0..=4, false) => {
            let i = rows[pick(rng, rows.len())];
            let mut fields: Vec<String> = lines[i]
                .split([',', ' ', '\t'])
                .filter(|f| !f.is_empty())
                .map(str::to_string)
                .collect();
            if fields.is_empty() {
                return String::new();
            }
            let k = pick(rng, fields.len());
            let x = float_edge(rng, fields[k].parse().ok());
            fields[k] = number_as_text(rng, x);
            lines[i] = fields.join(sep);
            format!("line {} field {} = {}", i + 1, k + 1, fields[k])
        }
        (5, false) => {
            let i = rows[pick(rng, rows.len())];
            let line = lines[i].clone();
            lines.insert(i, line);
            format!("line {} duplicated", i + 1)
        }
        (6, false) => {
            let i = rows[pick(rng, rows.len())];
            lines.remove(i);
            format!("line {} deleted", i + 1)
        }
        (7, false) if rows.len() > 1 => {
            let (a, b) = (rows[pick(rng, rows.len())], rows[pick(rng, rows.len())]);
            lines.swap(a, b);
            format!("lines {} and {} swapped", a + 1, b + 1)
        }
        (8, _) => {
            let keep = [0, 1, 2][pick(rng, 3)];
            let mut kept = 0;
            lines.retain(|l| {
                let data = l
                    .chars()
                    .next()
                    .is_some_and(|c| c.is_ascii_digit() || c == '-');
                if data {
                    kept += 1;
                }
                !data || kept <= keep
            });
            format!("{keep} rows kept")
        }
        (9, _) if chance(rng, 0.05) => {
            // Rows at the count cap: MAX_SAMPLES (tracks), with increasing times (rare: such a
            // file takes a second to write, read and check).
            let cap = trust_world::script::MAX_SAMPLES;
            let n = if timed {
                cap - 1 + pick(rng, 3)
            } else {
                [10_000, 100_000][pick(rng, 2)]
            };
            lines = vec![header.to_string()];
            lines.extend((0..n).map(|i| {
                let t = i as f64 * 0.01;
                if timed {
                    format!("{t},{},{},1", 1.0 + 1e-4 * t, 2.0)
                } else {
                    format!("{} {} {}", 15.0 + 1e-5 * t, 4.0, t % 10.0)
                }
            }));
            format!("{n} rows")
        }
        (10, _) => {
            let variants = [
                String::new(),
                header.to_uppercase(),
                format!("{header}{sep}w"),
                header.replace(',', ";"),
                "# only a comment".into(),
            ];
            let h = variants[pick(rng, variants.len())].clone();
            if chance(rng, 0.5) {
                lines.retain(|l| !l.eq_ignore_ascii_case(header));
            }
            let at = pick(rng, lines.len() + 1);
            lines.insert(at, h.clone());
            format!("header {h:?} at line {}", at + 1)
        }
        (11, _) => {
            let sep2 = ["\t", ";", "  ", ", ", ",,"][pick(rng, 5)];
            for l in &mut lines {
                *l = l.replace([',', ' '], sep2);
            }
            format!("separator {sep2:?}")
        }
        (12, false) if timed => {
            // A looped track closing within or just beyond LOOP_CLOSURE_M.
            let first = lines[rows[0]].clone();
            let last = *rows.last().unwrap_or(&0);
            let mut f: Vec<f64> = first
                .split(',')
                .filter_map(|x| x.trim().parse().ok())
                .collect();
            let t_last: f64 = lines[last]
                .split(',')
                .next()
                .and_then(|x| x.trim().parse().ok())
                .unwrap_or(0.0);
            if f.len() == 4 {
                let gap = [0.0, 0.9e-6, 1e-6, 1.1e-6, 1e-3][pick(rng, 5)];
                f[0] = t_last + 0.1;
                f[1] += gap;
                lines.push(format!("{},{},{},{}", f[0], f[1], f[2], f[3]));
                format!("closing sample off by {gap:e}")
            } else {
                String::new()
            }
        }
        _ => {
            let line = ["", "#", "1,2", "   ", "t,x,y,z", "1 2 3 4 5 6", "é,é,é,é"][pick(rng, 7)];
            let at = pick(rng, lines.len() + 1);
            lines.insert(at, line.into());
            format!("{line:?} at line {}", at + 1)
        }
    };
    let mut out = lines.join("\n").into_bytes();
    out.push(b'\n');
    *text = out;
    what
}

/// The document of a track case: the pedestrians (three CSV walkers), or a box on a track.
fn track_doc(ctx: &Ctx, rng: &mut Rng) -> Option<(toml::Value, Vec<Vec<Step>>)> {
    let find = |suffix: &str| {
        ctx.corpus
            .scenarios
            .iter()
            .find(|b| b.name.ends_with(suffix))
            .map(|b| toml::Value::Table(b.doc.clone()))
    };
    let mut doc = if chance(rng, 0.7) {
        find("scenarios/pedestrians.toml")?
    } else {
        let mut d = find("scenarios/boxes_on_curves.toml")?;
        let walker = ctx.corpus.tracks.last()?.0.clone();
        let motion = table(&[
            ("kind", "samples".into()),
            ("file", format!("data/{walker}").into()),
            ("end", "loop".into()),
        ]);
        set_path(
            &mut d,
            &[
                Step::Key("obstacles".into()),
                Step::Index(0),
                Step::Key("motion".into()),
            ],
            motion,
        );
        d
    };
    let files: Vec<Vec<Step>> = nodes_where(&doc, |v| v.is_str())
        .into_iter()
        .filter(|p| matches!(p.last(), Some(Step::Key(k)) if k == "file"))
        .collect();
    if chance(rng, 0.05) {
        // Both inline samples and a file.
        if let Some(p) = files.first() {
            let mut q = p.clone();
            q.pop();
            q.push(Step::Key("samples".into()));
            set_path(
                &mut doc,
                &q,
                toml::Value::Array(vec![floats(&[0.0, 1.0, 1.0, 1.0])]),
            );
        }
    }
    Some((doc, files))
}

/// `files::track`: the CSV tracks a scenario names, edited row by row (values at the edges,
/// rows duplicated, deleted or swapped so that times go back, too few or `MAX_SAMPLES ± 1`
/// rows, headers moved or changed, separators, a looped track's closure at its tolerance,
/// text at its cap) and sometimes byte by byte; the `file` names sometimes special paths.
pub fn track_case(ctx: &Ctx, rng: &mut Rng, dir: &CaseDir) -> Verdict {
    if let Err(e) = write_fixtures(ctx, dir) {
        return io_failed(&e);
    }
    let Some((mut doc, files)) = track_doc(ctx, rng) else {
        let mut v = Verdict::default();
        v.flag(
            Flag::Wrong,
            "no pedestrians or boxes_on_curves in the corpus".into(),
        );
        return v;
    };
    let mut v = Verdict::default();
    let mut input = String::new();
    for (name, base) in &ctx.corpus.tracks {
        let mut text = base.clone();
        if chance(rng, 0.6) {
            for _ in 0..1 + pick(rng, 3) {
                let what = edit_rows(rng, &mut text, "t,x,y,z", true);
                let _ = write!(v.note, " {name}: {what};");
            }
            if chance(rng, 0.25) {
                let what = raw_edit(rng, &mut text);
                let _ = write!(v.note, " {name} text: {what};");
            }
        }
        if chance(rng, 0.003) {
            // At the byte cap of a track: comment lines up to MAX_TRACK_BYTES ± 1.
            let cap = trust_world::scenario::files::MAX_TRACK_BYTES as usize;
            let target = cap - 1 + pick(rng, 3);
            while text.len() + 80 < target {
                text.extend_from_slice(&[b'#'; 79]);
                text.push(b'\n');
            }
            text.resize(target, b'#');
            let _ = write!(v.note, " {name}: {target} bytes;");
        }
        if let Err(e) = dir.write(&format!("data/{name}"), &text) {
            return io_failed(&e);
        }
        input.push_str(&String::from_utf8_lossy(&text));
    }
    for p in &files {
        if chance(rng, 0.1) {
            let special = special_path(rng, &dir.case, "data/walker_1.csv", "csv");
            set_path(&mut doc, p, special.clone().into());
            let _ = write!(v.note, " {} = {special:?};", show(p));
        }
        if chance(rng, 0.1) {
            let mut q = p.clone();
            q.pop();
            q.push(Step::Key("end".into()));
            let end = ["hold", "loop", "Loop", ""][pick(rng, 4)];
            set_path(&mut doc, &q, end.into());
            let _ = write!(v.note, " {} = {end:?};", show(&q));
        }
    }
    let text = to_text(&doc);
    if let Err(e) = dir.write(SCENARIO, &text) {
        return io_failed(&e);
    }
    input.push_str(&String::from_utf8_lossy(&text));
    judge(ctx, dir, &input, &mut v);
    v
}

/// `files::points`: quickstart with its planner map read from a points file, the file edited
/// row by row (values at the edges, headers, separators, too few or many rows) and byte by
/// byte, its `path` sometimes a special path, its voxel size sometimes at an edge.
pub fn points_case(ctx: &Ctx, rng: &mut Rng, dir: &CaseDir) -> Verdict {
    if let Err(e) = write_fixtures(ctx, dir) {
        return io_failed(&e);
    }
    let Some(doc) = super::corpus::cloud_scenario(&ctx.corpus.scenarios) else {
        let mut v = Verdict::default();
        v.flag(Flag::Wrong, "no quickstart in the corpus".into());
        return v;
    };
    let mut doc = toml::Value::Table(doc);
    let mut v = Verdict::default();
    let mut text = ctx.corpus.points.clone();
    for _ in 0..1 + pick(rng, 3) {
        let what = edit_rows(rng, &mut text, "x y z", false);
        let _ = write!(v.note, " cloud.xyz: {what};");
    }
    if chance(rng, 0.25) {
        let what = raw_edit(rng, &mut text);
        let _ = write!(v.note, " cloud.xyz text: {what};");
    }
    let cloud = [Step::Key("static".into()), Step::Key("point_cloud".into())];
    if chance(rng, 0.15) {
        let special = special_path(rng, &dir.case, "cloud.xyz", "xyz");
        let mut p = cloud.to_vec();
        p.push(Step::Key("path".into()));
        set_path(&mut doc, &p, special.clone().into());
        let _ = write!(v.note, " path = {special:?};");
    }
    if chance(rng, 0.15) {
        let voxel = float_edge(rng, Some(0.5));
        let mut p = cloud.to_vec();
        p.push(Step::Key("esdf_voxel_m".into()));
        set_path(&mut doc, &p, toml::Value::Float(voxel));
        let _ = write!(v.note, " esdf_voxel_m = {voxel:e};");
    }
    if let Err(e) = dir.write("cloud.xyz", &text) {
        return io_failed(&e);
    }
    let scenario = to_text(&doc);
    if let Err(e) = dir.write(SCENARIO, &scenario) {
        return io_failed(&e);
    }
    let input = format!(
        "{}{}",
        String::from_utf8_lossy(&text),
        String::from_utf8_lossy(&scenario)
    );
    judge(ctx, dir, &input, &mut v);
    v
}

/// One structure-aware edit of a points file's text (`x y z` rows); returns what it did.
pub fn edit_points(rng: &mut Rng, text: &mut Vec<u8>) -> String {
    edit_rows(rng, text, "x y z", false)
}

//! The run-log groups: mutated logs (`files::log`) through every reader of `trust-sim` — `audit`
//! ([`trust_runlog::audit::audit_file`], with and without `--cycles`), `replay`
//! ([`trust_replay::write_replay`], page and a small GIF), `export`
//! ([`trust_export::export_file`]) and [`trust_runlog::RunLog::read`] — and tampered logs
//! (`files::tamper`), whose every tamper the audit must flag as `docs/run-log.md` says.
//!
//! Oracles of `files::log`, beyond the harness's (no panic, abort or hang) and readable messages:
//! the readers agree on what they all read — a log [`RunLog::read`] accepts is read by the audit
//! (whose only other refusal is the points file), the replay (idem) and the export; a log it
//! refuses is refused by the replay and the export too; a log the audit's light reader refuses
//! is refused by the full reader.
//!
//! The tampers of `files::tamper` and what each must be flagged as (one tamper per case, on a
//! log the audit passes):
//!
//! | tamper | flagged as |
//! |---|---|
//! | one state's position moved by 5 cm–20 m, or to the policy's edge ±10⁶ m | finding `state.teleport` (§5.2) |
//! | one state's velocity changed by 0.2–100 m/s | finding `state.velocity_step` (§5.2) |
//! | a coordinate, velocity or acceleration component beyond the policy (1.5·10⁶ m … `f64::MAX`) | finding `state.p`, `state.v`, `state.a` or `state.obstacles` (§5.1) |
//! | a number no `f64` holds (`1e400`, `NaN`, `Infinity`), or a time beyond the policy | the reader's error (§5: numbers finite; times increase by ≤ 0.02 s) |
//! | a state's time at or before the previous one, or more than 0.02 s after it | the reader's error |
//! | the header, a state or the outcome line duplicated | the reader's error |
//! | the header, an interior state or the outcome line dropped | the reader's error |
//! | the first state dropped | finding `flight_time_s` (§5.3) |
//! | the last state dropped | finding `t` (§5.3) |
//! | the file truncated at a byte before its last non-blank one | the reader's error |
//! | a cycle line duplicated or dropped | nothing required: the contract counts no cycles (the outcome's `cycle_count` is not audited) |

use std::fmt::Write as _;
use std::path::Path;

use rand::Rng as _;
use serde_json::Value;
use trust_export::{ExportError, export_file};
use trust_replay::{GifParams, ReplayError, ReplayParams, page_html, write_replay};
use trust_runlog::audit::{AuditOptions, audit_file};
use trust_runlog::{LogError, RunLog};

use super::corpus::{BaseLog, CaseDir};
use super::mutate::{Rng, chance, float_edge, int_edge, number_text, pick, raw_edit, special_path};
use super::{Ctx, Flag, Verdict};

/// The log file of every case, in the case folder.
const LOG: &str = "run.jsonl";
/// The points file the corpus logs name.
const POINTS: &str = "static_points.xyz";
/// Placeholder for a number text JSON cannot hold, replaced after serialization.
const RAW: &str = "@@raw-number@@";

/// A JSON line as the writer writes it: `type` first (so that the reader's fast path sees
/// it), the other keys after; `tagged_order` writes them all in map order instead (the reader's
/// tagged path).
fn line_of(v: &Value, raw: &str, tagged_order: bool) -> String {
    let text = match v {
        Value::Object(m) if !tagged_order && m.contains_key("type") => {
            let mut rest = m.clone();
            let t = rest.remove("type").unwrap_or(Value::Null);
            let body = serde_json::to_string(&rest).unwrap_or_default();
            let t = serde_json::to_string(&t).unwrap_or_default();
            if body == "{}" {
                format!("{{\"type\":{t}}}")
            } else {
                format!("{{\"type\":{t},{}", &body[1..])
            }
        }
        _ => serde_json::to_string(v).unwrap_or_default(),
    };
    text.replace(&format!("\"{RAW}\""), raw)
}

/// A path into a JSON value.
#[derive(Debug, Clone)]
enum Step {
    Key(String),
    Index(usize),
}

fn collect(v: &Value, path: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    let mut visit = |step: Step, x: &Value, path: &mut Vec<Step>| {
        path.push(step);
        out.push(path.clone());
        collect(x, path, out);
        path.pop();
    };
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                visit(Step::Key(k.clone()), x, path);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                visit(Step::Index(i), x, path);
            }
        }
        _ => {}
    }
}

fn node_mut<'a>(v: &'a mut Value, path: &[Step]) -> Option<&'a mut Value> {
    let Some((first, rest)) = path.split_first() else {
        return Some(v);
    };
    let next = match (v, first) {
        (Value::Object(m), Step::Key(k)) => m.get_mut(k)?,
        (Value::Array(a), Step::Index(i)) => a.get_mut(*i)?,
        _ => return None,
    };
    node_mut(next, rest)
}

fn show(path: &[Step]) -> String {
    let mut s = String::new();
    for step in path {
        match step {
            Step::Key(k) => {
                let _ = write!(s, ".{k}");
            }
            Step::Index(i) => {
                let _ = write!(s, "[{i}]");
            }
        }
    }
    s
}

/// A JSON number at an edge; `raw` receives a text JSON cannot hold when the edge is one.
fn edge_json(rng: &mut Rng, current: &Value, raw: &mut String) -> Value {
    if chance(rng, 0.1) {
        *raw = number_text(rng);
        return Value::String(RAW.into());
    }
    if current.is_i64() || current.is_u64() {
        if chance(rng, 0.2) {
            return Value::from(u64::MAX);
        }
        return Value::from(int_edge(rng, current.as_i64()));
    }
    let x = float_edge(rng, current.as_f64());
    match serde_json::Number::from_f64(x) {
        Some(n) => Value::Number(n),
        None => {
            *raw = format!("{x}");
            Value::String(RAW.into())
        }
    }
}

/// One structure-aware edit of a log; returns what it did.
fn edit_log(
    rng: &mut Rng,
    dir: &CaseDir,
    lines: &mut Vec<String>,
    points: &mut Option<Vec<u8>>,
) -> String {
    if lines.is_empty() {
        lines.push(String::new());
    }
    match pick(rng, 20) {
        0..=9 => {
            // A JSON edit of one line (the header a third of the time).
            let i = if chance(rng, 0.33) {
                0
            } else {
                pick(rng, lines.len())
            };
            let Ok(mut v) = serde_json::from_str::<Value>(&lines[i]) else {
                return format!("line {} is not JSON", i + 1);
            };
            let mut raw = String::new();
            let what = edit_value(rng, dir, &mut v, &mut raw);
            lines[i] = line_of(&v, &raw, chance(rng, 0.1));
            format!("line {}: {what}", i + 1)
        }
        10..=11 => {
            let i = pick(rng, lines.len());
            let line = lines[i].clone();
            let at = pick(rng, lines.len() + 1);
            lines.insert(at, line);
            format!("line {} duplicated at {}", i + 1, at + 1)
        }
        12..=13 => {
            let i = pick(rng, lines.len());
            lines.remove(i);
            format!("line {} dropped", i + 1)
        }
        14 => {
            let (a, b) = (pick(rng, lines.len()), pick(rng, lines.len()));
            lines.swap(a, b);
            format!("lines {} and {} swapped", a + 1, b + 1)
        }
        15 => {
            let at = pick(rng, lines.len() + 1);
            let junk = [
                "",
                "   ",
                "{}",
                "null",
                "[]",
                "{\"type\":\"state\"}",
                "\u{feff}",
            ][pick(rng, 7)];
            lines.insert(at, junk.into());
            format!("{junk:?} at line {}", at + 1)
        }
        16 => {
            // Consistent obstacle counts, huge: the header's list and every state's.
            let n = [0, 1, 50, 1_000][pick(rng, 4)];
            set_obstacle_count(lines, n);
            format!("{n} obstacles everywhere")
        }
        17 => {
            if let Some(p) = points.as_mut() {
                let what = super::scenario::edit_points(rng, p);
                format!("{POINTS}: {what}")
            } else {
                *points = Some(b"0 0 0\n".to_vec());
                format!("{POINTS} added")
            }
        }
        _ => {
            // The header's points file.
            let Ok(mut h) = serde_json::from_str::<Value>(&lines[0]) else {
                return "header is not JSON".into();
            };
            let name = if chance(rng, 0.2) {
                Value::String(POINTS.into())
            } else if chance(rng, 0.1) {
                Value::Null
            } else {
                Value::String(special_path(rng, &dir.case, POINTS, "xyz"))
            };
            if let Value::Object(m) = &mut h {
                m.insert("static_points_file".into(), name.clone());
            }
            lines[0] = line_of(&h, "", false);
            format!("static_points_file = {name}")
        }
    }
}

/// Gives the header `n` moving obstacles (copies of its first, or a sphere) and every state `n`
/// centres.
fn set_obstacle_count(lines: &mut [String], n: usize) {
    for (i, line) in lines.iter_mut().enumerate() {
        let Ok(mut v) = serde_json::from_str::<Value>(line) else {
            continue;
        };
        let Some(list) = v.get_mut("obstacles").and_then(Value::as_array_mut) else {
            continue;
        };
        let proto = list.first().cloned().unwrap_or_else(|| {
            if i == 0 {
                serde_json::json!({"id": 0, "shape": "sphere", "radius": 0.5})
            } else {
                serde_json::json!([20.0, 10.0, 3.0])
            }
        });
        list.clear();
        for k in 0..n {
            let mut o = proto.clone();
            if let Some(id) = o.get_mut("id") {
                *id = Value::from(k);
            }
            list.push(o);
        }
        *line = line_of(&v, "", false);
    }
}

/// One edit inside a JSON value: a number to an edge, a node retyped or deleted, an unknown
/// key, an array replicated, a box without its extents.
fn edit_value(rng: &mut Rng, dir: &CaseDir, v: &mut Value, raw: &mut String) -> String {
    let mut all = Vec::new();
    collect(v, &mut Vec::new(), &mut all);
    if all.is_empty() {
        *v = Value::Null;
        return "replaced by null".into();
    }
    let p = all[pick(rng, all.len())].clone();
    match pick(rng, 10) {
        6 => {
            let (last, parent) = p
                .split_last()
                .map_or((None, &[][..]), |(l, r)| (Some(l), r));
            match (node_mut(v, parent), last) {
                (Some(Value::Object(m)), Some(Step::Key(k))) => {
                    m.remove(k);
                }
                (Some(Value::Array(a)), Some(Step::Index(i))) if *i < a.len() => {
                    a.remove(*i);
                }
                _ => {}
            }
            format!("{} deleted", show(&p))
        }
        7 => {
            if let Value::Object(m) = v {
                m.insert("fuzz_unknown".into(), Value::from(1));
            }
            "unknown key".into()
        }
        9 => {
            if let Some(obstacles) = v.get_mut("obstacles").and_then(Value::as_array_mut)
                && let Some(Value::Object(o)) = obstacles.first_mut()
                && o.contains_key("shape")
            {
                o.insert("shape".into(), "box".into());
                if chance(rng, 0.5) {
                    o.remove("half_extents");
                } else {
                    let x = float_edge(rng, Some(0.3));
                    o.insert(
                        "half_extents".into(),
                        serde_json::json!([serde_json::Number::from_f64(x), 0.3, 0.3]),
                    );
                }
                return "obstacle 0 a box".into();
            }
            let special = special_path(rng, &dir.case, POINTS, "xyz");
            if let Some(node) = node_mut(v, &p) {
                *node = Value::String(special.clone());
            }
            format!("{} = {special:?}", show(&p))
        }
        choice => {
            let Some(node) = node_mut(v, &p) else {
                return String::new();
            };
            match choice {
                5 => {
                    *node = match pick(rng, 6) {
                        0 => Value::Null,
                        1 => Value::Bool(true),
                        2 => Value::String(["", "1e308", "box", "NaN"][pick(rng, 4)].into()),
                        3 => Value::Array(Vec::new()),
                        4 => Value::Object(serde_json::Map::new()),
                        _ => Value::from(-1),
                    };
                    format!("{} = {node}", show(&p))
                }
                8 => {
                    if let Value::Array(a) = node
                        && !a.is_empty()
                    {
                        let n = [2, 5, 1_000][pick(rng, 3)];
                        let items = a.clone();
                        a.clear();
                        for i in 0..n {
                            a.push(items[i % items.len()].clone());
                        }
                        return format!("{} replicated to {n}", show(&p));
                    }
                    *node = Value::from(rng.random::<u32>());
                    format!("{} = {node}", show(&p))
                }
                _ => {
                    // A number: one at or below the node.
                    let mut numbers = Vec::new();
                    collect_numbers(node, &mut Vec::new(), &mut numbers);
                    if let Some(q) = numbers.get(pick(rng, numbers.len().max(1)))
                        && let Some(x) = node_mut(node, q)
                    {
                        *x = edge_json(rng, x, raw);
                        return format!("{}{} = {x}{raw}", show(&p), show(q));
                    }
                    *node = edge_json(rng, node, raw);
                    format!("{} = {node}{raw}", show(&p))
                }
            }
        }
    }
}

fn collect_numbers(v: &Value, path: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    match v {
        Value::Number(_) => out.push(path.clone()),
        Value::Object(m) => {
            for (k, x) in m {
                path.push(Step::Key(k.clone()));
                collect_numbers(x, path, out);
                path.pop();
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                path.push(Step::Index(i));
                collect_numbers(x, path, out);
                path.pop();
            }
        }
        _ => {}
    }
}

/// Writes the case's log (and its points file, if any) into the case folder.
fn write_log(dir: &CaseDir, text: &[u8], points: Option<&[u8]>) -> std::io::Result<()> {
    dir.write(LOG, text)?;
    let p = dir.case.join(POINTS);
    match points {
        Some(b) => {
            dir.write(POINTS, b)?;
        }
        None if p.exists() => std::fs::remove_file(p)?,
        None => {}
    }
    Ok(())
}

/// A small replay: the page as `trust-sim replay` makes it, a GIF of two 200-px frames.
fn replay_params() -> ReplayParams {
    ReplayParams {
        gif: GifParams {
            width_px: 200,
            max_frames: 2,
            ..GifParams::default()
        },
        ..ReplayParams::default()
    }
}

/// Every reader of the case's log, judged (module docs). The replay runs as `trust-sim replay`
/// does ([`write_replay`], streaming, page and GIF) in a tenth of the cases, its page alone
/// ([`trust_replay::page_html`] on the log [`RunLog::read`] read) in the others; the export in
/// half of them (the GIF and the MCAP file cost 20–100 times what the reading does).
fn read_everywhere(rng: &mut Rng, dir: &CaseDir, input: &str, v: &mut Verdict) {
    let path = dir.case.join(LOG);
    let audit = audit_file(
        &path,
        AuditOptions {
            cycles: chance(rng, 0.5),
        },
    );
    let full = RunLog::read(&path);
    let replay = if chance(rng, 0.1) {
        Some(write_replay(&path, &dir.out, &replay_params()).map(|_| ()))
    } else {
        None
    };
    let page = match (&replay, &full) {
        (None, Ok(log)) => Some(page_html(log, &dir.case, &replay_params()).map(|_| ())),
        _ => None,
    };
    let export = chance(rng, 0.5).then(|| export_file(&path, &dir.out.join("run.mcap")));
    match &audit {
        Ok(a) => {
            v.accepted = a.passed();
            for f in &a.findings {
                v.readable(&f.to_string(), input);
            }
        }
        Err(e) => v.readable(&e.to_string(), input),
    }
    if let Err(e) = &full {
        v.readable(&e.to_string(), input);
    }
    if let Some(Err(e)) = replay.as_ref().or(page.as_ref()) {
        v.readable(&e.to_string(), input);
    }
    if let Some(Err(e)) = &export {
        v.readable(&e.to_string(), input);
    }
    let audit_points = matches!(audit, Err(LogError::Points { .. }));
    match &full {
        Ok(_) => {
            if let Err(e) = &audit
                && !audit_points
            {
                v.flag(Flag::Disagree, format!("read whole, the audit says: {e}"));
            }
            if let Some(Err(e @ ReplayError::Log(_))) = replay.as_ref().or(page.as_ref()) {
                v.flag(Flag::Disagree, format!("read whole, the replay says: {e}"));
            }
            if let Some(Err(e @ ExportError::Log(_))) = &export {
                v.flag(Flag::Disagree, format!("read whole, the export says: {e}"));
            }
            // The audit reads no points for a header outside its policy (it reports the header).
            let header_refused = audit
                .as_ref()
                .is_ok_and(|a| a.findings.iter().any(|f| f.field == "header"));
            if let Some(r) = replay.as_ref().or(page.as_ref())
                && !header_refused
            {
                let replay_points = matches!(r, Err(ReplayError::Points { .. }));
                if replay_points != audit_points {
                    v.flag(
                        Flag::Disagree,
                        format!(
                            "points file: the audit {}, the replay {}",
                            if audit_points {
                                "refuses it"
                            } else {
                                "reads it"
                            },
                            if replay_points {
                                "refuses it"
                            } else {
                                "reads it"
                            }
                        ),
                    );
                }
            }
        }
        Err(e) => {
            if let Some(Ok(())) = &replay {
                v.flag(
                    Flag::Disagree,
                    format!("the replay reads a log that says: {e}"),
                );
            }
            if let Some(Ok(_)) = &export {
                v.flag(
                    Flag::Disagree,
                    format!("the export reads a log that says: {e}"),
                );
            }
        }
    }
}

/// `files::log`: one to three edits of a corpus log (JSON edits of a line, lines duplicated,
/// dropped, swapped or inserted, consistent huge obstacle counts, its points file and the
/// header's name of it), sometimes a byte-level edit of the text; every reader judged.
pub fn log_case(ctx: &Ctx, rng: &mut Rng, dir: &CaseDir) -> Verdict {
    let base = &ctx.corpus.logs[pick(rng, ctx.corpus.logs.len())];
    let mut v = Verdict::default();
    let _ = write!(v.note, "{}:", base.name);
    let mut lines = base.lines.clone();
    let mut points = base.points.clone();
    for _ in 0..1 + pick(rng, 3) {
        let what = edit_log(rng, dir, &mut lines, &mut points);
        let _ = write!(v.note, " {what};");
    }
    let mut text = lines.join("\n").into_bytes();
    text.push(b'\n');
    if chance(rng, 0.3) {
        let what = raw_edit(rng, &mut text);
        let _ = write!(v.note, " text: {what}");
    }
    if let Err(e) = write_log(dir, &text, points.as_deref()) {
        v.flag(
            Flag::Wrong,
            format!("the harness could not write the case: {e}"),
        );
        return v;
    }
    let mut input = String::from_utf8_lossy(&text).into_owned();
    if let Some(p) = &points {
        input.push_str(&String::from_utf8_lossy(p));
    }
    read_everywhere(rng, dir, &input, &mut v);
    v
}

// ---------------------------------------------------------------- tampers

/// What the audit must say about a tampered log.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Expect {
    /// A finding of this field.
    Finding(&'static str),
    /// The reader's error (a `LogError` other than the points file's).
    Error,
    /// Nothing required.
    Nothing,
}

/// The lines of the state records.
fn state_lines(lines: &[String]) -> Vec<usize> {
    lines
        .iter()
        .enumerate()
        .filter(|(_, l)| l.starts_with(r#"{"type":"state","#))
        .map(|(i, _)| i)
        .collect()
}

fn state_t(line: &str) -> f64 {
    serde_json::from_str::<Value>(line)
        .ok()
        .and_then(|v| v.get("t").and_then(Value::as_f64))
        .unwrap_or(0.0)
}

/// Sets one component of a state's vector `key` (`p`, `v`, `a`, or `obstacles` `j`) with `f`.
fn set_component(line: &str, key: &str, j: usize, k: usize, f: impl Fn(f64) -> Value) -> String {
    let Ok(mut v) = serde_json::from_str::<Value>(line) else {
        return line.to_string();
    };
    let slot = match key {
        "obstacles" => v.get_mut("obstacles").and_then(|o| o.get_mut(j)),
        _ => v.get_mut(key),
    }
    .and_then(|x| x.get_mut(k));
    if let Some(x) = slot {
        *x = f(x.as_f64().unwrap_or(0.0));
    }
    line_of(&v, "", false)
}

fn num(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// Applies one tamper to `lines` (module docs); returns what it did and what it must be
/// flagged as.
fn tamper(rng: &mut Rng, lines: &mut Vec<String>) -> (String, Expect) {
    let states = state_lines(lines);
    let n = states.len();
    let i = pick(rng, n);
    let line = lines[states[i]].clone();
    let sign = if chance(rng, 0.5) { 1.0 } else { -1.0 };
    match pick(rng, 8) {
        0 => {
            let k = pick(rng, 3);
            let (what, new) = if chance(rng, 0.2) {
                let edge = sign * trust_runlog::audit::MAX_COORDINATE_M;
                (
                    "to the policy's edge",
                    set_component(&line, "p", 0, k, |_| num(edge)),
                )
            } else {
                let d = sign * 10f64.powf(rng.random_range(-1.3..1.3));
                ("by a step", set_component(&line, "p", 0, k, |x| num(x + d)))
            };
            lines[states[i]] = new;
            (
                format!("state {i} p[{k}] moved {what}"),
                Expect::Finding("state.teleport"),
            )
        }
        1 => {
            let k = pick(rng, 3);
            let d = sign * rng.random_range(0.2..100.0);
            lines[states[i]] = set_component(&line, "v", 0, k, |x| num(x + d));
            (
                format!("state {i} v[{k}] + {d:.3}"),
                Expect::Finding("state.velocity_step"),
            )
        }
        2 => {
            let obstacles = serde_json::from_str::<Value>(&line)
                .ok()
                .and_then(|v| v.get("obstacles").and_then(Value::as_array).map(Vec::len))
                .unwrap_or(0);
            let keys: &[&str] = if obstacles > 0 {
                &["p", "v", "a", "obstacles"]
            } else {
                &["p", "v", "a"]
            };
            let key = keys[pick(rng, keys.len())];
            let (k, j) = (pick(rng, 3), pick(rng, obstacles.max(1)));
            if chance(rng, 0.25) {
                let raw = ["1e400", "-1e400", "NaN", "Infinity"][pick(rng, 4)];
                let mut v: Value = serde_json::from_str(&line).unwrap_or(Value::Null);
                let slot = match key {
                    "obstacles" => v.get_mut("obstacles").and_then(|o| o.get_mut(j)),
                    _ => v.get_mut(key),
                }
                .and_then(|x| x.get_mut(k));
                if let Some(x) = slot {
                    *x = Value::String(RAW.into());
                }
                lines[states[i]] = line_of(&v, raw, false);
                return (format!("state {i} {key}[{k}] = {raw}"), Expect::Error);
            }
            let bound = match key {
                "v" => trust_runlog::audit::MAX_SPEED_M_S,
                "a" => trust_runlog::audit::MAX_ACCEL_M_S2,
                _ => trust_runlog::audit::MAX_COORDINATE_M,
            };
            let x = sign * [bound * 1.5, bound * 10.0, 1e300, f64::MAX][pick(rng, 4)];
            lines[states[i]] = set_component(&line, key, j, k, |_| num(x));
            let field = match key {
                "p" => "state.p",
                "v" => "state.v",
                "a" => "state.a",
                _ => "state.obstacles",
            };
            (
                format!("state {i} {key}[{k}] = {x:e}"),
                Expect::Finding(field),
            )
        }
        3 if n > 1 => {
            let i = 1 + pick(rng, n - 1);
            let prev = state_t(&lines[states[i - 1]]);
            let eps = [0.0, 1e-9, 1e-3, 0.02, 1e6][pick(rng, 5)];
            let t = prev - eps;
            lines[states[i]] = set_t(&lines[states[i]], t);
            (format!("state {i} t = previous − {eps:e}"), Expect::Error)
        }
        4 if n > 1 => {
            let i = 1 + pick(rng, n - 1);
            let prev = state_t(&lines[states[i - 1]]);
            let t = prev + [0.0201, 0.05, 1e300][pick(rng, 3)];
            lines[states[i]] = set_t(&lines[states[i]], t);
            (format!("state {i} t = {t:e}, after {prev}"), Expect::Error)
        }
        5 => {
            let cycles: Vec<usize> = (0..lines.len())
                .filter(|&j| lines[j].starts_with(r#"{"type":"cycle","#))
                .collect();
            let (j, expect) = match pick(rng, 4) {
                0 => (0, Expect::Error),
                1 => (lines.len() - 1, Expect::Error),
                2 if !cycles.is_empty() => (cycles[pick(rng, cycles.len())], Expect::Nothing),
                _ => (states[i], Expect::Error),
            };
            let copy = lines[j].clone();
            let at = if chance(rng, 0.5) {
                j + 1
            } else {
                1 + pick(rng, lines.len() - 1)
            };
            lines.insert(at, copy);
            (format!("line {} duplicated at {}", j + 1, at + 1), expect)
        }
        6 => {
            let cycles: Vec<usize> = (0..lines.len())
                .filter(|&j| lines[j].starts_with(r#"{"type":"cycle","#))
                .collect();
            let (j, expect) = match pick(rng, 5) {
                0 => (0, Expect::Error),
                1 => (lines.len() - 1, Expect::Error),
                2 => (states[0], Expect::Finding("flight_time_s")),
                3 => (states[n - 1], Expect::Finding("t")),
                _ if n > 2 => (states[1 + pick(rng, n - 2)], Expect::Error),
                _ if !cycles.is_empty() => (cycles[pick(rng, cycles.len())], Expect::Nothing),
                _ => (0, Expect::Error),
            };
            lines.remove(j);
            (format!("line {} dropped", j + 1), expect)
        }
        _ => {
            // Truncated before the last non-blank byte: marked by an empty line count.
            (String::from("truncated"), Expect::Error)
        }
    }
}

fn set_t(line: &str, t: f64) -> String {
    let Ok(mut v) = serde_json::from_str::<Value>(line) else {
        return line.to_string();
    };
    if let Some(x) = v.get_mut("t") {
        *x = num(t);
    }
    line_of(&v, "", false)
}

/// `files::tamper`: one tamper of a corpus log, which the audit must flag as the module docs'
/// table says.
pub fn tamper_case(ctx: &Ctx, rng: &mut Rng, dir: &CaseDir) -> Verdict {
    let base = &ctx.corpus.logs[pick(rng, ctx.corpus.logs.len())];
    let mut v = Verdict::default();
    let mut lines = base.lines.clone();
    let (what, expect) = tamper(rng, &mut lines);
    let mut text = lines.join("\n").into_bytes();
    text.push(b'\n');
    if what == "truncated" {
        let last = text
            .iter()
            .rposition(|b| !b.is_ascii_whitespace())
            .unwrap_or(0);
        let at = pick(rng, last.max(1));
        text.truncate(at);
        let _ = write!(
            v.note,
            "{}: truncated at byte {at} of {}",
            base.name,
            last + 1
        );
    } else {
        let _ = write!(v.note, "{}: {what}", base.name);
    }
    if let Err(e) = write_log(dir, &text, base.points.as_deref()) {
        v.flag(
            Flag::Wrong,
            format!("the harness could not write the case: {e}"),
        );
        return v;
    }
    let input = String::from_utf8_lossy(&text);
    let cycles = chance(rng, 0.5);
    let audit = audit_file(&dir.case.join(LOG), AuditOptions { cycles });
    match &audit {
        Ok(a) => {
            v.accepted = a.passed();
            for f in &a.findings {
                v.readable(&f.to_string(), &input);
            }
        }
        Err(e) => v.readable(&e.to_string(), &input),
    }
    let fields = |a: &trust_runlog::audit::Audit| -> String {
        a.findings
            .iter()
            .map(|f| f.field)
            .collect::<Vec<_>>()
            .join(", ")
    };
    match (expect, &audit) {
        (Expect::Finding(field), Ok(a)) if !a.findings.iter().any(|f| f.field == field) => v.flag(
            Flag::Wrong,
            format!(
                "{}: no `{field}` finding (findings: [{}])",
                v.note,
                fields(a)
            ),
        ),
        (Expect::Finding(field), Err(e)) => v.flag(
            Flag::Wrong,
            format!(
                "{}: expected a `{field}` finding, the reader refused: {e}",
                v.note
            ),
        ),
        (Expect::Error, Ok(a)) => v.flag(
            Flag::Wrong,
            format!("{}: read without error (findings: [{}])", v.note, fields(a)),
        ),
        (Expect::Error, Err(LogError::Points { message })) => v.flag(
            Flag::Wrong,
            format!("{}: refused for its points file: {message}", v.note),
        ),
        _ => {}
    }
    v
}

/// Checks that every corpus log passes the audit untouched (the tampers' premise).
///
/// # Errors
/// The first log that does not, with its findings.
pub fn check_bases(logs: &[BaseLog], dir: &Path) -> anyhow::Result<()> {
    for log in logs {
        let folder = dir.join(&log.name);
        let a = audit_file(&folder.join(LOG), AuditOptions { cycles: true })?;
        anyhow::ensure!(
            a.passed() && state_lines(&log.lines).len() >= 3,
            "the corpus log {} does not pass the audit untouched ({} states): {:?}",
            log.name,
            a.state_count,
            a.findings
        );
    }
    Ok(())
}

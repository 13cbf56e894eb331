//! Streaming a run log: [`LogReader`] yields one record at a time and checks the contract's
//! structure as it goes, so a one-hour log is read in the memory of one line.

use std::path::Path;

use crate::files::{BoundedLines, MAX_LOG_BYTES, cut_message, readable};
use crate::{Header, LogError, ObstacleKind, Record, SCHEMA};

/// Largest step between two state times the reader accepts (s): the contract's 0.02 s, plus a
/// nanosecond for the rounding of times written as decimals.
pub const MAX_STATE_STEP_S: f64 = 0.02 + 1e-9;

/// Reads a run log record by record (module docs), checking: the header first (right schema,
/// every box obstacle with positive `half_extents`), the outcome last, exactly one of each, state
/// times strictly increasing with steps ≤ [`MAX_STATE_STEP_S`], every state with one position per
/// header obstacle, at least one state. The file is read under [`crate::files`]' policy (a
/// regular file, at most [`MAX_LOG_BYTES`]).
#[derive(Debug)]
pub struct LogReader {
    lines: BoundedLines,
    header: Header,
    line: String,
    last_state_t: Option<f64>,
    state_count: usize,
    finished: bool,
    light_cycles: bool,
}

/// A cycle record's contract fields only (the rest skipped unparsed).
#[derive(serde::Deserialize)]
struct LightCycle {
    t: f64,
    wall_ms: f64,
    main: Option<u64>,
    branches: usize,
    events: Vec<String>,
}

/// Parses one line. Lines the writer wrote (`{"type":"state",…`, `{"type":"cycle",…`) go
/// straight to their record type, the type key ignored; any other order of keys goes through
/// the tagged [`Record`] (slower: serde buffers the object to find its tag).
fn parse_record(line: &str, light_cycles: bool) -> Result<Record, serde_json::Error> {
    let head = line.trim_start();
    if head.starts_with(r#"{"type":"state","#) {
        return serde_json::from_str(line).map(Record::State);
    }
    if head.starts_with(r#"{"type":"cycle","#) {
        if light_cycles {
            let c: LightCycle = serde_json::from_str(line)?;
            return Ok(Record::Cycle(crate::CycleRecord {
                t: c.t,
                wall_ms: c.wall_ms,
                main: c.main,
                branches: c.branches,
                events: c.events,
                frontend_ms: 0.0,
                backend_ms: 0.0,
                checker_ms: 0.0,
                solve_count: 0,
                effective_t: 0.0,
                branch_j: Vec::new(),
                fallback_collision_free: None,
                fallback_shortfall_m: None,
                fallback_along: None,
                dropped: crate::Dropped::default(),
                route: None,
                route_ms: None,
                branch_samples: None,
                forecasts: None,
                charged_ms: None,
                overrun_ticks: None,
                worker_ms: None,
                waited_ms: None,
                map_ms: None,
            }));
        }
        return serde_json::from_str(line).map(Record::Cycle);
    }
    serde_json::from_str(line)
}

impl LogReader {
    /// Opens `path` and reads its header.
    ///
    /// # Errors
    /// [`LogError`] naming the file and, for a bad line, its number.
    pub fn open(path: &Path) -> Result<LogReader, LogError> {
        let mut lines = BoundedLines::open(path, MAX_LOG_BYTES, "a run log")?;
        let header = loop {
            let Some((n, line)) = lines.next_line()?.map(|(n, l)| (n, l.to_string())) else {
                return Err(LogError::Structure {
                    path: path.to_path_buf(),
                    message: "no header (the file is empty)".into(),
                });
            };
            if line.trim().is_empty() {
                continue;
            }
            let parse = |message: String| LogError::Parse {
                path: path.to_path_buf(),
                line: n,
                message,
            };
            let record: Record =
                serde_json::from_str(&line).map_err(|e| parse(cut_message(&e.to_string())))?;
            let Record::Header(h) = record else {
                return Err(parse("the first line must be the header".into()));
            };
            if n > 1 {
                return Err(parse("the header must be the first line, once".into()));
            }
            if h.schema != SCHEMA {
                return Err(parse(format!(
                    "schema {}, expected `{SCHEMA}`",
                    crate::files::echo(&h.schema)
                )));
            }
            for o in &h.obstacles {
                let sized = o
                    .half_extents
                    .is_some_and(|e| e.iter().all(|x| x.is_finite() && *x > 0.0));
                if o.shape == ObstacleKind::Box && !sized {
                    return Err(parse(format!(
                        "obstacle {}: a box needs `half_extents` [hx, hy, hz] > 0, got {}",
                        o.id,
                        o.half_extents.map_or("none".into(), |e| format!(
                            "[{}, {}, {}]",
                            readable(e[0]),
                            readable(e[1]),
                            readable(e[2])
                        ))
                    )));
                }
            }
            break h;
        };
        Ok(LogReader {
            lines,
            header,
            line: String::new(),
            last_state_t: None,
            state_count: 0,
            finished: false,
            light_cycles: false,
        })
    }

    /// From now on, read only the contract's fields of cycle records (`t`, `wall_ms`, `main`,
    /// `branches`, `events`; the others are left at their defaults): for readers that need no
    /// more, such as the audit, this skips most of a log's bytes (branches and forecasts).
    pub fn light_cycles(mut self) -> Self {
        self.light_cycles = true;
        self
    }

    /// The header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// The file.
    pub fn path(&self) -> &Path {
        self.lines.path()
    }

    /// The text of the line of the record last returned.
    pub fn line(&self) -> &str {
        &self.line
    }

    /// The 1-based number of the line of the record last returned.
    pub fn line_number(&self) -> usize {
        self.lines.number()
    }

    /// State records read so far.
    pub fn state_count(&self) -> usize {
        self.state_count
    }

    /// The next record after the header (a state, a cycle, or the outcome, which is the last);
    /// `None` after the outcome, once the rest of the file is known to be blank.
    ///
    /// # Errors
    /// [`LogError`] naming the file and the line.
    pub fn next_record(&mut self) -> Result<Option<Record>, LogError> {
        loop {
            let Some((n, line)) = self.lines.next_line()? else {
                self.line.clear();
                if self.finished {
                    return Ok(None);
                }
                return Err(LogError::Structure {
                    path: self.lines.path().to_path_buf(),
                    message: "no outcome (the run did not finish)".into(),
                });
            };
            if line.trim().is_empty() {
                continue;
            }
            self.line.clear();
            self.line.push_str(line);
            let path = self.lines.path().to_path_buf();
            let parse = |message: String| LogError::Parse {
                path: path.clone(),
                line: n,
                message,
            };
            let record: Record = parse_record(&self.line, self.light_cycles)
                .map_err(|e| parse(cut_message(&e.to_string())))?;
            if self.finished {
                return Err(parse("a record after the outcome".into()));
            }
            match &record {
                Record::Header(_) => {
                    return Err(parse("the header must be the first line, once".into()));
                }
                Record::State(s) => {
                    let expected = self.header.obstacles.len();
                    if s.obstacles.len() != expected {
                        return Err(parse(format!(
                            "{} obstacle positions, the header lists {expected}",
                            s.obstacles.len()
                        )));
                    }
                    if let Some(prev) = self.last_state_t
                        && !(s.t > prev && s.t - prev <= MAX_STATE_STEP_S)
                    {
                        return Err(parse(format!(
                            "state time {} after {}: times must increase by at most 0.02 s",
                            readable(s.t),
                            readable(prev)
                        )));
                    }
                    self.last_state_t = Some(s.t);
                    self.state_count += 1;
                }
                Record::Cycle(_) => {}
                Record::Outcome(_) => {
                    if self.state_count == 0 {
                        return Err(LogError::Structure {
                            path,
                            message: "no state records".into(),
                        });
                    }
                    self.finished = true;
                }
            }
            return Ok(Some(record));
        }
    }
}

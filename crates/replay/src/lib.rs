//! # trust-replay — watch a flight: one self-contained HTML page and an animated GIF from a run log
//!
//! Use it to *see* what a flight of the simulator (paper Sec. IV) did, from its run log alone
//! (`trust-runlog`, `docs/run-log.md`): [`write_replay`] turns `RUN.jsonl` into
//!
//! - `RUN.replay.html` ([`page_html`]): one page with everything inline — the flight's data as
//!   embedded JSON, the script and the style sheet — and no network access (no CDN, no fonts, no
//!   images fetched). It plays the flight in a top (x–y) and a side (x–z) view on 2-D canvases:
//!   static shapes (and the thinned static point cloud when the log names one), the true moving
//!   obstacles with their shapes, the forecasts the planner held (centre and growing radius, when
//!   the log has them, and dashed the regions whose walls it mirrors them at), the flown path, the branches of the current cycle with the main one
//!   highlighted, and the latest global route when the log carries one. Under the views: a
//!   timeline with the cycles' events (switch, fallback, stalled, …), play/pause, a time slider,
//!   a speed control, and the speed and clearance traces with a cursor. The page reads `#t=SECONDS`
//!   from its address (paused at that time), and keeps a machine-readable status — script errors,
//!   the time shown, the vehicle's position on the canvas — in the element `#replay-status`, which
//!   the headless-browser check ([`browser`]) reads.
//! - `RUN.replay.gif` ([`write_top_view_gif`]): the top view as an animated GIF through
//!   `trust-plot` (plotters' GIF backend, pure Rust, the bundled font), small enough for a README.
//!
//! The branches and forecasts come from the cycles' optional `branch_samples` and `forecasts`
//! (added in issue 20; written by `trust-sim run` unless `--no-log-branches`); a log without them
//! replays without branches and forecasts. The clearance traces are recomputed from the states
//! with the audit's own distance formulas ([`trust_runlog::audit::TrueGeometry`], a k-d tree for
//! a static point cloud).
//!
//! # Long flights: bounded memory, decimated page
//!
//! [`write_replay`] streams the log twice ([`trust_runlog::LogReader`]): once for the page, once
//! for the GIF's frames (their times need the flight's end). Neither holds every state:
//!
//! - the page keeps a state every [`ReplayParams::state_step_s`] (0.1 s), and whenever more than
//!   [`ReplayParams::max_states`] (6 000) would be kept, every other one is dropped and the step
//!   doubled; each kept state carries the smallest clearance since the previous kept one, so the
//!   clearance trace keeps every minimum. Cycles are kept all, up to
//!   [`ReplayParams::max_cycles`] (3 000); beyond, every other one is dropped as often as
//!   needed, its events and route going to the next kept cycle (the timeline keeps every event,
//!   shifted by at most the kept spacing). A one-hour flight (180 000 states, 36 000 cycles)
//!   keeps a state every 0.8 s and a cycle every 1.6 s: a page of about 10 MB with 100
//!   obstacles.
//! - the GIF keeps, per frame, the latest state, cycle and route, and the flown path at one point
//!   per 0.1 s, the spacing doubling beyond 4 000 points.
//! - the static points are read once, thinned to [`ReplayParams::max_points`] for the page and
//!   the GIF; the clearances use all of them.
//!
//! [`page_html`] and [`write_top_view_gif`] do the same from a log already in memory.
//!
//! This crate sits beside the plots, on the far side of the simulator: it depends on
//! `trust-runlog` and `trust-plot` and nothing depends on it but the `trust-sim` binary and xtask.
//! Why one offline page, checked without WebDriver: `docs/decisions/0016`.
//!
//! ```no_run
//! use std::path::Path;
//! use trust_replay::{ReplayParams, write_replay};
//!
//! let log = Path::new("out/run/run.jsonl");
//! let files = write_replay(log, Path::new("out/run"), &ReplayParams::default())?;
//! println!("open {}", files.html.display());
//! # Ok::<(), trust_replay::ReplayError>(())
//! ```
#![warn(missing_docs)]

pub mod browser;
mod data;
mod error;
mod frames;
mod page;

use std::path::{Path, PathBuf};

use data::PageBuilder;
pub use error::ReplayError;
pub use frames::write_top_view_gif;
pub use page::page_html;
pub use trust_plot::GifWritten;

/// Settings of a replay (choices of ours, not the paper's: they keep the page of a 30 s E4 flight
/// with 100 obstacles at a few MB and its GIF under 1 MB).
#[derive(Debug, Clone, PartialEq)]
pub struct ReplayParams {
    /// Keep one state per this many seconds in the page (the log has 50 Hz; the page interpolates
    /// linearly between kept states); `≥ 0`, 0 keeps all. Default 0.1 s.
    pub state_step_s: f64,
    /// Decimals kept for every number in the page's data. Default 2 (cm; a pixel of the views
    /// is 5–10 cm).
    pub decimals: i32,
    /// The branches are drawn as polylines within this distance of the logged samples
    /// (Ramer–Douglas–Peucker, m); `≥ 0`. Default 0.03 m.
    pub branch_tolerance_m: f64,
    /// A cycle's forecast is in the page when its obstacle is within this distance (plus its
    /// radius) of the vehicle, or of a kept branch at the same time (m). Default 5 m; E4 has 100
    /// obstacles and the page would otherwise carry all their forecasts in every cycle.
    pub forecast_near_m: f64,
    /// At most this many static points in the page and the GIF (thinned in file order). Default
    /// 20 000.
    pub max_points: usize,
    /// At most this many states in the page: beyond, every other kept state is dropped and
    /// `state_step_s` doubled, as often as needed (a kept state's clearance is the smallest
    /// since the previous kept one, so the traces keep every minimum). Default 6 000 (10 min of
    /// flight at 0.1 s; an hour's flight is kept every 0.8 s).
    pub max_states: usize,
    /// At most this many cycles in the page: beyond, every other kept cycle is dropped, as often
    /// as needed, its events (and route) going to the next kept one. Default 3 000 (5 min of
    /// cycles at 10 Hz; an hour's are kept every 1.6 s).
    pub max_cycles: usize,
    /// The GIF.
    pub gif: GifParams,
}

impl Default for ReplayParams {
    fn default() -> Self {
        ReplayParams {
            state_step_s: 0.1,
            decimals: 2,
            branch_tolerance_m: 0.03,
            forecast_near_m: 5.0,
            max_points: 20_000,
            max_states: 6_000,
            max_cycles: 3_000,
            gif: GifParams::default(),
        }
    }
}

/// Settings of the animated GIF.
#[derive(Debug, Clone, PartialEq)]
pub struct GifParams {
    /// Simulated seconds between frames, at least; `> 0`. Default 0.5 s.
    pub frame_step_s: f64,
    /// At most this many frames (the step grows for long flights); `≥ 2`. Default 48.
    pub max_frames: usize,
    /// Width of a frame (px, 200 to 8000). Default 480.
    pub width_px: u32,
    /// How long each frame shows (ms). Default 150 ms (about 3× real time at 0.5 s per frame).
    pub frame_delay_ms: u32,
}

impl Default for GifParams {
    fn default() -> Self {
        GifParams {
            frame_step_s: 0.5,
            max_frames: 48,
            width_px: 480,
            frame_delay_ms: 150,
        }
    }
}

/// What [`write_replay`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct ReplayFiles {
    /// The HTML page.
    pub html: PathBuf,
    /// Its size in bytes.
    pub html_bytes: usize,
    /// The GIF.
    pub gif: GifWritten,
}

/// Reads the run log at `log_path` and writes `STEM.replay.html` and `STEM.replay.gif` into
/// `out_dir` (created if needed), `STEM` being the log's file stem.
///
/// # Errors
/// [`ReplayError`] naming the file: a log that cannot be read or is not a run log (with the line),
/// an unreadable static points file, bad parameters, or an output that cannot be written.
pub fn write_replay(
    log_path: &Path,
    out_dir: &Path,
    params: &ReplayParams,
) -> Result<ReplayFiles, ReplayError> {
    data::check_params(params)?;
    frames::check(&params.gif)?;
    let log_dir = log_path.parent().unwrap_or(Path::new("."));
    let stem = log_path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("run");
    // Pass 1, the page: the log streamed once, the points read once.
    let mut prepared: Option<(Vec<[f64; 3]>, PageBuilder<'_>)> = None;
    let (header, outcome) = data::visit_file(log_path, &mut |header, item| {
        if prepared.is_none() {
            let (points, geometry) = data::geometry(header, log_dir, params.max_points)?;
            prepared = Some((points, PageBuilder::new(params, geometry)));
        }
        if let Some((_, page)) = prepared.as_mut() {
            page.item(item);
        }
        Ok(())
    })?;
    let (points, page) = prepared.expect("a log has at least one state");
    let (t0, t1) = page.span().expect("a log has at least one state");
    let data = page.finish(&header, &outcome, &points);
    let html = page::html_of(&header, &outcome, &data);
    std::fs::create_dir_all(out_dir).map_err(|source| ReplayError::Write {
        path: out_dir.to_path_buf(),
        source,
    })?;
    let html_path = out_dir.join(format!("{stem}.replay.html"));
    std::fs::write(&html_path, &html).map_err(|source| ReplayError::Write {
        path: html_path.clone(),
        source,
    })?;
    // Pass 2, the GIF: the frames' snapshots, the log streamed again.
    let mut frames = frames::FrameCollector::new(t0, t1, &params.gif);
    data::visit_file(log_path, &mut |_, item| {
        frames.item(item);
        Ok(())
    })?;
    let gif = frames::draw_gif(
        &header,
        &points,
        frames,
        &out_dir.join(format!("{stem}.replay.gif")),
        &params.gif,
    )?;
    Ok(ReplayFiles {
        html: html_path,
        html_bytes: html.len(),
        gif,
    })
}

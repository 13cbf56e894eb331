//! Figures for the experiment reports, written as both SVG and PNG.
//!
//! Four figure kinds (and one animation) cover the reports of the paper's simulation experiments (Sec. IV-D):
//!
//! - [`MapView`]: a top (x–y) or side (x–z) view of a scene at equal aspect ratio — static shapes,
//!   a thinned point cloud, the flown path and planned trajectories, obstacle tracks, forecast rings,
//!   start and goal markers.
//! - [`TimeSeries`]: named (x, y) series against labelled limit lines (v_max, a_max, clearance 0) with
//!   optional shaded bands — speed, acceleration, clearance and CPU time per cycle.
//! - [`BarChart`]: one bar per category with an optional interval (a 95 % Wilson interval, mean ± CI),
//!   an optional reference value per category (the paper's number) and value labels.
//! - [`write_gif`]: a sequence of [`MapView`] frames as an animated GIF (the flight replay's top
//!   view; plotters' GIF backend over the pure-Rust `gif` crate).
//! - [`Distribution`]: box plots (Tukey or min/max whiskers) and/or strip plots per category — flight
//!   duration and CPU time across trials.
//!
//! The API is data in, files out: figures know nothing of the simulator's types, every figure is a
//! pure function of its inputs (the same figure gives byte-identical SVG), and text is drawn with the
//! bundled DejaVu Sans through plotters' pure-Rust `ab_glyph` path, so PNGs look the same on every
//! machine and no system font library is involved. Legends sit in a band below the plot and never
//! cover data. Items with non-finite coordinates are skipped and counted ([`Written::skipped_count`]);
//! a figure with nothing left to draw, unusable bounds or ranges, and file-system failures are
//! [`PlotError`]s naming the file.
//!
//! # Example
//!
//! ```
//! use trust_plot::{Figure, HLine, Series, TimeSeries};
//!
//! let speed: Vec<(f64, f64)> = (0..50).map(|i| (0.1 * i as f64, (0.1 * i as f64).min(2.5))).collect();
//! let figure = TimeSeries::new("Speed")
//!     .axis_labels("t [s]", "|v| [m/s]")
//!     .series(Series::new("TRUST-Planner", speed))
//!     .limit(HLine::new("v_max = 3 m/s", 3.0));
//! let dir = std::env::temp_dir().join("trust-plot-doc");
//! let written = figure.write(&dir, "speed")?;
//! assert!(written.svg.ends_with("speed.svg") && written.png.ends_with("speed.png"));
//! # Ok::<(), trust_plot::PlotError>(())
//! ```
#![warn(missing_docs)]

mod animation;
mod axis;
mod bar;
mod distribution;
mod error;
mod frame;
mod legend;
mod map;
mod output;
mod series;
mod style;

pub use animation::{GifWritten, write_gif};
pub use bar::{Bar, BarChart};
pub use distribution::{BoxStats, Distribution, DistributionKind, Whiskers, quantile_sorted};
pub use error::PlotError;
pub use map::{Bounds, ForecastRings, MapView, Marker, Plane, Polyline, Shape};
pub use output::{Figure, Written};
pub use series::{Band, HLine, Series, TimeSeries};
pub use style::{Color, MarkerShape};

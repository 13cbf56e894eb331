//! Scripted obstacle motion: deterministic truth that follows time-stamped samples or a closed
//! parametric curve (scenario `motion = { kind = "samples", … }` / `{ kind = "fourier", … }`).
//!
//! A scripted obstacle ignores its region's walls and draws no random maneuvers; the planner
//! still sees it only through the noisy sensor and the EKF ([`crate::sensing`]).
//!
//! # Samples
//!
//! `samples = [[t, x, y, z], …]` inline, or `file = "data/track.csv"` (relative to the scenario
//! file): a CSV of `t,x,y,z` lines (comma- or whitespace-separated; an optional header line
//! `t,x,y,z`; blank lines and `#` comments ignored). Times are absolute simulation times and must
//! increase strictly; at least 2 samples.
//!
//! The centre between samples is a **piecewise cubic Hermite** interpolant per axis with PCHIP
//! tangents (Fritsch–Carlson monotonicity, the Fritsch–Butland weighted harmonic mean of the two
//! neighbouring slopes, zero where they differ in sign or one is zero). It passes through every
//! sample, is C¹ (the true velocity is its derivative, continuous at the samples), and never
//! overshoots two consecutive samples on any axis: a stop (repeated positions) stays a stop, and an
//! obstacle whose samples all keep it inside its region stays inside between them — which is why
//! validation checks the samples only.
//!
//! `end = "hold"` (default): before the first sample the obstacle rests at the first, after the
//! last at the last, and the tangents at both ends are zero, so the velocity reaches 0 smoothly
//! (C¹ into the hold). `end = "loop"`: the track repeats with period `t_last − t_first` (also
//! before `t_first`); the last sample must equal the first (within 1e-6 m) and the tangent there
//! is computed from the slopes on both sides of the seam, so the loop is C¹ everywhere.
//!
//! # Fourier curves
//!
//! `{ kind = "fourier", period_s = T, center = [cx, cy, cz], cos = [a₁, a₂, …], sin = [b₁, b₂,
//! …], phase_s = φ }`, each `a_k`, `b_k` a vector `[x, y, z]`: with `ω = 2π/T` and `τ = t + φ`,
//!
//! ```text
//! p(t) = c + Σ_k ( a_k cos(k ω τ) + b_k sin(k ω τ) )
//! ```
//!
//! a closed curve of period `T` (`p(t + T) = p(t)`) with velocity `Σ_k k ω (b_k cos − a_k sin)`.
//! It expresses the closed curves of moving-obstacle benchmarks directly: a circle of radius `r`
//! in the plane `z = cz` is `cos = [[r, 0, 0]], sin = [[0, r, 0]]`; an ellipse with half axes
//! `(rx, ry)` is `cos = [[rx, 0, 0]], sin = [[0, ry, 0]]`; a figure-eight (Lissajous 1:2) is
//! `cos = [[rx, 0, 0]], sin = [[0, 0, 0], [0, ry, 0]]` (x at ω, y at 2ω); any other Lissajous
//! figure sets the harmonics its frequencies name, with phases through `cos`/`sin` pairs. At most
//! [`MAX_HARMONICS`] harmonics per list. Validation checks that the obstacle stays inside its
//! region at [`FOURIER_CHECK_SAMPLES`] evenly spaced instants of one period (not between them).

use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use trust_core::{Aabb, Vec3};

use crate::error::WorldError;
use crate::problem::{Problems, fmt_bounds, fmt_vec};

/// Most samples of one track (the scale policy's cap on path vertices).
pub const MAX_SAMPLES: usize = 100_000;
/// Most harmonics in each of a Fourier curve's `cos` and `sin` lists.
pub const MAX_HARMONICS: usize = 64;
/// Instants of one period at which validation checks that a Fourier curve stays in its region.
pub const FOURIER_CHECK_SAMPLES: usize = 1024;
/// Largest accepted gap between the last and the first sample of a looped track (m).
pub const LOOP_CLOSURE_M: f64 = 1e-6;
/// Largest absolute sample time and period (s), the scale policy's time range.
const MAX_TIME_S: f64 = 1e7;

/// What a sampled track does after its last sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EndMode {
    /// Rest at the last sample (and at the first before it starts).
    #[default]
    Hold,
    /// Repeat with period `t_last − t_first`; the last sample must equal the first.
    Loop,
}

/// `motion = { kind = "samples", … }`: time-stamped samples, inline or from a CSV file (module
/// docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SamplesSpec {
    /// `[[t, x, y, z], …]` (s, m). Empty when `file` is given.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub samples: Vec<[f64; 4]>,
    /// A CSV file of `t,x,y,z` lines, relative to the scenario file's folder (or absolute).
    /// Exactly one of `samples` and `file`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    /// `"hold"` (default) or `"loop"`.
    #[serde(default)]
    pub end: EndMode,
    /// The CSV line of each sample when `samples` were read from `file` (validation names a bad
    /// sample by its line); empty otherwise. Not part of the file.
    #[serde(skip)]
    pub lines: Vec<usize>,
}

impl SamplesSpec {
    /// Names of the samples in messages: `FIELD.samples[k]`, or `FIELD.file "PATH" line N` for
    /// samples read from a file.
    pub(crate) fn labels(&self, field: &str) -> Vec<String> {
        match &self.file {
            Some(file) if self.lines.len() == self.samples.len() => self
                .lines
                .iter()
                .map(|n| format!("{field}.file {:?} line {n}", file.display().to_string()))
                .collect(),
            _ => sample_labels(field, self.samples.len()),
        }
    }

    /// The samples of `file` (resolved by `resolve`) in place of the file name: inline samples
    /// are returned as they are.
    ///
    /// The file is read incrementally under [`crate::files`]'s policy (a regular file
    /// of at most [`crate::files::MAX_TRACK_BYTES`]), and at most [`MAX_SAMPLES`]
    /// samples.
    ///
    /// # Errors
    /// [`WorldError::Read`], [`WorldError::NotAFile`], [`WorldError::TooLarge`], or
    /// [`WorldError::PointsFile`] (the CSV line that does not parse, the line beyond
    /// [`MAX_SAMPLES`] samples, or a file with no sample: "only a header").
    pub fn load(&self, resolve: impl Fn(&Path) -> PathBuf) -> Result<SamplesSpec, WorldError> {
        let Some(file) = &self.file else {
            return Ok(self.clone());
        };
        if !self.samples.is_empty() {
            return Ok(self.clone());
        }
        let full = resolve(file);
        let mut csv = CsvTrack::default();
        crate::files::for_each_line(
            &full,
            crate::files::MAX_TRACK_BYTES,
            "a track file",
            |n, line| csv.line(n, line),
        )?;
        let rows = csv
            .finish()
            .map_err(|(line, message)| WorldError::PointsFile {
                path: full.clone(),
                line,
                message,
            })?;
        Ok(SamplesSpec {
            samples: rows.iter().map(|r| r.1).collect(),
            file: Some(file.clone()),
            end: self.end,
            lines: rows.iter().map(|r| r.0).collect(),
        })
    }
}

/// `motion = { kind = "fourier", … }`: a closed curve `c + Σ a_k cos(kωτ) + b_k sin(kωτ)`
/// (module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FourierSpec {
    /// Period `T` (s), `> 0`.
    pub period_s: f64,
    /// Centre `c` (m).
    pub center: [f64; 3],
    /// `a_1, a_2, …` (m): the cosine coefficient vector of each harmonic.
    #[serde(default)]
    pub cos: Vec<[f64; 3]>,
    /// `b_1, b_2, …` (m): the sine coefficient vector of each harmonic.
    #[serde(default)]
    pub sin: Vec<[f64; 3]>,
    /// Time offset `φ` (s): the curve is evaluated at `τ = t + φ`. Default 0.
    #[serde(default)]
    pub phase_s: f64,
}

/// A sampled track ready to evaluate: PCHIP cubic Hermite per axis (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct SampledPath {
    times: Vec<f64>,
    points: Vec<Vec3>,
    tangents: Vec<Vec3>,
    end: EndMode,
}

/// Fritsch–Butland tangent between slopes `d0` (interval `h0`, before) and `d1` (`h1`, after).
fn pchip_tangent(d0: f64, d1: f64, h0: f64, h1: f64) -> f64 {
    if d0 * d1 <= 0.0 {
        return 0.0;
    }
    let w1 = 2.0 * h1 + h0;
    let w2 = h1 + 2.0 * h0;
    (w1 + w2) / (w1 / d0 + w2 / d1)
}

impl SampledPath {
    /// The interpolant of `samples` (`[t, x, y, z]`), checked first: at least 2 and at most
    /// [`MAX_SAMPLES`] samples, finite values within the scale policy, strictly increasing times,
    /// and for a loop the last position equal to the first (the region is checked by the
    /// scenario's validation).
    ///
    /// # Errors
    /// [`WorldError::Input`] naming the first bad sample under `field`.
    pub fn new(field: &str, samples: &[[f64; 4]], end: EndMode) -> Result<Self, WorldError> {
        let mut p = Problems::default();
        check_samples(
            field,
            samples,
            &sample_labels(field, samples.len()),
            end,
            &mut p,
        );
        if let Some(first) = p.list.into_iter().next() {
            return Err(WorldError::Input(first));
        }
        let times: Vec<f64> = samples.iter().map(|s| s[0]).collect();
        let points: Vec<Vec3> = samples
            .iter()
            .map(|s| Vec3::new(s[1], s[2], s[3]))
            .collect();
        let n = points.len();
        let h: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
        let slope: Vec<Vec3> = (0..n - 1)
            .map(|i| (points[i + 1] - points[i]) / h[i])
            .collect();
        let mut tangents = vec![Vec3::zeros(); n];
        for i in 1..n - 1 {
            for a in 0..3 {
                tangents[i][a] = pchip_tangent(slope[i - 1][a], slope[i][a], h[i - 1], h[i]);
            }
        }
        if end == EndMode::Loop && n >= 3 {
            for a in 0..3 {
                tangents[0][a] = pchip_tangent(slope[n - 2][a], slope[0][a], h[n - 2], h[0]);
            }
            tangents[n - 1] = tangents[0];
        }
        Ok(SampledPath {
            times,
            points,
            tangents,
            end,
        })
    }

    /// Maps `t` into the sampled span: clamped (hold) or wrapped (loop).
    fn local_time(&self, t: f64) -> f64 {
        let (t0, t1) = (self.times[0], self.times[self.times.len() - 1]);
        match self.end {
            EndMode::Hold => t.clamp(t0, t1),
            EndMode::Loop => t0 + (t - t0).rem_euclid(t1 - t0),
        }
    }

    /// Position and velocity at time `t` (s).
    pub fn evaluate(&self, t: f64) -> (Vec3, Vec3) {
        let u = self.local_time(t);
        let n = self.times.len();
        let i = self.times.partition_point(|&x| x <= u).clamp(1, n - 1) - 1;
        let h = self.times[i + 1] - self.times[i];
        let s = ((u - self.times[i]) / h).clamp(0.0, 1.0);
        let (s2, s3) = (s * s, s * s * s);
        let (p0, p1) = (self.points[i], self.points[i + 1]);
        let (m0, m1) = (self.tangents[i] * h, self.tangents[i + 1] * h);
        let p = p0 * (2.0 * s3 - 3.0 * s2 + 1.0)
            + m0 * (s3 - 2.0 * s2 + s)
            + p1 * (-2.0 * s3 + 3.0 * s2)
            + m1 * (s3 - s2);
        let held = self.end == EndMode::Hold && (t < self.times[0] || t > self.times[n - 1]);
        let v = if held {
            Vec3::zeros()
        } else {
            (p0 * (6.0 * s2 - 6.0 * s)
                + m0 * (3.0 * s2 - 4.0 * s + 1.0)
                + p1 * (-6.0 * s2 + 6.0 * s)
                + m1 * (3.0 * s2 - 2.0 * s))
                / h
        };
        (p, v)
    }

    /// The sample times (s).
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// The sample positions (m).
    pub fn points(&self) -> &[Vec3] {
        &self.points
    }
}

/// A Fourier curve ready to evaluate (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct FourierCurve {
    spec: FourierSpec,
}

impl FourierCurve {
    /// The curve of `spec`, checked first: a period in `(0, 1e7]` s, finite centre, phase and
    /// coefficients (within 1e6 m), at most [`MAX_HARMONICS`] per list (the region is checked by
    /// the scenario's validation).
    ///
    /// # Errors
    /// [`WorldError::Input`] naming the first bad field under `field`.
    pub fn new(field: &str, spec: &FourierSpec) -> Result<Self, WorldError> {
        let mut p = Problems::default();
        check_fourier(field, spec, &mut p);
        if let Some(first) = p.list.into_iter().next() {
            return Err(WorldError::Input(first));
        }
        Ok(FourierCurve { spec: spec.clone() })
    }

    /// Position and velocity at time `t` (s).
    pub fn evaluate(&self, t: f64) -> (Vec3, Vec3) {
        let s = &self.spec;
        let omega = TAU / s.period_s;
        // Reduce the phase to one period first, so that large t keeps its precision.
        let tau = (t + s.phase_s).rem_euclid(s.period_s);
        let mut p = Vec3::from(s.center);
        let mut v = Vec3::zeros();
        let harmonics = s.cos.len().max(s.sin.len());
        for k in 1..=harmonics {
            let kw = k as f64 * omega;
            let (sin, cos) = (kw * tau).sin_cos();
            let a = s.cos.get(k - 1).map_or(Vec3::zeros(), |a| Vec3::from(*a));
            let b = s.sin.get(k - 1).map_or(Vec3::zeros(), |b| Vec3::from(*b));
            p += a * cos + b * sin;
            v += (b * cos - a * sin) * kw;
        }
        (p, v)
    }
}

/// A scripted motion ready to evaluate.
#[derive(Debug, Clone, PartialEq)]
pub enum Script {
    /// Time-stamped samples.
    Samples(SampledPath),
    /// A closed Fourier curve.
    Fourier(FourierCurve),
}

impl Script {
    /// Position and velocity at time `t` (s).
    pub fn evaluate(&self, t: f64) -> (Vec3, Vec3) {
        match self {
            Script::Samples(s) => s.evaluate(t),
            Script::Fourier(f) => f.evaluate(t),
        }
    }
}

fn sample_labels(field: &str, n: usize) -> Vec<String> {
    (0..n).map(|k| format!("{field}.samples[{k}]")).collect()
}

/// Checks a track: at least 2 and at most [`MAX_SAMPLES`] samples, every value finite and within
/// the scale policy, times strictly increasing, and for a loop the last position equal to the
/// first. `labels[k]` names sample `k` in the messages (`obstacles[0].motion.samples[3]`, or the
/// CSV file and line).
pub(crate) fn check_samples(
    field: &str,
    samples: &[[f64; 4]],
    labels: &[String],
    end: EndMode,
    p: &mut Problems,
) -> bool {
    let before = p.list.len();
    if samples.len() < 2 {
        p.push(
            format!("{field}.samples"),
            format!("{} sample(s)", samples.len()),
            "at least 2 samples [t, x, y, z]",
        );
        return false;
    }
    if samples.len() > MAX_SAMPLES {
        p.push(
            format!("{field}.samples"),
            format!("{} samples", samples.len()),
            format!("at most {MAX_SAMPLES} samples"),
        );
        return false;
    }
    let mut previous: Option<f64> = None;
    for (s, label) in samples.iter().zip(labels) {
        if !s.iter().all(|x| x.is_finite()) {
            p.push(label.clone(), fmt_vec(s), "finite numbers [t, x, y, z]");
            previous = None;
            continue;
        }
        if s[0].abs() > MAX_TIME_S || s[1..].iter().any(|x| x.abs() > 1e6) {
            p.push(
                label.clone(),
                fmt_vec(s),
                "|t| <= 1e7 s and positions within 1e6 m (the scale policy)",
            );
        }
        if let Some(prev) = previous
            && s[0] <= prev
        {
            p.push(
                format!("{label}.t"),
                crate::problem::fmt_num(s[0]),
                format!(
                    "a time after the previous sample's ({} s): times must increase",
                    crate::problem::fmt_num(prev)
                ),
            );
        }
        previous = Some(s[0]);
    }
    let ok = p.list.len() == before;
    if ok && end == EndMode::Loop {
        let (a, b) = (samples[0], samples[samples.len() - 1]);
        let gap = ((a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2) + (a[3] - b[3]).powi(2)).sqrt();
        if gap > LOOP_CLOSURE_M {
            p.push(
                labels[labels.len() - 1].clone(),
                fmt_vec(&b),
                format!(
                    "the first sample's position {} for end = \"loop\" (the track must close; \
                     it ends {} m away)",
                    fmt_vec(&a[1..]),
                    crate::problem::fmt_num(gap)
                ),
            );
        }
    }
    p.list.len() == before
}

/// Checks a Fourier curve's own fields: a finite period in `(0, 1e7]` s, finite centre,
/// coefficients and phase, at most [`MAX_HARMONICS`] harmonics per list.
pub(crate) fn check_fourier(field: &str, f: &FourierSpec, p: &mut Problems) -> bool {
    let before = p.list.len();
    if !(f.period_s.is_finite() && f.period_s > 0.0 && f.period_s <= MAX_TIME_S) {
        p.push(
            format!("{field}.period_s"),
            crate::problem::fmt_num(f.period_s),
            "a finite period in (0, 1e7] s",
        );
    }
    p.finite_vec(&format!("{field}.center"), &f.center);
    p.finite(&format!("{field}.phase_s"), f.phase_s);
    for (name, list) in [("cos", &f.cos), ("sin", &f.sin)] {
        if list.len() > MAX_HARMONICS {
            p.push(
                format!("{field}.{name}"),
                format!("{} harmonics", list.len()),
                format!("at most {MAX_HARMONICS} harmonics"),
            );
        }
        for (k, c) in list.iter().enumerate() {
            if !c.iter().all(|x| x.is_finite() && x.abs() <= 1e6) {
                p.push(
                    format!("{field}.{name}[{k}]"),
                    fmt_vec(c),
                    "finite coefficients within 1e6 m",
                );
            }
        }
    }
    p.list.len() == before
}

/// Checks that the labelled positions keep an obstacle of half extents `e` inside `region`
/// (named `region_field` in messages); reports each offending position.
pub(crate) fn check_inside(
    positions: &[(String, Vec3)],
    e: &Vec3,
    region: &Aabb,
    region_field: &str,
    p: &mut Problems,
) {
    let outside: Vec<&(String, Vec3)> = positions
        .iter()
        .filter(|(_, c)| {
            !(0..3)
                .all(|i| c[i] >= region.min[i] + e[i] - 1e-9 && c[i] <= region.max[i] - e[i] + 1e-9)
        })
        .collect();
    for (label, c) in outside {
        p.push(
            label.clone(),
            fmt_vec(c.as_slice()),
            format!(
                "a centre keeping the whole obstacle (half extents {}) inside {region_field} {}",
                fmt_vec(e.as_slice()),
                fmt_bounds(region.min.as_slice(), region.max.as_slice())
            ),
        );
    }
}

/// One row of a CSV track: its 1-based line number and `[t, x, y, z]`.
pub type CsvRow = (usize, [f64; 4]);

/// Parses the text of a CSV track into `(1-based line, [t, x, y, z])` rows; on error, the line
/// number and what is wrong. Non-finite numbers parse (validation names them with their line).
/// A text without any sample (empty, comments only, or only the header) is an error.
pub fn parse_samples_csv(text: &str) -> Result<Vec<CsvRow>, (usize, String)> {
    let mut csv = CsvTrack::default();
    for (i, raw) in text.lines().enumerate() {
        csv.line(i + 1, raw)?;
    }
    csv.finish()
}

/// A CSV track parsed line by line (as it is read).
#[derive(Default)]
struct CsvTrack {
    rows: Vec<CsvRow>,
    /// The line of the header, if the first non-comment line was one.
    header: Option<usize>,
    seen_data: bool,
    last_line: usize,
}

impl CsvTrack {
    fn line(&mut self, n: usize, raw: &str) -> Result<(), (usize, String)> {
        use crate::files::echo;
        self.last_line = n;
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            return Ok(());
        }
        if self.rows.len() >= MAX_SAMPLES {
            return Err((
                n,
                format!("more than {MAX_SAMPLES} samples (the cap on a track, scale policy)"),
            ));
        }
        let fields: Vec<&str> = line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|f| !f.is_empty())
            .take(5)
            .collect();
        let is_header = fields.len() == 4
            && fields
                .iter()
                .zip(["t", "x", "y", "z"])
                .all(|(f, h)| f.eq_ignore_ascii_case(h));
        if is_header && !self.seen_data {
            self.seen_data = true;
            self.header = Some(n);
            return Ok(());
        }
        self.seen_data = true;
        if fields.len() != 4 {
            let count = if fields.len() > 4 {
                "more than 4".to_string()
            } else {
                fields.len().to_string()
            };
            return Err((
                n,
                format!(
                    "{} has {count} fields, expected four numbers `t,x,y,z`",
                    echo(line)
                ),
            ));
        }
        let mut s = [0.0; 4];
        for (k, f) in fields.iter().enumerate() {
            s[k] = f.parse::<f64>().map_err(|_| {
                (
                    n,
                    format!(
                        "{}: field {} = {} is not a number",
                        echo(line),
                        ["t", "x", "y", "z"][k],
                        echo(f)
                    ),
                )
            })?;
        }
        self.rows.push((n, s));
        Ok(())
    }

    fn finish(self) -> Result<Vec<CsvRow>, (usize, String)> {
        if !self.rows.is_empty() {
            return Ok(self.rows);
        }
        Err(match self.header {
            Some(h) => (
                h,
                "only a header line `t,x,y,z` and no sample: a track needs at least 2 `t,x,y,z` \
                 lines"
                    .to_string(),
            ),
            None => (
                self.last_line.max(1),
                "no sample (the file is empty or only comments): a track needs at least 2 \
                 `t,x,y,z` lines"
                    .to_string(),
            ),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track() -> Vec<[f64; 4]> {
        vec![
            [0.0, 0.0, 0.0, 1.0],
            [1.0, 1.0, 0.5, 1.0],
            [2.5, 2.0, 2.0, 1.0],
            [3.0, 2.0, 2.0, 1.0], // a stop
            [4.0, 1.0, 3.0, 1.2],
            [6.0, 0.0, 0.0, 1.0],
        ]
    }

    #[test]
    fn interpolation_passes_through_the_samples_and_is_c1() {
        for end in [EndMode::Hold, EndMode::Loop] {
            let path = SampledPath::new("m", &track(), end).unwrap();
            for s in track() {
                let (p, _) = path.evaluate(s[0]);
                assert!(
                    (p - Vec3::new(s[1], s[2], s[3])).norm() < 1e-12,
                    "{end:?} {s:?}"
                );
            }
            // C¹ at every interior knot (and at the seam of the loop): velocities from both
            // sides agree, and they are the derivative of the position.
            let eps = 1e-7;
            for s in &track()[1..] {
                let t = s[0];
                let (_, v_minus) = path.evaluate(t - eps);
                let (_, v_plus) = path.evaluate(t + eps);
                if end == EndMode::Hold && t == 6.0 {
                    assert!(v_minus.norm() < 1e-5, "hold ends at rest");
                    continue;
                }
                assert!((v_minus - v_plus).norm() < 1e-5, "{end:?} t = {t}");
            }
            for t in [0.3, 1.7, 2.9, 3.5, 5.2] {
                let (_, v) = path.evaluate(t);
                let h = 1e-6;
                let fd = trust_numdiff::central_difference(|s| path.evaluate(s).0, t, h);
                assert!((v - fd).norm() < 1e-6, "{end:?} t = {t}: {v} vs {fd}");
            }
        }
    }

    #[test]
    fn a_stop_stays_a_stop_and_no_axis_overshoots() {
        let path = SampledPath::new("m", &track(), EndMode::Hold).unwrap();
        for k in 0..=100 {
            let t = 2.5 + 0.5 * k as f64 / 100.0;
            let (p, v) = path.evaluate(t);
            assert!((p - Vec3::new(2.0, 2.0, 1.0)).norm() < 1e-12 && v.norm() < 1e-12);
        }
        let samples = track();
        for w in samples.windows(2) {
            for k in 0..=50 {
                let t = w[0][0] + (w[1][0] - w[0][0]) * k as f64 / 50.0;
                let (p, _) = path.evaluate(t);
                for a in 0..3 {
                    let (lo, hi) = (w[0][a + 1].min(w[1][a + 1]), w[0][a + 1].max(w[1][a + 1]));
                    assert!(p[a] >= lo - 1e-12 && p[a] <= hi + 1e-12, "t = {t} axis {a}");
                }
            }
        }
    }

    #[test]
    fn hold_stays_and_loop_wraps_continuously() {
        let hold = SampledPath::new("m", &track(), EndMode::Hold).unwrap();
        for t in [-5.0, -0.1] {
            let (p, v) = hold.evaluate(t);
            assert_eq!((p, v), (Vec3::new(0.0, 0.0, 1.0), Vec3::zeros()));
        }
        for t in [6.0, 6.1, 100.0] {
            let (p, v) = hold.evaluate(t);
            assert!((p - Vec3::new(0.0, 0.0, 1.0)).norm() < 1e-12 && v.norm() < 1e-12);
        }
        let looped = SampledPath::new("m", &track(), EndMode::Loop).unwrap();
        for t in [0.4, 2.0, 3.3, 5.9] {
            let (p, v) = looped.evaluate(t);
            for k in [-2.0, 1.0, 3.0] {
                let (q, w) = looped.evaluate(t + 6.0 * k);
                assert!((p - q).norm() < 1e-9 && (v - w).norm() < 1e-9, "t = {t}");
            }
        }
        // Across the seam of a round track the position is continuous and the velocity too.
        let round = [
            [0.0, 1.0, 0.0, 1.0],
            [1.0, 0.0, 1.0, 1.0],
            [2.0, -1.0, 0.0, 1.0],
            [3.0, 0.0, -1.0, 1.0],
            [4.0, 1.0, 0.0, 1.0],
        ];
        let looped = SampledPath::new("m", &round, EndMode::Loop).unwrap();
        let (a, va) = looped.evaluate(4.0 - 1e-9);
        let (b, vb) = looped.evaluate(4.0 + 1e-9);
        assert!((a - b).norm() < 1e-6 && (va - vb).norm() < 1e-5);
        assert!(va.norm() > 0.1, "the loop keeps moving through the seam");
    }

    #[test]
    fn a_fourier_curve_closes_on_itself() {
        // A figure-eight: x at ω, y at 2ω, a small vertical wobble at 3ω.
        let spec = FourierSpec {
            period_s: 8.0,
            center: [5.0, 5.0, 1.5],
            cos: vec![[2.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.2]],
            sin: vec![[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            phase_s: 0.7,
        };
        let f = FourierCurve::new("m", &spec).unwrap();
        for t in [0.0, 1.3, 4.0, 7.99] {
            let (p, v) = f.evaluate(t);
            let (q, w) = f.evaluate(t + 8.0);
            let (r, u) = f.evaluate(t + 800.0);
            assert!((p - q).norm() < 1e-12 && (v - w).norm() < 1e-12);
            assert!((p - r).norm() < 1e-9 && (v - u).norm() < 1e-9);
            let h = 1e-6;
            let fd = trust_numdiff::central_difference(|s| f.evaluate(s).0, t, h);
            assert!((v - fd).norm() < 1e-6);
        }
        // A circle of radius 2 keeps its radius and speed 2·ω.
        let circle = FourierCurve::new(
            "m",
            &FourierSpec {
                period_s: 4.0,
                center: [0.0; 3],
                cos: vec![[2.0, 0.0, 0.0]],
                sin: vec![[0.0, 2.0, 0.0]],
                phase_s: 0.0,
            },
        )
        .unwrap();
        for t in [0.0, 0.5, 3.1] {
            let (p, v) = circle.evaluate(t);
            assert!((p.norm() - 2.0).abs() < 1e-12);
            assert!((v.norm() - 2.0 * TAU / 4.0).abs() < 1e-12);
        }
    }

    #[test]
    fn every_bad_sample_is_named() {
        let mut p = Problems::default();
        let s = vec![
            [0.0, 0.0, 0.0, 0.0],
            [1.0, f64::NAN, 0.0, 0.0],
            [0.5, 1.0, 0.0, 0.0],
            [0.5, 2.0, 0.0, 0.0],
        ];
        assert!(!check_samples(
            "m",
            &s,
            &sample_labels("m", 4),
            EndMode::Hold,
            &mut p
        ));
        let fields: Vec<&str> = p.list.iter().map(|q| q.field.as_str()).collect();
        assert_eq!(fields, ["m.samples[1]", "m.samples[3].t"]);
        let mut p = Problems::default();
        check_samples("m", &s[..1], &sample_labels("m", 1), EndMode::Hold, &mut p);
        assert_eq!(p.list[0].field, "m.samples");
        let mut p = Problems::default();
        let open = [[0.0, 0.0, 0.0, 0.0], [1.0, 1.0, 0.0, 0.0]];
        check_samples("m", &open, &sample_labels("m", 2), EndMode::Loop, &mut p);
        assert_eq!(p.list[0].field, "m.samples[1]");
        assert!(p.list[0].expected.contains("loop"), "{}", p.list[0]);
        assert!(SampledPath::new("m", &s, EndMode::Hold).is_err());
    }

    #[test]
    fn csv_tracks_parse_with_an_optional_header_and_name_bad_lines() {
        let rows = parse_samples_csv("# walker\nt,x,y,z\n0,1,2,3\n\n1.5, 2, 2, 0\n").unwrap();
        assert_eq!(
            rows,
            vec![(3, [0.0, 1.0, 2.0, 3.0]), (5, [1.5, 2.0, 2.0, 0.0])]
        );
        assert_eq!(parse_samples_csv("0 1 2 3\n").unwrap().len(), 1);
        let (line, msg) = parse_samples_csv("t,x,y,z\n0,1,2,3\n1,2,x3,4\n").unwrap_err();
        assert_eq!(line, 3);
        assert!(msg.contains("field y"), "{msg}");
        let (line, msg) = parse_samples_csv("0,1,2\n").unwrap_err();
        assert_eq!(line, 1);
        assert!(msg.contains("3 fields"), "{msg}");
        // A header after data is an error on its line.
        assert_eq!(parse_samples_csv("0,1,2,3\nt,x,y,z\n").unwrap_err().0, 2);
        // Only a header: a clear message, not "(not loaded)".
        let (line, msg) = parse_samples_csv("# walker\nt,x,y,z\n").unwrap_err();
        assert_eq!(line, 2);
        assert!(msg.contains("only a header"), "{msg}");
        assert!(parse_samples_csv("").unwrap_err().1.contains("no sample"));
        // A bad line is quoted, cut short.
        let (_, msg) = parse_samples_csv(&format!("0,1,2,{}\n", "y".repeat(5000))).unwrap_err();
        assert!(msg.len() < 200, "{msg}");
    }
}

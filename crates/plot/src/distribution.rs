//! [`Distribution`]: box plots and strip plots per category, and the [`BoxStats`] behind them.

use std::path::Path;

use plotters::coord::Shift;
use plotters::element::{Circle, PathElement, Rectangle, Text};
use plotters::prelude::{DrawingArea, DrawingBackend};
use plotters::style::text_anchor::{HPos, VPos};

use super::axis::{self, Axis};
use super::bar::{category_axis, category_label};
use super::error::{DrawError, InputError, PlotError};
use super::frame::{self, Frame, Grid};
use super::legend::{self, Legend, LegendLayout, Swatch};
use super::output::{self, Figure, Prepared, Render, Written};
use super::style::{self, Color, MarkerShape, draw_marker, filled, size, stroke};

/// Where box-plot whiskers end.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Whiskers {
    /// Tukey's rule: at the most extreme samples within 1.5 × IQR of the quartiles; samples beyond
    /// are outliers.
    #[default]
    Tukey,
    /// At the minimum and maximum; no outliers.
    MinMax,
}

/// How a [`Distribution`] shows each category's samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DistributionKind {
    /// Box plot: quartile box, median line, whiskers, outliers as open circles.
    #[default]
    Box,
    /// Strip plot: every sample as a dot, spread sideways by a deterministic offset.
    Strip,
    /// Box plot with every sample drawn over it (outliers then need no separate symbol).
    BoxAndStrip,
}

/// Five-number summary of finite samples, with whiskers and outliers for a box plot.
///
/// Quartiles interpolate linearly between order statistics (Hyndman–Fan type 7, the default of R
/// and NumPy): the `q`-quantile of sorted `x[0..n]` is at position `q (n − 1)`.
#[derive(Clone, Debug, PartialEq)]
pub struct BoxStats {
    /// Number of finite samples.
    pub count: usize,
    /// Smallest sample.
    pub min: f64,
    /// First quartile.
    pub q1: f64,
    /// Median.
    pub median: f64,
    /// Third quartile.
    pub q3: f64,
    /// Largest sample.
    pub max: f64,
    /// Arithmetic mean.
    pub mean: f64,
    /// Lower whisker end.
    pub whisker_low: f64,
    /// Upper whisker end.
    pub whisker_high: f64,
    /// Samples beyond the whiskers, ascending.
    pub outliers: Vec<f64>,
}

impl BoxStats {
    /// Summary of the finite values of `samples` (non-finite ones are ignored); `None` if there are
    /// none.
    pub fn from_samples(samples: &[f64], whiskers: Whiskers) -> Option<Self> {
        let mut x: Vec<f64> = samples.iter().copied().filter(|v| v.is_finite()).collect();
        if x.is_empty() {
            return None;
        }
        x.sort_by(f64::total_cmp);
        let (q1, median, q3) = (
            quantile_sorted(&x, 0.25)?,
            quantile_sorted(&x, 0.5)?,
            quantile_sorted(&x, 0.75)?,
        );
        let (min, max) = (x[0], x[x.len() - 1]);
        let (whisker_low, whisker_high, outliers) = match whiskers {
            Whiskers::MinMax => (min, max, Vec::new()),
            Whiskers::Tukey => {
                let fence = 1.5 * (q3 - q1);
                let (lo_fence, hi_fence) = (q1 - fence, q3 + fence);
                let inside = x
                    .iter()
                    .copied()
                    .filter(|v| *v >= lo_fence && *v <= hi_fence);
                let lo = inside.clone().fold(f64::INFINITY, f64::min);
                let hi = inside.fold(f64::NEG_INFINITY, f64::max);
                let outliers = x
                    .iter()
                    .copied()
                    .filter(|v| *v < lo_fence || *v > hi_fence)
                    .collect();
                (lo, hi, outliers)
            }
        };
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        Some(Self {
            count: x.len(),
            min,
            q1,
            median,
            q3,
            max,
            mean,
            whisker_low,
            whisker_high,
            outliers,
        })
    }
}

/// The `q`-quantile (`q` clamped to `[0, 1]`) of ascending, finite `sorted`, by linear
/// interpolation between order statistics (Hyndman–Fan type 7, R's default): with
/// `h = q (n − 1)`, `x[⌊h⌋] + (h − ⌊h⌋) (x[⌊h⌋ + 1] − x[⌊h⌋])`. `None` for an empty slice.
///
/// The one quantile of the workspace: box plots, the flight summary's cycle-time median and p99, and
/// the study medians all use it.
pub fn quantile_sorted(sorted: &[f64], q: f64) -> Option<f64> {
    let n = sorted.len();
    if n == 0 {
        return None;
    }
    let h = q.clamp(0.0, 1.0) * (n - 1) as f64;
    let lo = h.floor() as usize;
    let hi = (lo + 1).min(n - 1);
    Some(sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo]))
}

#[derive(Clone, Debug, PartialEq)]
struct Group {
    category: String,
    samples: Vec<f64>,
    color: Option<Color>,
}

/// Distributions of samples per category (e.g. flight duration over 100 trials per planner).
///
/// Non-finite samples are skipped and counted; a category without finite samples is labelled
/// "no data". The y range covers all finite samples unless fixed.
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution {
    title: String,
    y_label: String,
    groups: Vec<Group>,
    kind: DistributionKind,
    whiskers: Whiskers,
    show_mean: bool,
    y_range: Option<(f64, f64)>,
    plot_height_px: u32,
}

const BOX_WIDTH: f64 = 0.5;
const STRIP_WIDTH: f64 = 0.56;

impl Distribution {
    /// An empty box-plot figure with Tukey whiskers.
    pub fn new(title: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            y_label: String::new(),
            groups: Vec::new(),
            kind: DistributionKind::Box,
            whiskers: Whiskers::Tukey,
            show_mean: false,
            y_range: None,
            plot_height_px: 360,
        }
    }

    /// Title of the value axis.
    #[must_use]
    pub fn y_label(mut self, label: impl Into<String>) -> Self {
        self.y_label = label.into();
        self
    }

    /// Adds a category with its samples (categories appear left to right in the order added),
    /// coloured from the palette by position.
    #[must_use]
    pub fn category(mut self, name: impl Into<String>, samples: Vec<f64>) -> Self {
        self.groups.push(Group {
            category: name.into(),
            samples,
            color: None,
        });
        self
    }

    /// Adds a category with an explicit colour.
    #[must_use]
    pub fn category_colored(
        mut self,
        name: impl Into<String>,
        samples: Vec<f64>,
        color: Color,
    ) -> Self {
        self.groups.push(Group {
            category: name.into(),
            samples,
            color: Some(color),
        });
        self
    }

    /// Box plot, strip plot or both (default: box plot).
    #[must_use]
    pub fn kind(mut self, kind: DistributionKind) -> Self {
        self.kind = kind;
        self
    }

    /// Whisker rule of the box plots (default: Tukey).
    #[must_use]
    pub fn whiskers(mut self, whiskers: Whiskers) -> Self {
        self.whiskers = whiskers;
        self
    }

    /// Marks each category's mean with a white diamond (legend entry "mean").
    #[must_use]
    pub fn show_mean(mut self, show: bool) -> Self {
        self.show_mean = show;
        self
    }

    /// Fixes the y range.
    #[must_use]
    pub fn y_range(mut self, lo: f64, hi: f64) -> Self {
        self.y_range = Some((lo, hi));
        self
    }

    /// Height of the plot area in pixels (100–4000; default 360).
    #[must_use]
    pub fn plot_height_px(mut self, height: u32) -> Self {
        self.plot_height_px = height;
        self
    }

    fn color(&self, index: usize) -> Color {
        self.groups[index]
            .color
            .unwrap_or_else(|| Color::palette(index))
    }
}

/// Deterministic sideways offset in `[-0.5, 0.5)` for the `i`-th sample (golden-ratio sequence).
fn jitter(i: usize) -> f64 {
    (i as f64 * 0.618_033_988_749_894_9).fract() - 0.5
}

/// Layout of a [`Distribution`].
pub(crate) struct DistributionPlan {
    frame: Frame,
    x: Axis,
    y: Axis,
    stats: Vec<Option<BoxStats>>,
    legend: Legend,
    legend_layout: LegendLayout,
}

impl Render for Distribution {
    type Plan = DistributionPlan;

    fn prepare(&self) -> Result<Prepared<DistributionPlan>, InputError> {
        if !(100..=4000).contains(&self.plot_height_px) {
            return Err(InputError::invalid(
                "plot_height_px",
                self.plot_height_px,
                "100 to 4000",
            ));
        }
        if self.groups.is_empty() {
            return Err(InputError::NoData(
                "the distribution plot has no categories".to_string(),
            ));
        }
        let stats: Vec<Option<BoxStats>> = self
            .groups
            .iter()
            .map(|g| BoxStats::from_samples(&g.samples, self.whiskers))
            .collect();
        let Some((lo, hi)) =
            axis::finite_extent(self.groups.iter().flat_map(|g| g.samples.iter().copied()))
        else {
            return Err(InputError::NoData(
                "no category has a finite sample".to_string(),
            ));
        };
        let (y0, y1) = match self.y_range {
            Some((a, b)) if a.is_finite() && b.is_finite() => axis::pad_degenerate(a, b),
            Some(r) => return Err(InputError::invalid("y_range", r, "finite bounds")),
            None => axis::with_margin(lo, hi, 0.06),
        };
        let ph = self.plot_height_px;
        let y = Axis::new(y0, y1, (ph / 60).max(2) as usize);
        let (pw, x) = category_axis(self.groups.iter().map(|g| g.category.clone()));
        let y_labels: Vec<String> = y.ticks.iter().map(|t| y.label(*t)).collect();
        let mut frame = Frame::new(pw, ph, y_labels.iter().map(String::as_str), "");

        let mut legend = Legend::default();
        let has_outliers = stats.iter().flatten().any(|s| !s.outliers.is_empty());
        if self.kind == DistributionKind::Box && has_outliers {
            legend.add(
                "outliers (beyond 1.5 IQR)",
                Swatch::Ring {
                    color: Color::DARK_GREY.opaque(),
                    radius: 4,
                },
            );
        }
        if self.show_mean {
            legend.add(
                "mean",
                Swatch::Marker {
                    shape: MarkerShape::Diamond,
                    color: Color::rgb(255, 255, 255).opaque(),
                },
            );
        }
        let legend_layout = legend.layout(frame.width());
        frame.legend_h = legend_layout.height();

        let skipped = self
            .groups
            .iter()
            .flat_map(|g| &g.samples)
            .filter(|v| !v.is_finite())
            .count();
        let size = frame.size();
        Ok(Prepared {
            plan: DistributionPlan {
                frame,
                x,
                y,
                stats,
                legend,
                legend_layout,
            },
            size,
            skipped_count: skipped,
            thinned_count: 0,
        })
    }

    fn draw<DB: DrawingBackend>(
        &self,
        plan: &DistributionPlan,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawError> {
        let (chart_area, legend_area) =
            frame::split(root, &plan.frame, &self.title, "", &self.y_label)?;
        let (x, y) = (&plan.x, &plan.y);
        let names: Vec<&str> = self.groups.iter().map(|g| g.category.as_str()).collect();
        let fx = |v: &f64| category_label(&names, *v);
        let fy = |v: &f64| y.label(*v);
        let chart = frame::chart(
            &chart_area,
            &plan.frame,
            x,
            y,
            &fx,
            &fy,
            Grid { x: false, y: true },
        )?;
        let area = chart.plotting_area();
        let clamp = |v: f64| v.clamp(y.lo, y.hi);
        let show_box = self.kind != DistributionKind::Strip;
        let show_strip = self.kind != DistributionKind::Box;

        for (i, (group, stats)) in self.groups.iter().zip(&plan.stats).enumerate() {
            let xc = i as f64;
            let color = self.color(i);
            let Some(st) = stats else {
                let at = chart.backend_coord(&(xc, 0.5 * (y.lo + y.hi)));
                root.draw(&Text::new(
                    "no data",
                    (at.0, at.1 + style::center_shift(size::VALUE)),
                    style::text_style(size::VALUE, Color::GREY, HPos::Center, VPos::Center),
                ))?;
                continue;
            };
            if show_box {
                let (l, r) = (xc - 0.5 * BOX_WIDTH, xc + 0.5 * BOX_WIDTH);
                let edge = stroke(color.opaque(), 2);
                let whisker = stroke(Color::rgb(50, 50, 50).opaque(), 1);
                for (from, to) in [(st.q1, st.whisker_low), (st.q3, st.whisker_high)] {
                    let (from, to) = (clamp(from), clamp(to));
                    area.draw(&PathElement::new(vec![(xc, from), (xc, to)], whisker))?;
                    area.draw(&PathElement::new(
                        vec![(xc - 0.25 * BOX_WIDTH, to), (xc + 0.25 * BOX_WIDTH, to)],
                        whisker,
                    ))?;
                }
                let (q1, q3) = (clamp(st.q1), clamp(st.q3));
                area.draw(&Rectangle::new(
                    [(l, q1), (r, q3)],
                    filled(color.alpha(0.3)),
                ))?;
                area.draw(&Rectangle::new([(l, q1), (r, q3)], edge))?;
                let m = clamp(st.median);
                area.draw(&PathElement::new(
                    vec![(l, m), (r, m)],
                    stroke(Color::BLACK.opaque(), 3),
                ))?;
                if !show_strip {
                    for v in st.outliers.iter().filter(|v| y.contains(**v)) {
                        let at = chart.backend_coord(&(xc, *v));
                        root.draw(&Circle::new(at, 4, stroke(Color::DARK_GREY.opaque(), 1)))?;
                    }
                }
            }
            if show_strip {
                let dot = filled(color.alpha(if show_box { 0.55 } else { 0.7 }));
                for (k, v) in group.samples.iter().filter(|v| v.is_finite()).enumerate() {
                    if y.contains(*v) {
                        let at = chart.backend_coord(&(xc + STRIP_WIDTH * jitter(k), *v));
                        root.draw(&Circle::new(at, 3, dot))?;
                    }
                }
            }
            if self.show_mean && y.contains(st.mean) {
                let at = chart.backend_coord(&(xc, st.mean));
                draw_marker(
                    root,
                    at,
                    MarkerShape::Diamond,
                    6.0,
                    Color::rgb(255, 255, 255).opaque(),
                )?;
            }
        }

        frame::border(&chart, x, y)?;
        legend::draw(&plan.legend, &plan.legend_layout, &legend_area)
    }
}

impl Figure for Distribution {
    fn title(&self) -> &str {
        &self.title
    }

    fn write(&self, dir: &Path, base_name: &str) -> Result<Written, PlotError> {
        output::write_figure(self, dir, base_name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_interpolate_like_r_type_7() {
        let x = [1.0, 2.0, 3.0, 4.0];
        let q = |p: f64| quantile_sorted(&x, p).expect("non-empty");
        assert!((q(0.25) - 1.75).abs() < 1e-12);
        assert!((q(0.5) - 2.5).abs() < 1e-12);
        assert!((q(1.0) - 4.0).abs() < 1e-12);
        // An even count's median is the midpoint, an odd count's the middle value.
        assert!((quantile_sorted(&[1.0, 2.0, 3.0], 0.5).expect("non-empty") - 2.0).abs() < 1e-12);
        assert_eq!(quantile_sorted(&[], 0.5), None);
    }

    #[test]
    fn tukey_whiskers_stop_at_data_inside_the_fences() {
        let mut samples: Vec<f64> = (1..=20).map(f64::from).collect();
        samples.push(100.0);
        samples.push(f64::NAN);
        let st = BoxStats::from_samples(&samples, Whiskers::Tukey).expect("finite samples");
        assert_eq!(st.count, 21);
        assert_eq!(st.whisker_high, 20.0);
        assert_eq!(st.whisker_low, 1.0);
        assert_eq!(st.outliers, vec![100.0]);
        let mm = BoxStats::from_samples(&samples, Whiskers::MinMax).expect("finite samples");
        assert_eq!((mm.whisker_low, mm.whisker_high), (1.0, 100.0));
        assert!(mm.outliers.is_empty());
    }

    #[test]
    fn a_single_sample_gives_a_flat_box() {
        let st = BoxStats::from_samples(&[3.0], Whiskers::Tukey).expect("one sample");
        assert_eq!(
            (st.q1, st.median, st.q3, st.whisker_low, st.whisker_high),
            (3.0, 3.0, 3.0, 3.0, 3.0)
        );
        assert!(BoxStats::from_samples(&[f64::NAN], Whiskers::Tukey).is_none());
    }

    #[test]
    fn jitter_is_deterministic_and_bounded() {
        assert!((0..1000).all(|i| (-0.5..0.5).contains(&jitter(i))));
        assert_eq!(jitter(17), jitter(17));
    }
}

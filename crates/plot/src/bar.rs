//! [`BarChart`]: one bar per category with intervals, reference values and value labels.

use std::path::Path;

use plotters::coord::Shift;
use plotters::element::{PathElement, Rectangle, Text};
use plotters::prelude::{DrawingArea, DrawingBackend};
use plotters::style::text_anchor::{HPos, VPos};

use super::axis::{self, Axis, format_number};
use super::error::{DrawError, InputError, PlotError};
use super::frame::{self, Frame, Grid};
use super::legend::{self, Legend, LegendLayout, Swatch};
use super::output::{self, Figure, Prepared, Render, Written};
use super::style::{self, Color, MarkerShape, draw_marker, filled, size, stroke, text_width};

/// One bar of a [`BarChart`].
#[derive(Clone, Debug, PartialEq)]
pub struct Bar {
    category: String,
    value: f64,
    interval: Option<(f64, f64)>,
    reference: Option<f64>,
    color: Option<Color>,
}

impl Bar {
    /// A bar of height `value` for `category`. A non-finite value draws no bar and the label
    /// "n/a" (counted as skipped).
    pub fn new(category: impl Into<String>, value: f64) -> Self {
        Self {
            category: category.into(),
            value,
            interval: None,
            reference: None,
            color: None,
        }
    }

    /// An interval drawn as an error bar, e.g. a 95 % Wilson interval or mean ± CI (the ends may
    /// come in either order; a non-finite end drops the interval, counted as skipped).
    #[must_use]
    pub fn interval(mut self, lower: f64, upper: f64) -> Self {
        self.interval = Some((lower, upper));
        self
    }

    /// A reference value for this category (e.g. the paper's number), drawn as a marker.
    #[must_use]
    pub fn reference(mut self, value: f64) -> Self {
        self.reference = Some(value);
        self
    }

    /// Colour of the bar (default: the palette colour of its position).
    #[must_use]
    pub fn color(mut self, color: Color) -> Self {
        self.color = Some(color);
        self
    }
}

/// A bar chart with one bar per category (planner), optional error bars, reference markers and
/// value labels above the bars.
///
/// The y range defaults to include zero, every bar, interval end and reference, with headroom for
/// the labels. The image is wide enough that category names never overlap.
#[derive(Clone, Debug, PartialEq)]
pub struct BarChart {
    title: String,
    y_label: String,
    bars: Vec<Bar>,
    reference_label: String,
    interval_label: String,
    value_decimals: usize,
    value_suffix: String,
    y_range: Option<(f64, f64)>,
    plot_height_px: u32,
}

const BAR_WIDTH: f64 = 0.6;
const CAP_WIDTH: f64 = 0.14;
const REFERENCE_OFFSET: f64 = 0.2;

impl BarChart {
    /// An empty chart; references are labelled "paper", intervals "95 % CI", values printed with
    /// one decimal.
    pub fn new(title: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            y_label: String::new(),
            bars: Vec::new(),
            reference_label: "paper".to_string(),
            interval_label: "95 % CI".to_string(),
            value_decimals: 1,
            value_suffix: String::new(),
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

    /// Adds a bar (categories appear left to right in the order added).
    #[must_use]
    pub fn bar(mut self, bar: Bar) -> Self {
        self.bars.push(bar);
        self
    }

    /// Legend label of the reference markers (default "paper"; empty: no entry).
    #[must_use]
    pub fn reference_label(mut self, label: impl Into<String>) -> Self {
        self.reference_label = label.into();
        self
    }

    /// Legend label of the error bars (default "95 % CI"; empty: no entry).
    #[must_use]
    pub fn interval_label(mut self, label: impl Into<String>) -> Self {
        self.interval_label = label.into();
        self
    }

    /// Value labels: number of decimals and a suffix such as " %" or " s".
    #[must_use]
    pub fn value_format(mut self, decimals: usize, suffix: impl Into<String>) -> Self {
        self.value_decimals = decimals.min(12);
        self.value_suffix = suffix.into();
        self
    }

    /// Fixes the y range (e.g. 0–100 for success rates in percent).
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

    fn bar_color(&self, index: usize) -> Color {
        self.bars[index]
            .color
            .unwrap_or_else(|| Color::palette(index))
    }

    fn value_text(&self, bar: &Bar) -> String {
        if bar.value.is_finite() {
            format!(
                "{}{}",
                format_number(bar.value, self.value_decimals),
                self.value_suffix
            )
        } else {
            "n/a".to_string()
        }
    }
}

fn finite_interval(bar: &Bar) -> Option<(f64, f64)> {
    bar.interval
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .map(|(a, b)| (a.min(b), a.max(b)))
}

fn finite_reference(bar: &Bar) -> Option<f64> {
    bar.reference.filter(|r| r.is_finite())
}

/// Category-axis geometry shared by [`BarChart`] and [`Distribution`](super::Distribution):
/// the plot width that keeps category names apart, and the axis with one tick per category.
pub(crate) fn category_axis(names: impl Iterator<Item = String>) -> (u32, Axis) {
    let names: Vec<String> = names.collect();
    let n = names.len();
    let widest = names
        .iter()
        .map(|c| text_width(c, size::TICK))
        .max()
        .unwrap_or(0);
    let per_category = (widest + 28).max(110);
    let plot_w = (per_category * n as u32).max(420);
    let axis = Axis::with_ticks(-0.5, n as f64 - 0.5, (0..n).map(|i| i as f64).collect());
    (plot_w, axis)
}

/// The label of category tick `v` (ticks sit at 0, 1, 2, …).
pub(crate) fn category_label(names: &[&str], v: f64) -> String {
    let i = v.round();
    if i >= 0.0 && (i as usize) < names.len() {
        names[i as usize].to_string()
    } else {
        String::new()
    }
}

/// Layout of a [`BarChart`].
pub(crate) struct BarPlan {
    frame: Frame,
    x: Axis,
    y: Axis,
    legend: Legend,
    legend_layout: LegendLayout,
}

impl Render for BarChart {
    type Plan = BarPlan;

    fn prepare(&self) -> Result<Prepared<BarPlan>, InputError> {
        if !(100..=4000).contains(&self.plot_height_px) {
            return Err(InputError::invalid(
                "plot_height_px",
                self.plot_height_px,
                "100 to 4000",
            ));
        }
        if self.bars.is_empty() {
            return Err(InputError::NoData("the bar chart has no bars".to_string()));
        }
        let has_value = self.bars.iter().any(|b| {
            b.value.is_finite() || finite_interval(b).is_some() || finite_reference(b).is_some()
        });
        if !has_value {
            return Err(InputError::NoData(
                "no bar has a finite value, interval or reference".to_string(),
            ));
        }
        let (y0, y1) = match self.y_range {
            Some((lo, hi)) if lo.is_finite() && hi.is_finite() => axis::pad_degenerate(lo, hi),
            Some(r) => return Err(InputError::invalid("y_range", r, "finite bounds")),
            None => {
                let values = self.bars.iter().flat_map(|b| {
                    let (il, ih) = finite_interval(b).unzip();
                    [Some(b.value), il, ih, finite_reference(b)]
                        .into_iter()
                        .flatten()
                });
                let (lo, hi) = axis::finite_extent(values.chain([0.0])).unwrap_or((0.0, 1.0));
                let (lo, hi) = if hi - lo > 0.0 { (lo, hi) } else { (0.0, 1.0) };
                // Headroom above for the value labels, and below when bars go negative.
                let span = hi - lo;
                (
                    if lo < 0.0 { lo - 0.1 * span } else { lo },
                    hi + 0.14 * span,
                )
            }
        };
        let ph = self.plot_height_px;
        let y = Axis::new(y0, y1, (ph / 60).max(2) as usize);
        let (pw, x) = category_axis(self.bars.iter().map(|b| b.category.clone()));
        let y_labels: Vec<String> = y.ticks.iter().map(|t| y.label(*t)).collect();
        let mut frame = Frame::new(pw, ph, y_labels.iter().map(String::as_str), "");

        let mut legend = Legend::default();
        if self.bars.iter().any(|b| finite_interval(b).is_some()) {
            legend.add(
                &self.interval_label,
                Swatch::ErrorBar {
                    color: Color::BLACK.opaque(),
                },
            );
        }
        if self.bars.iter().any(|b| finite_reference(b).is_some()) {
            legend.add(
                &self.reference_label,
                Swatch::Marker {
                    shape: MarkerShape::Diamond,
                    color: Color::BLACK.opaque(),
                },
            );
        }
        let legend_layout = legend.layout(frame.width());
        frame.legend_h = legend_layout.height();

        let skipped = self.bars.iter().filter(|b| !b.value.is_finite()).count()
            + self
                .bars
                .iter()
                .filter(|b| b.interval.is_some() && finite_interval(b).is_none())
                .count()
            + self
                .bars
                .iter()
                .filter(|b| b.reference.is_some() && finite_reference(b).is_none())
                .count();
        let size = frame.size();
        Ok(Prepared {
            plan: BarPlan {
                frame,
                x,
                y,
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
        plan: &BarPlan,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawError> {
        let (chart_area, legend_area) =
            frame::split(root, &plan.frame, &self.title, "", &self.y_label)?;
        let (x, y) = (&plan.x, &plan.y);
        let names: Vec<&str> = self.bars.iter().map(|b| b.category.as_str()).collect();
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
        let black = Color::BLACK.opaque();
        let top_px = chart.backend_coord(&(x.lo, y.hi)).1;

        for (i, bar) in self.bars.iter().enumerate() {
            let xc = i as f64;
            let mut label_top = clamp(0.0);
            if bar.value.is_finite() {
                let (a, b) = (clamp(0.0), clamp(bar.value));
                area.draw(&Rectangle::new(
                    [(xc - 0.5 * BAR_WIDTH, a), (xc + 0.5 * BAR_WIDTH, b)],
                    filled(self.bar_color(i).alpha(0.85)),
                ))?;
                label_top = label_top.max(b);
            }
            if let Some((lo, hi)) = finite_interval(bar) {
                let (lo, hi) = (clamp(lo), clamp(hi));
                let s = stroke(black, 2);
                area.draw(&PathElement::new(vec![(xc, lo), (xc, hi)], s))?;
                for v in [lo, hi] {
                    area.draw(&PathElement::new(
                        vec![(xc - 0.5 * CAP_WIDTH, v), (xc + 0.5 * CAP_WIDTH, v)],
                        s,
                    ))?;
                }
                label_top = label_top.max(hi);
            }
            if let Some(r) = finite_reference(bar)
                && y.contains(r)
            {
                let at = chart.backend_coord(&(xc + REFERENCE_OFFSET, r));
                draw_marker(root, at, MarkerShape::Diamond, 7.0, black)?;
                label_top = label_top.max(r);
            }
            let (px, py) = chart.backend_coord(&(xc, label_top));
            // Above the highest element, but never above the plot's top edge.
            let ty = (py - 12).max(top_px + 2 + size::VALUE as i32);
            root.draw(&Text::new(
                self.value_text(bar),
                (px, ty),
                style::text_style(size::VALUE, Color::BLACK, HPos::Center, VPos::Bottom),
            ))?;
        }

        frame::border(&chart, x, y)?;
        legend::draw(&plan.legend, &plan.legend_layout, &legend_area)
    }
}

impl Figure for BarChart {
    fn title(&self) -> &str {
        &self.title
    }

    fn write(&self, dir: &Path, base_name: &str) -> Result<Written, PlotError> {
        output::write_figure(self, dir, base_name)
    }
}

//! [`TimeSeries`]: named (x, y) line series against labelled limit lines and shaded bands.

use std::path::Path;

use plotters::coord::Shift;
use plotters::element::{DashedPathElement, PathElement, Polygon};
use plotters::prelude::{DrawingArea, DrawingBackend};

use super::axis::{self, Axis, Rect};
use super::error::{DrawError, InputError, PlotError};
use super::frame::{self, Frame, Grid};
use super::legend::{self, Legend, LegendLayout, Swatch};
use super::output::{self, Figure, Prepared, Render, Written};
use super::style::{Color, MarkerShape, draw_marker, filled, stroke};

/// One named line of a [`TimeSeries`].
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    name: String,
    points: Vec<(f64, f64)>,
    color: Option<Color>,
    width_px: u32,
    dashed: bool,
}

impl Series {
    /// A solid 2-pixel line through `points` (in the given order), coloured from the palette.
    /// Non-finite points break the line and are counted as skipped; an isolated point is drawn
    /// as a dot.
    pub fn new(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            name: name.into(),
            points,
            color: None,
            width_px: 2,
            dashed: false,
        }
    }

    /// Colour (default: the next palette colour among uncoloured series).
    #[must_use]
    pub fn color(mut self, color: Color) -> Self {
        self.color = Some(color);
        self
    }

    /// Line width in pixels (at least 1).
    #[must_use]
    pub fn width_px(mut self, width_px: u32) -> Self {
        self.width_px = width_px.max(1);
        self
    }

    /// Draws the line dashed.
    #[must_use]
    pub fn dashed(mut self) -> Self {
        self.dashed = true;
        self
    }
}

/// A labelled horizontal line: a limit (v_max, a_max) or a threshold (clearance 0).
#[derive(Clone, Debug, PartialEq)]
pub struct HLine {
    label: String,
    y: f64,
    color: Option<Color>,
}

impl HLine {
    /// A dashed line at `y`; colours default to black, dark grey, grey for the first three limits
    /// (distinct from the series palette).
    pub fn new(label: impl Into<String>, y: f64) -> Self {
        Self {
            label: label.into(),
            y,
            color: None,
        }
    }

    /// Colour of the line.
    #[must_use]
    pub fn color(mut self, color: Color) -> Self {
        self.color = Some(color);
        self
    }
}

/// A shaded band between a lower and an upper curve, given as samples `(x, lower, upper)`.
/// A constant band (a feasible region) needs two samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Band {
    label: String,
    samples: Vec<(f64, f64, f64)>,
    color: Color,
    alpha: f64,
}

impl Band {
    /// A band shaded in sky blue at opacity 0.25.
    pub fn new(label: impl Into<String>, samples: Vec<(f64, f64, f64)>) -> Self {
        Self {
            label: label.into(),
            samples,
            color: Color::PALETTE[5],
            alpha: 0.25,
        }
    }

    /// Colour and opacity of the shading.
    #[must_use]
    pub fn color(mut self, color: Color, alpha: f64) -> Self {
        self.color = color;
        self.alpha = alpha;
        self
    }
}

/// A line chart of several series with optional limit lines and bands.
///
/// Ranges default to the data (series, bands and limit lines; 4 % headroom in y); explicit ranges
/// clip. Zero-width ranges are padded.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeSeries {
    title: String,
    x_label: String,
    y_label: String,
    series: Vec<Series>,
    limits: Vec<HLine>,
    bands: Vec<Band>,
    x_range: Option<(f64, f64)>,
    y_range: Option<(f64, f64)>,
    plot_size: (u32, u32),
    legend: bool,
}

const LIMIT_COLORS: [Color; 3] = [Color::BLACK, Color::DARK_GREY, Color::GREY];

impl TimeSeries {
    /// An empty chart with a plot area of 820 × 360 pixels, x axis titled `t [s]`.
    pub fn new(title: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            x_label: "t [s]".to_string(),
            y_label: String::new(),
            series: Vec::new(),
            limits: Vec::new(),
            bands: Vec::new(),
            x_range: None,
            y_range: None,
            plot_size: (820, 360),
            legend: true,
        }
    }

    /// Axis titles.
    #[must_use]
    pub fn axis_labels(mut self, x: impl Into<String>, y: impl Into<String>) -> Self {
        self.x_label = x.into();
        self.y_label = y.into();
        self
    }

    /// Adds a series.
    #[must_use]
    pub fn series(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    /// Adds a limit line.
    #[must_use]
    pub fn limit(mut self, limit: HLine) -> Self {
        self.limits.push(limit);
        self
    }

    /// Adds a shaded band (drawn below the series).
    #[must_use]
    pub fn band(mut self, band: Band) -> Self {
        self.bands.push(band);
        self
    }

    /// Fixes the x range (default: the data's extent).
    #[must_use]
    pub fn x_range(mut self, lo: f64, hi: f64) -> Self {
        self.x_range = Some((lo, hi));
        self
    }

    /// Fixes the y range (default: the data's extent plus limits, with headroom).
    #[must_use]
    pub fn y_range(mut self, lo: f64, hi: f64) -> Self {
        self.y_range = Some((lo, hi));
        self
    }

    /// Size of the plot area in pixels (each 100–8000; the image adds labels and legend).
    #[must_use]
    pub fn plot_size_px(mut self, width: u32, height: u32) -> Self {
        self.plot_size = (width, height);
        self
    }

    /// Shows or hides the legend (shown below the plot by default).
    #[must_use]
    pub fn legend(mut self, show: bool) -> Self {
        self.legend = show;
        self
    }

    fn series_color(&self, index: usize) -> Color {
        let before = self.series[..index]
            .iter()
            .filter(|s| s.color.is_none())
            .count();
        self.series[index]
            .color
            .unwrap_or_else(|| Color::palette(before))
    }

    fn limit_color(&self, index: usize) -> Color {
        self.limits[index]
            .color
            .unwrap_or(LIMIT_COLORS[index % LIMIT_COLORS.len()])
    }
}

fn check_range(field: &str, range: Option<(f64, f64)>) -> Result<Option<(f64, f64)>, InputError> {
    match range {
        None => Ok(None),
        Some((lo, hi)) if lo.is_finite() && hi.is_finite() => {
            Ok(Some(axis::pad_degenerate(lo, hi)))
        }
        Some(r) => Err(InputError::invalid(field, r, "finite bounds")),
    }
}

fn finite2(p: &(f64, f64)) -> bool {
    p.0.is_finite() && p.1.is_finite()
}

fn finite3(s: &(f64, f64, f64)) -> bool {
    s.0.is_finite() && s.1.is_finite() && s.2.is_finite()
}

/// Layout of a [`TimeSeries`].
pub(crate) struct SeriesPlan {
    frame: Frame,
    x: Axis,
    y: Axis,
    legend: Legend,
    legend_layout: LegendLayout,
}

impl Render for TimeSeries {
    type Plan = SeriesPlan;

    fn prepare(&self) -> Result<Prepared<SeriesPlan>, InputError> {
        let (pw, ph) = self.plot_size;
        if !(100..=8000).contains(&pw) || !(100..=8000).contains(&ph) {
            return Err(InputError::invalid(
                "plot_size_px",
                self.plot_size,
                "100 to 8000 each",
            ));
        }
        let x_fixed = check_range("x_range", self.x_range)?;
        let y_fixed = check_range("y_range", self.y_range)?;
        for (i, l) in self.limits.iter().enumerate() {
            if !l.y.is_finite() {
                return Err(InputError::invalid(
                    format!("limits[{i}] ({}).y", l.label),
                    l.y,
                    "a finite value",
                ));
            }
        }
        let series_pts = self
            .series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|p| finite2(p));
        let band_pts = self
            .bands
            .iter()
            .flat_map(|b| b.samples.iter())
            .filter(|s| finite3(s));
        let xs = series_pts
            .clone()
            .map(|p| p.0)
            .chain(band_pts.clone().map(|s| s.0));
        let Some((x0, x1)) = axis::finite_extent(xs) else {
            return Err(InputError::NoData(
                "no series point or band sample has finite coordinates".to_string(),
            ));
        };
        let (x0, x1) = x_fixed.unwrap_or((x0, x1));
        // Only data inside the x range decides the automatic y range.
        let inside = |x: f64| x >= x0 && x <= x1;
        let ys = series_pts
            .filter(|p| inside(p.0))
            .map(|p| p.1)
            .chain(band_pts.filter(|s| inside(s.0)).flat_map(|s| [s.1, s.2]))
            .chain(self.limits.iter().map(|l| l.y));
        let (y0, y1) = match y_fixed {
            Some(r) => r,
            None => {
                let (lo, hi) = axis::finite_extent(ys).unwrap_or((0.0, 1.0));
                axis::with_margin(lo, hi, 0.04)
            }
        };
        let x = Axis::new(x0, x1, (pw / 100).max(2) as usize);
        let y = Axis::new(y0, y1, (ph / 60).max(2) as usize);
        let y_labels: Vec<String> = y.ticks.iter().map(|t| y.label(*t)).collect();
        let mut frame = Frame::new(pw, ph, y_labels.iter().map(String::as_str), &self.x_label);

        let mut legend = Legend::default();
        if self.legend {
            for (i, s) in self.series.iter().enumerate() {
                legend.add(
                    &s.name,
                    Swatch::Line {
                        color: self.series_color(i).opaque(),
                        width: s.width_px,
                        dashed: s.dashed,
                    },
                );
            }
            for b in &self.bands {
                legend.add(
                    &b.label,
                    Swatch::Fill {
                        color: b.color.alpha(b.alpha),
                    },
                );
            }
            for (i, l) in self.limits.iter().enumerate() {
                legend.add(
                    &l.label,
                    Swatch::Line {
                        color: self.limit_color(i).opaque(),
                        width: 2,
                        dashed: true,
                    },
                );
            }
        }
        let legend_layout = legend.layout(frame.width());
        frame.legend_h = legend_layout.height();

        let skipped = self
            .series
            .iter()
            .flat_map(|s| &s.points)
            .filter(|p| !finite2(p))
            .count()
            + self
                .bands
                .iter()
                .flat_map(|b| &b.samples)
                .filter(|s| !finite3(s))
                .count();
        let size = frame.size();
        Ok(Prepared {
            plan: SeriesPlan {
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
        plan: &SeriesPlan,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawError> {
        let (chart_area, legend_area) =
            frame::split(root, &plan.frame, &self.title, &self.x_label, &self.y_label)?;
        let (x, y) = (&plan.x, &plan.y);
        let fx = |v: &f64| x.label(*v);
        let fy = |v: &f64| y.label(*v);
        let chart = frame::chart(
            &chart_area,
            &plan.frame,
            x,
            y,
            &fx,
            &fy,
            Grid { x: true, y: true },
        )?;
        let area = chart.plotting_area();
        let rect = Rect::of(x, y);

        for b in &self.bands {
            let samples: Vec<(f64, f64, f64)> = b.samples.iter().copied().filter(finite3).collect();
            if samples.len() < 2 {
                continue;
            }
            let outline: Vec<(f64, f64)> = samples
                .iter()
                .map(|s| (s.0, s.2.max(s.1)))
                .chain(samples.iter().rev().map(|s| (s.0, s.1.min(s.2))))
                .collect();
            let clipped = axis::clip_polygon(&outline, &rect);
            if clipped.len() >= 3 {
                area.draw(&Polygon::new(clipped, filled(b.color.alpha(b.alpha))))?;
            }
        }

        for (i, l) in self.limits.iter().enumerate() {
            if y.contains(l.y) {
                area.draw(&DashedPathElement::new(
                    vec![(x.lo, l.y), (x.hi, l.y)],
                    9,
                    6,
                    stroke(self.limit_color(i).opaque(), 2),
                ))?;
            }
        }

        for (i, s) in self.series.iter().enumerate() {
            let style = stroke(self.series_color(i).opaque(), s.width_px);
            for run in axis::clip_polyline(&s.points, &rect).0 {
                if run.len() == 1 {
                    let at = chart.backend_coord(&run[0]);
                    draw_marker(
                        root,
                        at,
                        MarkerShape::Circle,
                        2.0 + f64::from(s.width_px),
                        style.color,
                    )?;
                } else if s.dashed {
                    area.draw(&DashedPathElement::new(run, 8, 5, style))?;
                } else {
                    area.draw(&PathElement::new(run, style))?;
                }
            }
        }

        frame::border(&chart, x, y)?;
        legend::draw(&plan.legend, &plan.legend_layout, &legend_area)
    }
}

impl Figure for TimeSeries {
    fn title(&self) -> &str {
        &self.title
    }

    fn write(&self, dir: &Path, base_name: &str) -> Result<Written, PlotError> {
        output::write_figure(self, dir, base_name)
    }
}

//! The layout every figure shares: a title band, the chart (tick labels, axis titles, plot area)
//! and a legend band, all sized in pixels before drawing starts.

use plotters::chart::{ChartBuilder, ChartContext};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::element::{Rectangle, Text};
use plotters::prelude::{Cartesian2d, DrawingArea, DrawingBackend};
use plotters::style::WHITE;
use plotters::style::text_anchor::{HPos, VPos};

use super::axis::Axis;
use super::error::DrawError;
use super::style::{self, Color, size, stroke, text_width};

pub(crate) type Coord = Cartesian2d<Ticked, Ticked>;

/// A linear f64 axis whose tick marks are exactly the given positions (plotters' own
/// `WithKeyPoints` wrapper cannot be combined with custom label formatters for f64).
#[derive(Clone, Debug)]
pub(crate) struct Ticked {
    lo: f64,
    hi: f64,
    ticks: Vec<f64>,
}

impl Ticked {
    fn of(axis: &Axis) -> Self {
        Self {
            lo: axis.lo,
            hi: axis.hi,
            ticks: axis.ticks.clone(),
        }
    }
}

impl Ranged for Ticked {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let t = (value - self.lo) / (self.hi - self.lo);
        // `as` saturates, so far-away values stay representable.
        (f64::from(limit.0) + t * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}
pub(crate) type Chart<'a, DB> = ChartContext<'a, DB, Coord>;
/// A drawing area in pixel coordinates.
pub(crate) type Area<DB> = DrawingArea<DB, Shift>;

const TITLE_H: u32 = 44;
pub(crate) const MARGIN_L: u32 = 8;
pub(crate) const MARGIN_R: u32 = 30;
const MARGIN_T: u32 = 8;
const MARGIN_B: u32 = 8;
const TICK_LEN: u32 = 5;
/// Height below the plot for tick labels, plus room for the x axis title when there is one.
const X_TICKS_H: u32 = 30;
const X_DESC_H: u32 = 26;

/// Pixel sizes of one figure.
#[derive(Clone, Debug)]
pub(crate) struct Frame {
    pub(crate) plot_w: u32,
    pub(crate) plot_h: u32,
    y_label_w: u32,
    x_label_h: u32,
    pub(crate) legend_h: u32,
}

impl Frame {
    /// A frame around a `plot_w` × `plot_h` plot whose y axis shows `y_tick_labels`, with room for
    /// an x axis title if `x_desc` is not empty.
    pub(crate) fn new<'s>(
        plot_w: u32,
        plot_h: u32,
        y_tick_labels: impl IntoIterator<Item = &'s str>,
        x_desc: &str,
    ) -> Self {
        Self {
            plot_w,
            plot_h,
            y_label_w: y_label_width(y_tick_labels),
            x_label_h: X_TICKS_H + if x_desc.is_empty() { 0 } else { X_DESC_H },
            legend_h: 0,
        }
    }

    fn chart_h(&self) -> u32 {
        MARGIN_T + self.plot_h + self.x_label_h + MARGIN_B
    }

    pub(crate) fn width(&self) -> u32 {
        MARGIN_L + self.y_label_w + self.plot_w + MARGIN_R
    }

    pub(crate) fn height(&self) -> u32 {
        TITLE_H + self.chart_h() + self.legend_h
    }

    pub(crate) fn size(&self) -> (u32, u32) {
        (self.width(), self.height())
    }
}

/// Width of the y label area: widest tick label, the tick mark and gap, the rotated axis title.
pub(crate) fn y_label_width<'s>(labels: impl IntoIterator<Item = &'s str>) -> u32 {
    let widest = labels
        .into_iter()
        .map(|l| text_width(l, size::TICK))
        .max()
        .unwrap_or(0);
    widest + 2 * TICK_LEN + 12 + size::AXIS_LABEL as u32 + 8
}

/// Fills the background, draws the title and the axis titles, and returns the chart area and the
/// legend area.
pub(crate) fn split<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    frame: &Frame,
    title: &str,
    x_desc: &str,
    y_desc: &str,
) -> Result<(Area<DB>, Area<DB>), DrawError> {
    root.fill(&WHITE)?;
    let (title_area, rest) = root.split_vertically(TITLE_H);
    title_area.draw(&Text::new(
        title.to_string(),
        ((frame.width() / 2) as i32, 12),
        style::text_style(size::TITLE, Color::BLACK, HPos::Center, VPos::Top),
    ))?;
    let (chart_area, legend_area) = rest.split_vertically(frame.chart_h());
    let plot_x0 = (MARGIN_L + frame.y_label_w) as i32;
    let plot_y_mid = (MARGIN_T + frame.plot_h / 2) as i32;
    if !x_desc.is_empty() {
        chart_area.draw(&Text::new(
            x_desc.to_string(),
            (
                plot_x0 + (frame.plot_w / 2) as i32,
                (frame.chart_h() - MARGIN_B) as i32 - 4,
            ),
            style::text_style(size::AXIS_LABEL, Color::BLACK, HPos::Center, VPos::Bottom),
        ))?;
    }
    if !y_desc.is_empty() {
        chart_area.draw(&Text::new(
            y_desc.to_string(),
            (
                (MARGIN_L + 2) as i32 + (size::AXIS_LABEL / 2.0) as i32,
                plot_y_mid,
            ),
            style::vertical_text_style(size::AXIS_LABEL, Color::BLACK),
        ))?;
    }
    Ok((chart_area, legend_area))
}

/// Which grid lines to draw.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Grid {
    pub(crate) x: bool,
    pub(crate) y: bool,
}

/// Builds the Cartesian chart on `area` and draws grid, ticks and tick labels.
pub(crate) fn chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    frame: &Frame,
    x: &Axis,
    y: &Axis,
    x_fmt: &dyn Fn(&f64) -> String,
    y_fmt: &dyn Fn(&f64) -> String,
    grid: Grid,
) -> Result<Chart<'a, DB>, DrawError> {
    let mut chart = ChartBuilder::on(area)
        .margin_top(MARGIN_T)
        .margin_bottom(MARGIN_B)
        .margin_left(MARGIN_L)
        .margin_right(MARGIN_R)
        .x_label_area_size(frame.x_label_h)
        .y_label_area_size(frame.y_label_w)
        .build_cartesian_2d(Ticked::of(x), Ticked::of(y))?;
    let tick_style = style::text_style(
        size::TICK,
        Color::rgb(30, 30, 30),
        HPos::Center,
        VPos::Center,
    );
    let mut mesh = chart.configure_mesh();
    mesh.x_label_formatter(x_fmt)
        .y_label_formatter(y_fmt)
        .label_style(tick_style)
        .bold_line_style(stroke(Color::rgb(225, 225, 225).opaque(), 1))
        .axis_style(stroke(Color::rgb(60, 60, 60).opaque(), 1))
        .set_all_tick_mark_size(TICK_LEN)
        .y_label_offset(style::center_shift(size::TICK));
    if !grid.x {
        mesh.disable_x_mesh();
    }
    if !grid.y {
        mesh.disable_y_mesh();
    }
    mesh.draw()?;
    Ok(chart)
}

/// Draws the frame around the plot area (after the data, so that it stays crisp).
pub(crate) fn border<DB: DrawingBackend>(
    chart: &Chart<'_, DB>,
    x: &Axis,
    y: &Axis,
) -> Result<(), DrawError> {
    chart.plotting_area().draw(&Rectangle::new(
        [(x.lo, y.lo), (x.hi, y.hi)],
        stroke(Color::rgb(60, 60, 60).opaque(), 1),
    ))?;
    Ok(())
}

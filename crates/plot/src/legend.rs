//! Legends drawn in their own band below the plot, so that they never cover data.

use plotters::coord::Shift;
use plotters::element::{Circle, DashedPathElement, PathElement, Rectangle, Text};
use plotters::prelude::{DrawingArea, DrawingBackend};
use plotters::style::RGBAColor;
use plotters::style::text_anchor::{HPos, VPos};

use super::error::DrawError;
use super::style::{self, Color, MarkerShape, draw_marker, filled, size, stroke, text_width};

/// What a legend entry shows before its label.
#[derive(Clone, Debug)]
pub(crate) enum Swatch {
    Line {
        color: RGBAColor,
        width: u32,
        dashed: bool,
    },
    Fill {
        color: RGBAColor,
    },
    Ring {
        color: RGBAColor,
        radius: i32,
    },
    Marker {
        shape: MarkerShape,
        color: RGBAColor,
    },
    Dots {
        color: RGBAColor,
    },
    ErrorBar {
        color: RGBAColor,
    },
}

const SWATCH_W: i32 = 30;
const SWATCH_GAP: i32 = 8;
const ITEM_SPACING: i32 = 28;
const ROW_H: u32 = 26;
const PAD: u32 = 8;
const SIDE_MARGIN: u32 = 20;

/// Ordered legend entries; a label appears once (the first swatch given for it wins).
#[derive(Clone, Debug, Default)]
pub(crate) struct Legend {
    entries: Vec<(String, Swatch)>,
}

/// Entries placed in rows: `(entry index, x offset)` per row.
#[derive(Clone, Debug, Default)]
pub(crate) struct LegendLayout {
    rows: Vec<Vec<(usize, i32)>>,
    width: u32,
}

impl Legend {
    pub(crate) fn add(&mut self, label: &str, swatch: Swatch) {
        if !label.is_empty() && !self.entries.iter().any(|(l, _)| l == label) {
            self.entries.push((label.to_string(), swatch));
        }
    }

    fn item_width(label: &str) -> i32 {
        SWATCH_W + SWATCH_GAP + text_width(label, size::LEGEND) as i32
    }

    /// Flows the entries into centred rows no wider than `width` pixels.
    pub(crate) fn layout(&self, width: u32) -> LegendLayout {
        let avail = width.saturating_sub(2 * SIDE_MARGIN).max(1) as i32;
        let mut rows: Vec<Vec<(usize, i32)>> = Vec::new();
        let mut row: Vec<(usize, i32)> = Vec::new();
        let mut x = 0;
        for (i, (label, _)) in self.entries.iter().enumerate() {
            let w = Self::item_width(label);
            if !row.is_empty() && x + w > avail {
                rows.push(std::mem::take(&mut row));
                x = 0;
            }
            row.push((i, x));
            x += w + ITEM_SPACING;
        }
        if !row.is_empty() {
            rows.push(row);
        }
        LegendLayout { rows, width }
    }
}

impl LegendLayout {
    /// Height of the legend band in pixels (0 when there are no entries).
    pub(crate) fn height(&self) -> u32 {
        if self.rows.is_empty() {
            0
        } else {
            2 * PAD + ROW_H * self.rows.len() as u32
        }
    }
}

fn draw_swatch<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    x: i32,
    yc: i32,
    swatch: &Swatch,
) -> Result<(), DrawError> {
    let xc = x + SWATCH_W / 2;
    match *swatch {
        Swatch::Line {
            color,
            width,
            dashed,
        } => {
            let pts = vec![(x, yc), (x + SWATCH_W, yc)];
            if dashed {
                area.draw(&DashedPathElement::new(pts, 7, 4, stroke(color, width)))?;
            } else {
                area.draw(&PathElement::new(pts, stroke(color, width)))?;
            }
        }
        Swatch::Fill { color } => {
            area.draw(&Rectangle::new(
                [(x + 3, yc - 7), (x + SWATCH_W - 3, yc + 7)],
                filled(color),
            ))?;
        }
        Swatch::Ring { color, radius } => {
            area.draw(&Circle::new((xc, yc), radius, stroke(color, 2)))?;
        }
        Swatch::Marker { shape, color } => draw_marker(area, (xc, yc), shape, 7.0, color)?,
        Swatch::Dots { color } => {
            for (dx, dy) in [(-8, 3), (-2, -4), (4, 2), (9, -3), (1, 5), (-6, -2)] {
                area.draw(&Circle::new((xc + dx, yc + dy), 2, filled(color)))?;
            }
        }
        Swatch::ErrorBar { color } => {
            let s = stroke(color, 2);
            area.draw(&PathElement::new(vec![(xc, yc - 9), (xc, yc + 9)], s))?;
            area.draw(&PathElement::new(
                vec![(xc - 6, yc - 9), (xc + 6, yc - 9)],
                s,
            ))?;
            area.draw(&PathElement::new(
                vec![(xc - 6, yc + 9), (xc + 6, yc + 9)],
                s,
            ))?;
        }
    }
    Ok(())
}

/// Draws the legend into `area` (the band reserved below the chart).
pub(crate) fn draw<DB: DrawingBackend>(
    legend: &Legend,
    layout: &LegendLayout,
    area: &DrawingArea<DB, Shift>,
) -> Result<(), DrawError> {
    let label_style = style::text_style(size::LEGEND, Color::BLACK, HPos::Left, VPos::Center);
    for (r, row) in layout.rows.iter().enumerate() {
        let Some(&(last, last_x)) = row.last() else {
            continue;
        };
        let row_w = last_x + Legend::item_width(&legend.entries[last].0);
        let x0 = (layout.width as i32 - row_w) / 2;
        let yc = (PAD + ROW_H * r as u32 + ROW_H / 2) as i32;
        for &(i, dx) in row {
            let (label, swatch) = &legend.entries[i];
            draw_swatch(area, x0 + dx, yc, swatch)?;
            area.draw(&Text::new(
                label.clone(),
                (
                    x0 + dx + SWATCH_W + SWATCH_GAP,
                    yc + style::center_shift(size::LEGEND),
                ),
                label_style.clone(),
            ))?;
        }
    }
    Ok(())
}

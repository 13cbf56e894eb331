//! Colours, markers, the bundled font and the text helpers shared by every figure.

use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::{DrawingArea, DrawingBackend, Polygon};
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{
    FontDesc, FontFamily, FontStyle, FontTransform, RGBAColor, ShapeStyle, TextStyle,
};

use super::error::{DrawError, PlotError};

/// An opaque sRGB colour. Transparency is chosen by each figure element, not stored here.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Color {
    /// Red, 0–255.
    pub r: u8,
    /// Green, 0–255.
    pub g: u8,
    /// Blue, 0–255.
    pub b: u8,
}

impl Color {
    /// A colour from its red, green and blue components.
    pub const fn rgb(r: u8, g: u8, b: u8) -> Self {
        Self { r, g, b }
    }

    /// Black.
    pub const BLACK: Self = Self::rgb(0, 0, 0);
    /// Dark grey, for static obstacles.
    pub const DARK_GREY: Self = Self::rgb(90, 90, 90);
    /// Mid grey, for point clouds and secondary lines.
    pub const GREY: Self = Self::rgb(140, 140, 140);
    /// Light grey, for obstacle tracks.
    pub const LIGHT_GREY: Self = Self::rgb(190, 190, 190);
    /// Green used for start markers.
    pub const START_GREEN: Self = Self::rgb(0, 158, 115);
    /// Red used for goal markers and limit lines.
    pub const GOAL_RED: Self = Self::rgb(213, 94, 0);

    /// The default series colours: the Okabe–Ito colour-blind-safe palette without its yellow (too
    /// faint on white), in the order blue, vermillion, bluish green, reddish purple, orange, sky blue,
    /// black.
    pub const PALETTE: [Self; 7] = [
        Self::rgb(0, 114, 178),
        Self::rgb(213, 94, 0),
        Self::rgb(0, 158, 115),
        Self::rgb(204, 121, 167),
        Self::rgb(230, 159, 0),
        Self::rgb(86, 180, 233),
        Self::rgb(0, 0, 0),
    ];

    /// The `index`-th palette colour, cycling.
    pub fn palette(index: usize) -> Self {
        Self::PALETTE[index % Self::PALETTE.len()]
    }

    pub(crate) fn alpha(self, alpha: f64) -> RGBAColor {
        RGBAColor(self.r, self.g, self.b, alpha.clamp(0.0, 1.0))
    }

    pub(crate) fn opaque(self) -> RGBAColor {
        self.alpha(1.0)
    }
}

/// Marker symbols for start/goal markers, bar-chart reference values and legends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum MarkerShape {
    /// Filled circle.
    Circle,
    /// Filled square.
    Square,
    /// Filled diamond (a square on its corner).
    Diamond,
    /// Filled triangle pointing up.
    Triangle,
    /// Filled five-pointed star.
    Star,
    /// Filled upright cross (plus sign).
    Cross,
}

/// The family name under which the bundled font is registered. plotters writes it verbatim into the
/// SVG `font-family` attribute, so viewers use DejaVu Sans when they have it and their own sans-serif
/// otherwise.
pub(crate) const FAMILY: &str = "DejaVu Sans, sans-serif";

/// DejaVu Sans 2.37 (Bitstream Vera licence, `assets/LICENSE-DejaVu.txt`).
static FONT_BYTES: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Registers the bundled font with plotters once per process (also as `sans-serif`, plotters'
/// default family, so that no text path can fall back to a missing system font).
pub(crate) fn ensure_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FAMILY, FontStyle::Normal, FONT_BYTES).is_ok()
            && plotters::style::register_font("sans-serif", FontStyle::Normal, FONT_BYTES).is_ok()
    });
    if ok { Ok(()) } else { Err(PlotError::Font) }
}

/// Font sizes in plotters' unit (pixel height of the font's ascent-to-descent box).
pub(crate) mod size {
    pub(crate) const TITLE: f64 = 24.0;
    pub(crate) const AXIS_LABEL: f64 = 19.0;
    pub(crate) const TICK: f64 = 16.0;
    pub(crate) const LEGEND: f64 = 16.0;
    pub(crate) const VALUE: f64 = 15.0;
}

pub(crate) fn font(px: f64) -> FontDesc<'static> {
    FontDesc::new(FontFamily::Name(FAMILY), px, FontStyle::Normal)
}

/// Text style with colour and anchor.
pub(crate) fn text_style(px: f64, color: Color, h: HPos, v: VPos) -> TextStyle<'static> {
    font(px).color(&color.opaque()).pos(Pos::new(h, v))
}

/// Rotated (reading bottom to top) text style, for vertical axis labels.
pub(crate) fn vertical_text_style(px: f64, color: Color) -> TextStyle<'static> {
    font(px)
        .transform(FontTransform::Rotate270)
        .color(&color.opaque())
        .pos(Pos::new(HPos::Center, VPos::Center))
}

/// Downward shift (pixels) that visually centres vertically centred text of size `px`.
///
/// plotters' `ab_glyph` path draws `VPos::Center` text about 0.2 × size too high, SVG viewers
/// about 0.07 × size too high; this shift splits the difference so both look centred.
pub(crate) fn center_shift(px: f64) -> i32 {
    (0.14 * px).round() as i32
}

/// Width in pixels of `text` in the bundled font (an estimate if the font cannot lay it out).
pub(crate) fn text_width(text: &str, px: f64) -> u32 {
    font(px)
        .box_size(text)
        .map(|(w, _)| w)
        .unwrap_or_else(|_| (0.62 * px * text.chars().count() as f64).ceil() as u32)
}

pub(crate) fn filled(color: RGBAColor) -> ShapeStyle {
    ShapeStyle {
        color,
        filled: true,
        stroke_width: 1,
    }
}

pub(crate) fn stroke(color: RGBAColor, width: u32) -> ShapeStyle {
    ShapeStyle {
        color,
        filled: false,
        stroke_width: width,
    }
}

/// The outline of a marker of radius `r` pixels around the origin, as pixel offsets.
fn marker_outline(shape: MarkerShape, r: f64) -> Vec<(f64, f64)> {
    let ring = |n: usize, radius: &dyn Fn(usize) -> f64, phase: f64| -> Vec<(f64, f64)> {
        (0..n)
            .map(|i| {
                let a = phase + std::f64::consts::TAU * i as f64 / n as f64;
                (radius(i) * a.cos(), -radius(i) * a.sin())
            })
            .collect()
    };
    match shape {
        MarkerShape::Circle => ring(24, &|_| r, 0.0),
        MarkerShape::Square => {
            let s = 0.85 * r;
            vec![(-s, -s), (s, -s), (s, s), (-s, s)]
        }
        MarkerShape::Diamond => vec![(0.0, -1.15 * r), (r, 0.0), (0.0, 1.15 * r), (-r, 0.0)],
        MarkerShape::Triangle => ring(3, &|_| 1.15 * r, std::f64::consts::FRAC_PI_2),
        MarkerShape::Star => ring(
            10,
            &|i| if i % 2 == 0 { 1.3 * r } else { 0.55 * r },
            std::f64::consts::FRAC_PI_2,
        ),
        MarkerShape::Cross => {
            let (a, b) = (r, 0.33 * r);
            vec![
                (-b, -a),
                (b, -a),
                (b, -b),
                (a, -b),
                (a, b),
                (b, b),
                (b, a),
                (-b, a),
                (-b, b),
                (-a, b),
                (-a, -b),
                (-b, -b),
            ]
        }
    }
}

/// Draws a filled marker with a thin dark edge at pixel position `at` of `area`.
pub(crate) fn draw_marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    at: (i32, i32),
    shape: MarkerShape,
    radius_px: f64,
    color: RGBAColor,
) -> Result<(), DrawError> {
    let pts: Vec<(i32, i32)> = marker_outline(shape, radius_px)
        .into_iter()
        .map(|(x, y)| (at.0 + x.round() as i32, at.1 + y.round() as i32))
        .collect();
    area.draw(&Polygon::new(pts.clone(), filled(color)))?;
    let mut closed = pts;
    closed.push(closed[0]);
    let edge = RGBAColor(40, 40, 40, color.3.min(0.9));
    area.draw(&plotters::element::PathElement::new(
        closed,
        stroke(edge, 1),
    ))?;
    Ok(())
}

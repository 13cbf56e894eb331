//! [`MapView`]: a 2-D view of a scene (top view x–y, side view x–z) at equal aspect ratio.

use std::path::Path;

use nalgebra::{Point2, Vector3};
use plotters::coord::Shift;
use plotters::element::{PathElement, Polygon, Rectangle};
use plotters::prelude::{DrawingArea, DrawingBackend};

use super::axis::{self, Axis, Rect};
use super::error::{DrawError, InputError, PlotError};
use super::frame::{self, Frame, Grid};
use super::legend::{self, Legend, LegendLayout, Swatch};
use super::output::{self, Figure, Prepared, Render, Written};
use super::style::{Color, MarkerShape, draw_marker, filled, stroke};

/// Which two coordinates of a 3-D point a [`MapView`] shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Plane {
    /// Top view: x to the right, y up.
    Xy,
    /// Side view: x to the right, z up.
    Xz,
    /// Side view: y to the right, z up.
    Yz,
}

impl Plane {
    /// The two coordinates of `p` shown in this plane.
    pub fn project(self, p: &Vector3<f64>) -> Point2<f64> {
        match self {
            Self::Xy => Point2::new(p.x, p.y),
            Self::Xz => Point2::new(p.x, p.z),
            Self::Yz => Point2::new(p.y, p.z),
        }
    }

    /// Axis titles for this plane, in metres.
    pub fn axis_labels(self) -> (&'static str, &'static str) {
        match self {
            Self::Xy => ("x [m]", "y [m]"),
            Self::Xz => ("x [m]", "z [m]"),
            Self::Yz => ("y [m]", "z [m]"),
        }
    }
}

/// The rectangle of the world a [`MapView`] shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Lower-left corner.
    pub min: Point2<f64>,
    /// Upper-right corner.
    pub max: Point2<f64>,
}

impl Bounds {
    /// The rectangle spanned by two corners (in any order). Non-finite coordinates are kept, so
    /// that writing the figure reports them.
    pub fn new(a: Point2<f64>, b: Point2<f64>) -> Self {
        let order = |u: f64, v: f64| if u <= v { (u, v) } else { (v, u) };
        let ((x0, x1), (y0, y1)) = (order(a.x, b.x), order(a.y, b.y));
        Self {
            min: Point2::new(x0, y0),
            max: Point2::new(x1, y1),
        }
    }
}

/// A filled static obstacle, in world units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A disc: a pillar seen from above, a sphere's cross-section.
    Circle {
        /// Centre.
        center: Point2<f64>,
        /// Radius (negative or non-finite: skipped).
        radius: f64,
    },
    /// An axis-aligned rectangle: a box or a wall.
    Rect {
        /// One corner.
        min: Point2<f64>,
        /// The opposite corner.
        max: Point2<f64>,
    },
}

/// A labelled polyline: the flown path, a planned trajectory.
#[derive(Clone, Debug, PartialEq)]
pub struct Polyline {
    points: Vec<Point2<f64>>,
    label: String,
    color: Option<Color>,
    width_px: u32,
    dashed: bool,
}

impl Polyline {
    /// A solid, 2-pixel polyline without a legend entry, coloured from the palette.
    pub fn new(points: Vec<Point2<f64>>) -> Self {
        Self {
            points,
            label: String::new(),
            color: None,
            width_px: 2,
            dashed: false,
        }
    }

    /// Legend label. Polylines sharing a label share one legend entry (e.g. all planned trajectories).
    #[must_use]
    pub fn label(mut self, label: impl Into<String>) -> Self {
        self.label = label.into();
        self
    }

    /// Colour (default: the next palette colour among uncoloured polylines).
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

/// Outlines of circles along one moving obstacle's forecast, e.g. `(centre(t), radius(t))` at a few
/// times; drawn with opacity fading linearly from the first circle to the last.
#[derive(Clone, Debug, PartialEq)]
pub struct ForecastRings {
    rings: Vec<(Point2<f64>, f64)>,
    color: Color,
    label: String,
    alpha_first: f64,
    alpha_last: f64,
}

impl ForecastRings {
    /// Rings `(centre, radius)` in forecast order, orange, fading from opacity 0.9 to 0.15, with
    /// the legend label "forecast".
    pub fn new(rings: Vec<(Point2<f64>, f64)>) -> Self {
        Self {
            rings,
            color: Color::PALETTE[4],
            label: "forecast".to_string(),
            alpha_first: 0.9,
            alpha_last: 0.15,
        }
    }

    /// Colour of the outlines.
    #[must_use]
    pub fn color(mut self, color: Color) -> Self {
        self.color = color;
        self
    }

    /// Legend label (empty: no entry). Rings sharing a label share one entry.
    #[must_use]
    pub fn label(mut self, label: impl Into<String>) -> Self {
        self.label = label.into();
        self
    }

    /// Opacity of the first and of the last ring (each clamped to `[0, 1]`).
    #[must_use]
    pub fn alpha(mut self, first: f64, last: f64) -> Self {
        self.alpha_first = first;
        self.alpha_last = last;
        self
    }
}

/// A marker drawn at a world position with a fixed pixel size.
#[derive(Clone, Debug, PartialEq)]
pub struct Marker {
    /// Position.
    pub at: Point2<f64>,
    /// Symbol.
    pub shape: MarkerShape,
    /// Fill colour.
    pub color: Color,
    /// Legend label (empty: no entry).
    pub label: String,
    /// Radius in pixels.
    pub radius_px: f64,
}

impl Marker {
    /// A marker with radius 8 px.
    pub fn new(
        at: Point2<f64>,
        shape: MarkerShape,
        color: Color,
        label: impl Into<String>,
    ) -> Self {
        Self {
            at,
            shape,
            color,
            label: label.into(),
            radius_px: 8.0,
        }
    }

    /// The start marker: a green circle labelled "start".
    pub fn start(at: Point2<f64>) -> Self {
        Self::new(at, MarkerShape::Circle, Color::START_GREEN, "start")
    }

    /// The goal marker: a red star labelled "goal".
    pub fn goal(at: Point2<f64>) -> Self {
        Self::new(at, MarkerShape::Star, Color::GOAL_RED, "goal").radius(10.0)
    }

    /// Sets the radius in pixels.
    #[must_use]
    pub fn radius(mut self, radius_px: f64) -> Self {
        self.radius_px = radius_px;
        self
    }
}

#[derive(Clone, Debug, PartialEq)]
struct PointCloud {
    points: Vec<Point2<f64>>,
    color: Color,
    label: String,
}

#[derive(Clone, Debug, PartialEq)]
struct Tracks {
    tracks: Vec<Vec<Point2<f64>>>,
    color: Color,
    label: String,
}

/// A 2-D scene view with equal aspect ratio (or a chosen vertical exaggeration).
///
/// Layers, bottom to top: static shapes, point cloud, obstacle tracks, forecast rings, polylines,
/// markers. Everything is clipped to the bounds. The plot area is `width_px` minus the axis labels
/// wide and as high as the bounds' aspect ratio requires; when that height would be below 140 px
/// or above 1000 px, the bounds are widened around their centre (never cropped) so that the aspect
/// stays exact.
///
/// A point cloud is thinned to at most one point per 2 × 2-pixel cell (first point wins, in input
/// order), so 10⁶ points render as fast as the cells they cover; the number dropped is
/// [`Written::thinned_count`].
#[derive(Clone, Debug, PartialEq)]
pub struct MapView {
    title: String,
    x_label: String,
    y_label: String,
    bounds: Bounds,
    width_px: u32,
    exaggeration: f64,
    shapes: Vec<Shape>,
    shape_color: Color,
    shape_label: String,
    clouds: Vec<PointCloud>,
    tracks: Vec<Tracks>,
    forecasts: Vec<ForecastRings>,
    polylines: Vec<Polyline>,
    markers: Vec<Marker>,
    legend: bool,
}

const MIN_PLOT_H: f64 = 140.0;
const MAX_PLOT_H: f64 = 1000.0;
const MIN_PLOT_W: f64 = 320.0;
const CLOUD_CELL_PX: f64 = 2.0;

impl MapView {
    /// An empty view of `bounds`, 1000 px wide, axes titled `x [m]` and `y [m]`, legend on.
    pub fn new(title: impl Into<String>, bounds: Bounds) -> Self {
        Self {
            title: title.into(),
            x_label: "x [m]".to_string(),
            y_label: "y [m]".to_string(),
            bounds,
            width_px: 1000,
            exaggeration: 1.0,
            shapes: Vec::new(),
            shape_color: Color::DARK_GREY,
            shape_label: "static obstacles".to_string(),
            clouds: Vec::new(),
            tracks: Vec::new(),
            forecasts: Vec::new(),
            polylines: Vec::new(),
            markers: Vec::new(),
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

    /// Axis titles of a projection plane (e.g. `x [m]` and `z [m]` for [`Plane::Xz`]).
    #[must_use]
    pub fn plane(self, plane: Plane) -> Self {
        let (x, y) = plane.axis_labels();
        self.axis_labels(x, y)
    }

    /// Target image width in pixels (200–8000; default 1000).
    #[must_use]
    pub fn width_px(mut self, width_px: u32) -> Self {
        self.width_px = width_px;
        self
    }

    /// Vertical scale relative to the horizontal one (default 1: equal aspect). A side view of a
    /// long, flat world may use e.g. 4; say so in the axis title.
    #[must_use]
    pub fn vertical_exaggeration(mut self, factor: f64) -> Self {
        self.exaggeration = factor;
        self
    }

    /// Adds a filled static shape.
    #[must_use]
    pub fn shape(mut self, shape: Shape) -> Self {
        self.shapes.push(shape);
        self
    }

    /// Adds filled static shapes.
    #[must_use]
    pub fn shapes(mut self, shapes: impl IntoIterator<Item = Shape>) -> Self {
        self.shapes.extend(shapes);
        self
    }

    /// Colour and legend label of all static shapes (default dark grey, "static obstacles").
    #[must_use]
    pub fn shape_style(mut self, color: Color, label: impl Into<String>) -> Self {
        self.shape_color = color;
        self.shape_label = label.into();
        self
    }

    /// Adds a point cloud (thinned for drawing, see the type's docs).
    #[must_use]
    pub fn point_cloud(
        mut self,
        points: Vec<Point2<f64>>,
        color: Color,
        label: impl Into<String>,
    ) -> Self {
        self.clouds.push(PointCloud {
            points,
            color,
            label: label.into(),
        });
        self
    }

    /// Adds obstacle tracks: thin polylines sharing one colour and one legend entry.
    #[must_use]
    pub fn tracks(
        mut self,
        tracks: Vec<Vec<Point2<f64>>>,
        color: Color,
        label: impl Into<String>,
    ) -> Self {
        self.tracks.push(Tracks {
            tracks,
            color,
            label: label.into(),
        });
        self
    }

    /// Adds the rings of one obstacle's forecast.
    #[must_use]
    pub fn forecast(mut self, rings: ForecastRings) -> Self {
        self.forecasts.push(rings);
        self
    }

    /// Adds a polyline.
    #[must_use]
    pub fn polyline(mut self, polyline: Polyline) -> Self {
        self.polylines.push(polyline);
        self
    }

    /// Adds a marker (see [`Marker::start`] and [`Marker::goal`]).
    #[must_use]
    pub fn marker(mut self, marker: Marker) -> Self {
        self.markers.push(marker);
        self
    }

    /// Shows or hides the legend (shown below the plot by default).
    #[must_use]
    pub fn legend(mut self, show: bool) -> Self {
        self.legend = show;
        self
    }

    /// Whether any item has finite coordinates (whether or not it lies inside the bounds).
    fn has_finite_item(&self) -> bool {
        self.shapes.iter().any(|s| match s {
            Shape::Circle { center, radius } => {
                finite(center) && radius.is_finite() && *radius >= 0.0
            }
            Shape::Rect { min, max } => finite(min) && finite(max),
        }) || self.clouds.iter().any(|c| c.points.iter().any(finite))
            || self
                .tracks
                .iter()
                .flat_map(|t| &t.tracks)
                .any(|t| t.iter().any(finite))
            || self
                .forecasts
                .iter()
                .flat_map(|f| &f.rings)
                .any(|(c, r)| finite(c) && r.is_finite() && *r >= 0.0)
            || self.polylines.iter().any(|p| p.points.iter().any(finite))
            || self
                .markers
                .iter()
                .any(|m| finite(&m.at) && m.radius_px.is_finite())
    }

    fn polyline_color(&self, index: usize) -> Color {
        let uncoloured_before = self.polylines[..index]
            .iter()
            .filter(|p| p.color.is_none())
            .count();
        self.polylines[index]
            .color
            .unwrap_or_else(|| Color::palette(uncoloured_before))
    }

    fn legend_entries(&self) -> Legend {
        let mut legend = Legend::default();
        if !self.legend {
            return legend;
        }
        if !self.shapes.is_empty() {
            legend.add(
                &self.shape_label,
                Swatch::Fill {
                    color: self.shape_color.alpha(SHAPE_ALPHA),
                },
            );
        }
        for c in &self.clouds {
            legend.add(
                &c.label,
                Swatch::Dots {
                    color: c.color.alpha(CLOUD_ALPHA),
                },
            );
        }
        for t in &self.tracks {
            legend.add(
                &t.label,
                Swatch::Line {
                    color: t.color.opaque(),
                    width: 1,
                    dashed: false,
                },
            );
        }
        for f in &self.forecasts {
            legend.add(
                &f.label,
                Swatch::Ring {
                    color: f.color.alpha(f.alpha_first.max(f.alpha_last)),
                    radius: 8,
                },
            );
        }
        for (i, p) in self.polylines.iter().enumerate() {
            legend.add(
                &p.label,
                Swatch::Line {
                    color: self.polyline_color(i).opaque(),
                    width: p.width_px,
                    dashed: p.dashed,
                },
            );
        }
        for m in &self.markers {
            legend.add(
                &m.label,
                Swatch::Marker {
                    shape: m.shape,
                    color: m.color.opaque(),
                },
            );
        }
        legend
    }
}

const SHAPE_ALPHA: f64 = 0.8;
const CLOUD_ALPHA: f64 = 0.7;

fn finite(p: &Point2<f64>) -> bool {
    p.x.is_finite() && p.y.is_finite()
}

fn tuples(points: &[Point2<f64>]) -> Vec<(f64, f64)> {
    points.iter().map(|p| (p.x, p.y)).collect()
}

/// Layout and preprocessed data of a [`MapView`].
pub(crate) struct MapPlan {
    frame: Frame,
    x: Axis,
    y: Axis,
    legend: Legend,
    legend_layout: LegendLayout,
    /// Kept cloud points per cloud, in input order.
    clouds: Vec<Vec<(f64, f64)>>,
}

impl Render for MapView {
    type Plan = MapPlan;

    fn prepare(&self) -> Result<Prepared<MapPlan>, InputError> {
        let b = &self.bounds;
        if !(finite(&b.min) && finite(&b.max)) {
            return Err(InputError::invalid("bounds", b, "finite corners"));
        }
        if !(200..=8000).contains(&self.width_px) {
            return Err(InputError::invalid(
                "width_px",
                self.width_px,
                "200 to 8000",
            ));
        }
        let k = self.exaggeration;
        if !(k.is_finite() && k > 0.0) {
            return Err(InputError::invalid(
                "vertical_exaggeration",
                k,
                "a finite factor > 0",
            ));
        }
        if !self.has_finite_item() {
            return Err(InputError::NoData(
                "the map has no shape, point, track, forecast, polyline or marker with finite coordinates"
                    .to_string(),
            ));
        }
        let (x0, x1) = axis::pad_degenerate(b.min.x.min(b.max.x), b.min.x.max(b.max.x));
        let (y0, y1) = axis::pad_degenerate(b.min.y.min(b.max.y), b.min.y.max(b.max.y));
        let (mut dx, mut dy) = (x1 - x0, y1 - y0);
        let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));

        // Provisional y labels decide the label width, hence the plot width.
        let provisional = Axis::new(y0, y1, 8);
        let labels: Vec<String> = provisional
            .ticks
            .iter()
            .map(|t| provisional.label(*t))
            .collect();
        let ylw = frame::y_label_width(labels.iter().map(String::as_str));
        let avail_w = f64::from(
            self.width_px
                .saturating_sub(frame::MARGIN_L + frame::MARGIN_R + ylw),
        )
        .max(MIN_PLOT_W);

        let mut plot_w = avail_w;
        let mut plot_h = plot_w * dy * k / dx;
        if plot_h < MIN_PLOT_H {
            plot_h = MIN_PLOT_H;
        } else if plot_h > MAX_PLOT_H {
            plot_h = MAX_PLOT_H;
            plot_w = (MAX_PLOT_H * dx / (dy * k)).max(MIN_PLOT_W);
        }
        let (pw, ph) = (plot_w.round(), plot_h.round());
        // Widen (never crop) the ranges so that pixels per unit match exactly (times k vertically).
        let scale = (pw / dx).min(ph / (dy * k));
        dx = pw / scale;
        dy = ph / (scale * k);
        let x = Axis::new(cx - 0.5 * dx, cx + 0.5 * dx, ((pw / 110.0) as usize).max(2));
        let y = Axis::new(cy - 0.5 * dy, cy + 0.5 * dy, ((ph / 60.0) as usize).max(2));

        let y_labels: Vec<String> = y.ticks.iter().map(|t| y.label(*t)).collect();
        let mut frame = Frame::new(
            pw as u32,
            ph as u32,
            y_labels.iter().map(String::as_str),
            &self.x_label,
        );
        let legend = self.legend_entries();
        let legend_layout = legend.layout(frame.width());
        frame.legend_h = legend_layout.height();

        // Thin the point clouds on a grid of pixel cells.
        let rect = Rect::of(&x, &y);
        let cols = (pw / CLOUD_CELL_PX).ceil() as usize + 1;
        let rows = (ph / CLOUD_CELL_PX).ceil() as usize + 1;
        let mut skipped = 0usize;
        let mut thinned = 0usize;
        let mut clouds = Vec::with_capacity(self.clouds.len());
        for cloud in &self.clouds {
            let mut occupied = vec![false; cols * rows];
            let mut kept = Vec::new();
            for p in &cloud.points {
                if !finite(p) {
                    skipped += 1;
                    continue;
                }
                if !rect.contains((p.x, p.y)) {
                    continue;
                }
                let c = (((p.x - x.lo) / dx * pw) / CLOUD_CELL_PX) as usize;
                let r = (((y.hi - p.y) / dy * ph) / CLOUD_CELL_PX) as usize;
                let cell = r.min(rows - 1) * cols + c.min(cols - 1);
                if occupied[cell] {
                    thinned += 1;
                } else {
                    occupied[cell] = true;
                    kept.push((p.x, p.y));
                }
            }
            clouds.push(kept);
        }
        skipped += self.count_skipped();

        let size = frame.size();
        Ok(Prepared {
            plan: MapPlan {
                frame,
                x,
                y,
                legend,
                legend_layout,
                clouds,
            },
            size,
            skipped_count: skipped,
            thinned_count: thinned,
        })
    }

    fn draw<DB: DrawingBackend>(
        &self,
        plan: &MapPlan,
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
        let px_per_unit = f64::from(plan.frame.plot_w) / (x.hi - x.lo);

        // Static shapes.
        let shape_style = filled(self.shape_color.alpha(SHAPE_ALPHA));
        for shape in &self.shapes {
            let poly = match *shape {
                Shape::Circle { center, radius } => {
                    if !(finite(&center) && radius.is_finite() && radius >= 0.0) {
                        continue;
                    }
                    let n = ((radius * px_per_unit).ceil() as usize).clamp(16, 128);
                    axis::circle_polygon((center.x, center.y), radius, n)
                }
                Shape::Rect { min, max } => {
                    if !(finite(&min) && finite(&max)) {
                        continue;
                    }
                    vec![
                        (min.x, min.y),
                        (max.x, min.y),
                        (max.x, max.y),
                        (min.x, max.y),
                    ]
                }
            };
            let clipped = axis::clip_polygon(&poly, &rect);
            if clipped.len() >= 3 {
                area.draw(&Polygon::new(clipped, shape_style))?;
            }
        }

        // Point clouds: one small square per kept cell.
        for (cloud, kept) in self.clouds.iter().zip(&plan.clouds) {
            let style = filled(cloud.color.alpha(CLOUD_ALPHA));
            for p in kept {
                let (px, py) = chart.backend_coord(p);
                root.draw(&Rectangle::new([(px, py), (px + 1, py + 1)], style))?;
            }
        }

        // Obstacle tracks.
        for t in &self.tracks {
            let style = stroke(t.color.opaque(), 1);
            for track in &t.tracks {
                for run in axis::clip_polyline(&tuples(track), &rect).0 {
                    area.draw(&PathElement::new(run, style))?;
                }
            }
        }

        // Forecast rings, fading along the forecast.
        for f in &self.forecasts {
            let n = f.rings.len();
            for (i, (c, r)) in f.rings.iter().enumerate() {
                if !(finite(c) && r.is_finite() && *r >= 0.0) {
                    continue;
                }
                let s = if n > 1 {
                    i as f64 / (n - 1) as f64
                } else {
                    0.0
                };
                let alpha = f.alpha_first + (f.alpha_last - f.alpha_first) * s;
                let m = ((r * px_per_unit).ceil() as usize).clamp(16, 128);
                let mut ring = axis::circle_polygon((c.x, c.y), *r, m);
                ring.push(ring[0]);
                for run in axis::clip_polyline(&ring, &rect).0 {
                    area.draw(&PathElement::new(run, stroke(f.color.alpha(alpha), 2)))?;
                }
            }
        }

        // Polylines.
        for (i, p) in self.polylines.iter().enumerate() {
            let style = stroke(self.polyline_color(i).opaque(), p.width_px);
            for run in axis::clip_polyline(&tuples(&p.points), &rect).0 {
                if run.len() == 1 {
                    let (px, py) = chart.backend_coord(&run[0]);
                    draw_marker(
                        root,
                        (px, py),
                        MarkerShape::Circle,
                        2.0 + f64::from(p.width_px),
                        style.color,
                    )?;
                } else if p.dashed {
                    area.draw(&plotters::element::DashedPathElement::new(run, 8, 5, style))?;
                } else {
                    area.draw(&PathElement::new(run, style))?;
                }
            }
        }

        // Markers.
        for m in &self.markers {
            if finite(&m.at) && rect.contains((m.at.x, m.at.y)) && m.radius_px.is_finite() {
                let at = chart.backend_coord(&(m.at.x, m.at.y));
                draw_marker(
                    root,
                    at,
                    m.shape,
                    m.radius_px.clamp(1.0, 100.0),
                    m.color.opaque(),
                )?;
            }
        }

        frame::border(&chart, x, y)?;
        legend::draw(&plan.legend, &plan.legend_layout, &legend_area)
    }
}

impl MapView {
    /// Items skipped for non-finite coordinates or negative radii (point-cloud points are counted
    /// while thinning).
    fn count_skipped(&self) -> usize {
        let shapes = self
            .shapes
            .iter()
            .filter(|s| match s {
                Shape::Circle { center, radius } => {
                    !(finite(center) && radius.is_finite() && *radius >= 0.0)
                }
                Shape::Rect { min, max } => !(finite(min) && finite(max)),
            })
            .count();
        let tracks: usize = self
            .tracks
            .iter()
            .flat_map(|t| &t.tracks)
            .map(|t| t.iter().filter(|p| !finite(p)).count())
            .sum();
        let rings: usize = self
            .forecasts
            .iter()
            .flat_map(|f| &f.rings)
            .filter(|(c, r)| !(finite(c) && r.is_finite() && *r >= 0.0))
            .count();
        let lines: usize = self
            .polylines
            .iter()
            .map(|p| p.points.iter().filter(|q| !finite(q)).count())
            .sum();
        let markers = self
            .markers
            .iter()
            .filter(|m| !(finite(&m.at) && m.radius_px.is_finite()))
            .count();
        shapes + tracks + rings + lines + markers
    }
}

impl Figure for MapView {
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

    fn plan(view: &MapView) -> MapPlan {
        view.prepare().expect("valid view").plan
    }

    fn scales(p: &MapPlan) -> (f64, f64) {
        (
            f64::from(p.frame.plot_w) / (p.x.hi - p.x.lo),
            f64::from(p.frame.plot_h) / (p.y.hi - p.y.lo),
        )
    }

    fn view(w: f64, h: f64) -> MapView {
        MapView::new("t", Bounds::new(Point2::new(0.0, 0.0), Point2::new(w, h)))
            .marker(Marker::start(Point2::origin()))
    }

    #[test]
    fn pixels_per_metre_are_equal_on_both_axes_and_bounds_are_never_cropped() {
        for (w, h) in [
            (250.0, 75.0),
            (75.0, 75.0),
            (250.0, 5.0),
            (10.0, 400.0),
            (1e-3, 2e-3),
        ] {
            let p = plan(&view(w, h));
            let (sx, sy) = scales(&p);
            assert!((sx / sy - 1.0).abs() < 1e-9, "{w}x{h}: {sx} vs {sy}");
            assert!(
                p.x.lo <= 0.0 && p.x.hi >= w && p.y.lo <= 0.0 && p.y.hi >= h,
                "{w}x{h} cropped"
            );
            assert!(
                (140..=1000).contains(&p.frame.plot_h),
                "{w}x{h}: plot height {}",
                p.frame.plot_h
            );
        }
    }

    #[test]
    fn a_wide_world_gets_a_wide_plot() {
        let p = plan(&view(250.0, 75.0));
        let ratio = f64::from(p.frame.plot_w) / f64::from(p.frame.plot_h);
        assert!((ratio - 250.0 / 75.0).abs() < 0.02, "{ratio}");
    }

    #[test]
    fn vertical_exaggeration_scales_the_vertical_axis() {
        let p = plan(&view(250.0, 30.0).vertical_exaggeration(4.0));
        let (sx, sy) = scales(&p);
        assert!((sy / sx - 4.0).abs() < 1e-9, "{sx} {sy}");
    }
}

//! Figures of one flight (`trust-sim run` writes them next to the run log): top and side views
//! with the static obstacles, the obstacle tracks, the flown path and snapshots of the plan;
//! speed and acceleration against the limits; clearance over time.

use std::path::Path;

use nalgebra::{Point2, Vector3};

use trust_flight::FlightRecord;
use trust_plot::{
    Bounds, Color, Figure, HLine, MapView, Marker, Plane, PlotError, Polyline, Series, Shape,
    TimeSeries, Written,
};
use trust_runlog::{Header, StateRecord, StaticShape};

/// Most points of the planner's cloud drawn (the view thins them further).
const MAX_CLOUD_POINTS: usize = 200_000;

fn p3(a: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

/// A static shape of a run log projected on `plane` for a [`MapView`].
pub fn static_shape(plane: Plane, s: &StaticShape) -> Shape {
    match (*s, plane) {
        (StaticShape::Sphere { center, radius }, _) => Shape::Circle {
            center: plane.project(&p3(&center)),
            radius,
        },
        (StaticShape::Cylinder { center, radius, .. }, Plane::Xy) => Shape::Circle {
            center: Point2::new(center[0], center[1]),
            radius,
        },
        (
            StaticShape::Cylinder {
                center,
                radius,
                z_min,
                z_max,
            },
            Plane::Xz,
        ) => Shape::Rect {
            min: Point2::new(center[0] - radius, z_min),
            max: Point2::new(center[0] + radius, z_max),
        },
        (
            StaticShape::Cylinder {
                center,
                radius,
                z_min,
                z_max,
            },
            Plane::Yz,
        ) => Shape::Rect {
            min: Point2::new(center[1] - radius, z_min),
            max: Point2::new(center[1] + radius, z_max),
        },
        (StaticShape::Box { min, max }, _) => Shape::Rect {
            min: plane.project(&p3(&min)),
            max: plane.project(&p3(&max)),
        },
    }
}

/// The map of a run log's world on `plane`: bounds, axis labels and the true static shapes.
pub(crate) fn base_view(header: &Header, plane: Plane, title: &str) -> MapView {
    let lo = plane.project(&p3(&header.bounds.min));
    let hi = plane.project(&p3(&header.bounds.max));
    let (xl, yl) = plane.axis_labels();
    MapView::new(title, Bounds::new(lo, hi))
        .plane(plane)
        .axis_labels(xl, yl)
        .shapes(header.static_shapes.iter().map(|s| static_shape(plane, s)))
        .shape_style(Color::rgb(150, 150, 150), "static obstacles")
}

fn view(
    header: &Header,
    record: &FlightRecord,
    cloud: Option<&[trust_core::Vec3]>,
    plane: Plane,
    title: &str,
) -> MapView {
    let mut v = base_view(header, plane, title);
    if let Some(points) = cloud {
        let stride = points.len().div_ceil(MAX_CLOUD_POINTS).max(1);
        let pts = points
            .iter()
            .step_by(stride)
            .map(|p| plane.project(p))
            .collect();
        v = v.point_cloud(pts, Color::rgb(120, 120, 120), "static point cloud");
    }
    let n = header.obstacles.len();
    let tracks: Vec<Vec<Point2<f64>>> = (0..n)
        .map(|i| {
            record
                .states
                .iter()
                .map(|s| plane.project(&p3(&s.obstacles[i])))
                .collect()
        })
        .collect();
    if n > 0 {
        v = v.tracks(tracks, Color::rgb(230, 140, 100), "moving obstacles (true)");
    }
    for (k, plan) in record.plans.iter().enumerate() {
        let steps = 40;
        let pts = (0..=steps)
            .map(|j| {
                let t = plan.t_start() + plan.duration() * j as f64 / steps as f64;
                plane.project(&plan.position(t))
            })
            .collect();
        let mut line = Polyline::new(pts)
            .color(Color::rgb(90, 160, 220))
            .width_px(1)
            .dashed();
        if k == 0 {
            line = line.label("plan (every 1 s)");
        }
        v = v.polyline(line);
    }
    // The global route (issue 19): the first one planned, and the last if the manager re-planned.
    let routes: Vec<&Vec<[f64; 3]>> = record
        .cycles
        .iter()
        .filter_map(|c| c.route.as_ref())
        .collect();
    let shown: Vec<(&Vec<[f64; 3]>, &str, Color)> = match routes.as_slice() {
        [] => vec![],
        [only] => vec![(only, "global route", Color::rgb(40, 160, 70))],
        [first, .., last] => vec![
            (first, "global route (first)", Color::rgb(40, 160, 70)),
            (
                last,
                "global route (last re-plan)",
                Color::rgb(150, 90, 200),
            ),
        ],
    };
    for (route, label, color) in shown {
        let pts = route.iter().map(|p| plane.project(&p3(p))).collect();
        v = v.polyline(
            Polyline::new(pts)
                .label(label)
                .color(color)
                .width_px(2)
                .dashed(),
        );
    }
    let flown = record
        .states
        .iter()
        .map(|s| plane.project(&p3(&s.p)))
        .collect();
    v.polyline(
        Polyline::new(flown)
            .label("flown")
            .color(Color::rgb(20, 20, 120))
            .width_px(2),
    )
    .marker(Marker::start(plane.project(&p3(&header.start))))
    .marker(Marker::goal(plane.project(&p3(&header.goal))))
}

/// Writes `top`, `side`, `speed`, `acceleration` and `clearance` (SVG + PNG) into `dir`;
/// `cloud` is the planner's static point cloud, if it sees one.
///
/// # Errors
/// [`PlotError`] naming the file.
pub fn write_flight_plots(
    dir: &Path,
    header: &Header,
    record: &FlightRecord,
    cloud: Option<&[trust_core::Vec3]>,
) -> Result<Vec<Written>, PlotError> {
    let title = format!(
        "{} — {} (seed {})",
        header.scenario, header.planner, header.seed
    );
    let mut written = vec![
        view(
            header,
            record,
            cloud,
            Plane::Xy,
            &format!("{title}: top view"),
        )
        .write(dir, "top")?,
        view(
            header,
            record,
            cloud,
            Plane::Xz,
            &format!("{title}: side view"),
        )
        .write(dir, "side")?,
    ];
    let series = |f: &dyn Fn(&trust_runlog::StateRecord) -> f64| -> Vec<(f64, f64)> {
        record.states.iter().map(|s| (s.t, f(s))).collect()
    };
    let norm = |v: &[f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    written.push(
        TimeSeries::new(format!("{title}: speed"))
            .axis_labels("t [s]", "|v| [m/s]")
            .series(Series::new("speed", series(&|s| norm(&s.v))))
            .limit(HLine::new(
                format!("v_max = {} m/s", header.limits.v_max),
                header.limits.v_max,
            ))
            .write(dir, "speed")?,
    );
    written.push(
        TimeSeries::new(format!("{title}: acceleration"))
            .axis_labels("t [s]", "|a| [m/s²]")
            .series(Series::new("acceleration", series(&|s| norm(&s.a))))
            .limit(HLine::new(
                format!("a_max = {} m/s²", header.limits.a_max),
                header.limits.a_max,
            ))
            .write(dir, "acceleration")?,
    );
    let times: Vec<f64> = record.states.iter().map(|s| s.t).collect();
    let clip = |c: f64| c.min(10.0);
    let mut clearance = TimeSeries::new(format!("{title}: clearance (vehicle surface)"))
        .axis_labels("t [s]", "clearance [m] (capped at 10)")
        .limit(HLine::new("collision", 0.0));
    if !header.static_shapes.is_empty() || header.static_points_file.is_some() {
        clearance = clearance.series(Series::new(
            "static",
            times
                .iter()
                .zip(&record.static_clearance)
                .map(|(t, c)| (*t, clip(*c)))
                .collect(),
        ));
    }
    if !header.obstacles.is_empty() {
        clearance = clearance.series(Series::new(
            "moving obstacles",
            times
                .iter()
                .zip(&record.dynamic_clearance)
                .map(|(t, c)| (*t, clip(*c)))
                .collect(),
        ));
    }
    if !header.static_shapes.is_empty()
        || header.static_points_file.is_some()
        || !header.obstacles.is_empty()
    {
        written.push(clearance.write(dir, "clearance")?);
    }
    Ok(written)
}

/// A top view of one world with several flights over it (the static obstacles of `header`, the
/// first flight's true obstacle tracks, and each flight's path in its own colour): the
/// representative trial of a study. `flights` holds `(label, states)` pairs.
///
/// # Errors
/// [`PlotError`] naming the file.
pub fn write_comparison_view(
    dir: &Path,
    name: &str,
    title: &str,
    header: &Header,
    flights: &[(String, &[StateRecord])],
) -> Result<Written, PlotError> {
    let plane = Plane::Xy;
    let mut v = base_view(header, plane, title);
    if let Some((_, states)) = flights.first() {
        let n = header.obstacles.len();
        if n > 0 {
            let tracks: Vec<Vec<Point2<f64>>> = (0..n)
                .map(|i| {
                    states
                        .iter()
                        .filter_map(|s| s.obstacles.get(i))
                        .map(|o| plane.project(&p3(o)))
                        .collect()
                })
                .collect();
            v = v.tracks(tracks, Color::rgb(240, 190, 160), "moving obstacles (true)");
        }
    }
    for (k, (label, states)) in flights.iter().enumerate() {
        let pts = states.iter().map(|s| plane.project(&p3(&s.p))).collect();
        v = v.polyline(
            Polyline::new(pts)
                .label(label.clone())
                .color(Color::palette(k))
                .width_px(2),
        );
    }
    v.marker(Marker::start(plane.project(&p3(&header.start))))
        .marker(Marker::goal(plane.project(&p3(&header.goal))))
        .write(dir, name)
}

//! The animated GIF of the top view, drawn with `trust-plot`.

use std::path::Path;

use nalgebra::Point2;
use trust_plot::{
    Bounds, Color, ForecastRings, GifWritten, MapView, Marker, MarkerShape, Polyline, Shape,
    write_gif,
};
use trust_runlog::{CycleRecord, Header, RunLog, StateRecord, StaticShape};

use crate::data::{Item, geometry, visit_log};
use crate::{GifParams, ReplayError};

fn xy(p: &[f64; 3]) -> Point2<f64> {
    Point2::new(p[0], p[1])
}

/// The `route` polyline of a serialized header or cycle record (`[[x, y, z], ...]`), if it has
/// one: the run log's optional global route, drawn when present.
pub(crate) fn route_of(record: &serde_json::Value) -> Option<Vec<Point2<f64>>> {
    record
        .get("route")?
        .as_array()?
        .iter()
        .map(|p| {
            let a = p.as_array()?;
            Some(Point2::new(a.first()?.as_f64()?, a.get(1)?.as_f64()?))
        })
        .collect()
}

/// The times of the frames: from the first state to the last, `frame_step_s` apart at least and
/// at most `max_frames` of them; the last frame is the last state.
fn frame_times(t0: f64, t1: f64, params: &GifParams) -> Vec<f64> {
    let span = (t1 - t0).max(0.0);
    let slots = (params.max_frames - 1).max(1) as f64;
    let step = params.frame_step_s.max(span / slots);
    let n = if step > 0.0 {
        (span / step).floor() as usize
    } else {
        0
    };
    let mut times: Vec<f64> = (0..=n).map(|k| t0 + k as f64 * step).collect();
    if times.last().is_some_and(|&t| t1 - t > 1e-9) {
        if times.len() >= params.max_frames {
            times.pop();
        }
        times.push(t1);
    }
    times
}

pub(crate) fn check(params: &GifParams) -> Result<(), ReplayError> {
    let invalid = |field, value: String, expected| {
        Err(ReplayError::InvalidParam {
            field,
            value,
            expected,
        })
    };
    if !(params.frame_step_s.is_finite() && params.frame_step_s > 0.0) {
        return invalid(
            "gif.frame_step_s",
            params.frame_step_s.to_string(),
            "a finite number > 0",
        );
    }
    if params.max_frames < 2 {
        return invalid("gif.max_frames", params.max_frames.to_string(), "≥ 2");
    }
    if !(200..=8000).contains(&params.width_px) {
        return invalid("gif.width_px", params.width_px.to_string(), "200 to 8000");
    }
    Ok(())
}

/// The latest state, cycle and route at one frame's time, and the path flown until then.
#[derive(Debug, Clone)]
struct Snapshot {
    state: StateRecord,
    cycle: Option<CycleRecord>,
    route: Option<Vec<Point2<f64>>>,
    flown: Vec<Point2<f64>>,
}

/// Most points of a frame's flown path (one per 0.1 s, the spacing doubling beyond).
const MAX_FLOWN_POINTS: usize = 4_000;

/// Collects the frames' snapshots from the records in log order, in bounded memory: the
/// latest state, cycle and route, and the flown path thinned to [`MAX_FLOWN_POINTS`].
pub(crate) struct FrameCollector {
    times: Vec<f64>,
    next: usize,
    latest: Option<StateRecord>,
    cycle: Option<CycleRecord>,
    route: Option<Vec<Point2<f64>>>,
    flown: Vec<Point2<f64>>,
    flown_step: f64,
    flown_next_t: f64,
    snapshots: Vec<Snapshot>,
    has_route: bool,
    has_regions: bool,
}

impl FrameCollector {
    /// Frames of a flight whose states span `t0` to `t1` ([`frame_times`]).
    pub(crate) fn new(t0: f64, t1: f64, params: &GifParams) -> Self {
        FrameCollector {
            times: frame_times(t0, t1, params),
            next: 0,
            latest: None,
            cycle: None,
            route: None,
            flown: Vec::new(),
            flown_step: 0.1,
            flown_next_t: f64::NEG_INFINITY,
            snapshots: Vec::new(),
            has_route: false,
            has_regions: false,
        }
    }

    /// Takes the snapshots of the frames before `t`.
    fn capture_before(&mut self, t: f64) {
        while self.next < self.times.len() && self.times[self.next] < t - 1e-9 {
            if let Some(s) = &self.latest {
                let mut flown = self.flown.clone();
                flown.push(xy(&s.p));
                self.snapshots.push(Snapshot {
                    state: s.clone(),
                    cycle: self.cycle.clone(),
                    route: self.route.clone(),
                    flown,
                });
            }
            self.next += 1;
        }
    }

    pub(crate) fn item(&mut self, item: Item<'_>) {
        match item {
            Item::State(s) => {
                self.capture_before(s.t);
                if s.t >= self.flown_next_t - 1e-9 {
                    self.flown.push(xy(&s.p));
                    self.flown_next_t = s.t + self.flown_step;
                    if self.flown.len() > MAX_FLOWN_POINTS {
                        let mut k = 0;
                        self.flown.retain(|_| {
                            k += 1;
                            k % 2 == 1
                        });
                        self.flown_step *= 2.0;
                    }
                }
                self.latest = Some(s.clone());
            }
            Item::Cycle(c) => {
                self.capture_before(c.t);
                if let Some(r) = &c.route {
                    self.route = Some(r.iter().map(xy).collect());
                    self.has_route = true;
                }
                self.has_regions |= c
                    .forecasts
                    .as_ref()
                    .is_some_and(|fs| fs.iter().any(|f| f.walls.is_some()));
                self.cycle = Some(c.clone());
            }
        }
    }

    fn finish(mut self) -> (Vec<Snapshot>, bool, bool) {
        self.capture_before(f64::INFINITY);
        (self.snapshots, self.has_route, self.has_regions)
    }
}

/// Writes the top view of `log`'s flight (read from a file in `log_dir`) as an animated GIF at
/// `path`: per frame the static geometry, the flown path so far, the true obstacles, the
/// forecasts of the latest cycle at their current radius (and dashed the regions whose walls the
/// planner mirrors them at, when the log has any), its branches (main thick, the others
/// thin and dashed), start, goal and the vehicle; the title carries the time and the cycle's
/// events. Frames are `params.frame_step_s` of simulated time apart (more for long flights, at
/// most `params.max_frames`); the static points are thinned to 20 000.
///
/// # Errors
/// [`ReplayError::InvalidParam`], [`ReplayError::Points`], [`ReplayError::Plot`].
pub fn write_top_view_gif(
    log: &RunLog,
    log_dir: &Path,
    path: &Path,
    params: &GifParams,
) -> Result<GifWritten, ReplayError> {
    check(params)?;
    let (cloud, _) = geometry(&log.header, log_dir, 20_000)?;
    let states = &log.states;
    let mut frames = FrameCollector::new(states[0].t, states[states.len() - 1].t, params);
    visit_log(log, &mut |item| {
        frames.item(item);
        Ok(())
    })?;
    draw_gif(&log.header, &cloud, frames, path, params)
}

/// Draws the collected frames (see [`write_top_view_gif`]).
pub(crate) fn draw_gif(
    h: &Header,
    cloud: &[[f64; 3]],
    frames: FrameCollector,
    path: &Path,
    params: &GifParams,
) -> Result<GifWritten, ReplayError> {
    check(params)?;
    let (snapshots, has_route, has_regions) = frames.finish();
    let bounds = Bounds::new(xy(&h.bounds.min), xy(&h.bounds.max));
    let shapes: Vec<Shape> = h
        .static_shapes
        .iter()
        .map(|s| match *s {
            StaticShape::Sphere { center, radius } => Shape::Circle {
                center: xy(&center),
                radius,
            },
            StaticShape::Cylinder { center, radius, .. } => Shape::Circle {
                center: Point2::new(center[0], center[1]),
                radius,
            },
            StaticShape::Box { min, max } => Shape::Rect {
                min: xy(&min),
                max: xy(&max),
            },
        })
        .collect();
    let cloud: Vec<Point2<f64>> = cloud.iter().map(xy).collect();
    let header_route = serde_json::to_value(h).ok().and_then(|v| route_of(&v));
    let has_route = has_route || header_route.is_some();
    let truth_color = Color::rgb(204, 51, 17);
    let forecast_color = Color::rgb(238, 153, 0);
    let main_color = Color::rgb(0, 90, 200);
    let path_color = Color::BLACK;
    let mut frames = Vec::with_capacity(snapshots.len());
    for snap in snapshots {
        let s = &snap.state;
        let cycle = snap.cycle.as_ref();
        let events = cycle
            .map(|c| {
                c.events
                    .iter()
                    .filter(|e| {
                        matches!(
                            e.as_str(),
                            "switched" | "fallback" | "stalled" | "escaped" | "repaired"
                        )
                    })
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", ")
            })
            .unwrap_or_default();
        let title = format!(
            "{} · {} · t = {:.1} s{}{}",
            h.scenario,
            h.planner,
            s.t,
            if events.is_empty() { "" } else { " · " },
            events
        );
        let mut view = MapView::new(title, bounds)
            .width_px(params.width_px)
            .shapes(shapes.clone());
        if !cloud.is_empty() {
            view = view.point_cloud(cloud.clone(), Color::DARK_GREY, "static points");
        }
        if has_route {
            let route = snap
                .route
                .clone()
                .or_else(|| header_route.clone())
                .unwrap_or_default();
            view = view.polyline(
                Polyline::new(route)
                    .color(Color::START_GREEN)
                    .width_px(2)
                    .dashed()
                    .label("global route"),
            );
        }
        // The same legend entries in every frame, so that every frame has the same size.
        let truth: Vec<(Point2<f64>, f64)> = h
            .obstacles
            .iter()
            .zip(&s.obstacles)
            .map(|(o, c)| (xy(c), o.radius))
            .collect();
        view = view.forecast(
            ForecastRings::new(truth)
                .color(truth_color)
                .alpha(1.0, 1.0)
                .label("obstacles (truth)"),
        );
        let forecasts: Vec<(Point2<f64>, f64)> = cycle
            .and_then(|c| c.forecasts.as_ref())
            .map(|fs| {
                fs.iter()
                    .map(|f| (xy(&f.centre_at(s.t)), f.radius_at(s.t)))
                    .collect()
            })
            .unwrap_or_default();
        view = view.forecast(
            ForecastRings::new(forecasts)
                .color(forecast_color)
                .alpha(0.9, 0.9)
                .label("forecasts"),
        );
        if has_regions {
            // The regions whose walls the planner mirrors the forecasts at, one outline each;
            // an empty outline when there is none keeps the legend, and so the frame size, the
            // same in every frame.
            let mut regions: Vec<[[f64; 3]; 2]> = Vec::new();
            for w in cycle
                .and_then(|c| c.forecasts.as_ref())
                .into_iter()
                .flatten()
                .filter_map(|f| f.walls)
            {
                if !regions.contains(&w) {
                    regions.push(w);
                }
            }
            let mut outlines: Vec<Vec<Point2<f64>>> = regions
                .iter()
                .map(|[lo, hi]| {
                    vec![
                        Point2::new(lo[0], lo[1]),
                        Point2::new(hi[0], lo[1]),
                        Point2::new(hi[0], hi[1]),
                        Point2::new(lo[0], hi[1]),
                        Point2::new(lo[0], lo[1]),
                    ]
                })
                .collect();
            if outlines.is_empty() {
                outlines.push(Vec::new());
            }
            for outline in outlines {
                view = view.polyline(
                    Polyline::new(outline)
                        .color(forecast_color)
                        .width_px(1)
                        .dashed()
                        .label("obstacle regions"),
                );
            }
        }
        let branches = cycle.and_then(|c| c.branch_samples.as_ref());
        let line = |b: &trust_runlog::BranchSamples| -> Vec<Point2<f64>> {
            b.samples.iter().map(|q| Point2::new(q[1], q[2])).collect()
        };
        let mut others = 0;
        for b in branches.into_iter().flatten().skip(1) {
            view = view.polyline(
                Polyline::new(line(b))
                    .color(Color::GREY)
                    .width_px(1)
                    .dashed()
                    .label("other branches"),
            );
            others += 1;
        }
        if others == 0 {
            view = view.polyline(
                Polyline::new(Vec::new())
                    .color(Color::GREY)
                    .width_px(1)
                    .dashed()
                    .label("other branches"),
            );
        }
        let main = branches
            .and_then(|b| b.first())
            .filter(|_| cycle.is_some_and(|c| c.main.is_some()))
            .map(line)
            .unwrap_or_default();
        view = view.polyline(
            Polyline::new(main)
                .color(main_color)
                .width_px(3)
                .label("main branch"),
        );
        let flown = snap.flown;
        view = view
            .polyline(
                Polyline::new(flown)
                    .color(path_color)
                    .width_px(2)
                    .label("flown"),
            )
            .marker(Marker::start(xy(&h.start)))
            .marker(Marker::goal(xy(&h.goal)))
            .marker(Marker::new(xy(&s.p), MarkerShape::Circle, main_color, "vehicle").radius(5.0));
        frames.push(view);
    }
    Ok(write_gif(&frames, path, params.frame_delay_ms)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_route_is_read_when_a_record_has_one() {
        let with = serde_json::json!({"t": 1.0, "route": [[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]]});
        assert_eq!(
            route_of(&with),
            Some(vec![Point2::new(0.0, 1.0), Point2::new(3.0, 4.0)])
        );
        assert_eq!(route_of(&serde_json::json!({"t": 1.0})), None);
        assert_eq!(route_of(&serde_json::json!({"route": [[0.0]]})), None);
    }

    #[test]
    fn frame_times_span_the_flight_within_the_frame_budget() {
        let p = GifParams {
            frame_step_s: 0.5,
            max_frames: 10,
            ..GifParams::default()
        };
        let short = frame_times(0.0, 2.2, &p);
        assert_eq!(short, vec![0.0, 0.5, 1.0, 1.5, 2.0, 2.2]);
        let long = frame_times(0.0, 30.0, &p);
        assert!(long.len() <= 10, "{long:?}");
        assert_eq!(long.first(), Some(&0.0));
        assert_eq!(long.last(), Some(&30.0));
        assert_eq!(frame_times(1.0, 1.0, &p), vec![1.0]);
    }
}

//! The animated GIF of the top view, drawn with `trust-plot`.

use std::path::Path;

use nalgebra::Point2;
use trust_plot::{
    Bounds, Color, ForecastRings, GifWritten, MapView, Marker, MarkerShape, Polyline, Shape,
    write_gif,
};
use trust_runlog::audit::read_static_points;
use trust_runlog::{CycleRecord, RunLog, StaticShape};

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

/// The latest cycle at or before `t`.
pub(crate) fn cycle_at(cycles: &[CycleRecord], t: f64) -> Option<&CycleRecord> {
    let n = cycles.partition_point(|c| c.t <= t + 1e-9);
    n.checked_sub(1).map(|i| &cycles[i])
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

fn check(params: &GifParams) -> Result<(), ReplayError> {
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

/// Writes the top view of `log`'s flight (read from a file in `log_dir`) as an animated GIF at
/// `path`: per frame the static geometry, the flown path so far, the true obstacles, the
/// forecasts of the latest cycle at their current radius (and dashed the regions whose walls the
/// planner mirrors them at, when the log has any), its branches (main thick, the others
/// thin and dashed), start, goal and the vehicle; the title carries the time and the cycle's
/// events. Frames are `params.frame_step_s` of simulated time apart (more for long flights, at
/// most `params.max_frames`).
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
    let h = &log.header;
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
    let cloud: Vec<Point2<f64>> = match &h.static_points_file {
        Some(f) => read_static_points(&log_dir.join(f))
            .map_err(|message| ReplayError::Points { message })?
            .iter()
            .map(xy)
            .collect(),
        None => Vec::new(),
    };
    let header_route = serde_json::to_value(h).ok().and_then(|v| route_of(&v));
    let cycle_routes: Vec<Option<Vec<Point2<f64>>>> = log
        .cycles
        .iter()
        .map(|c| serde_json::to_value(c).ok().and_then(|v| route_of(&v)))
        .collect();
    let has_route = header_route.is_some() || cycle_routes.iter().any(Option::is_some);
    let has_regions = log.cycles.iter().any(|c| {
        c.forecasts
            .as_ref()
            .is_some_and(|fs| fs.iter().any(|f| f.walls.is_some()))
    });
    let states = &log.states;
    let times = frame_times(states[0].t, states[states.len() - 1].t, params);
    let truth_color = Color::rgb(204, 51, 17);
    let forecast_color = Color::rgb(238, 153, 0);
    let main_color = Color::rgb(0, 90, 200);
    let path_color = Color::BLACK;
    let mut frames = Vec::with_capacity(times.len());
    for &t in &times {
        let k = states.partition_point(|s| s.t <= t + 1e-9).max(1) - 1;
        let s = &states[k];
        let cycle = cycle_at(&log.cycles, t);
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
            let n = log.cycles.partition_point(|c| c.t <= t + 1e-9);
            let route = cycle_routes[..n]
                .iter()
                .rev()
                .find_map(Clone::clone)
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
        let flown: Vec<Point2<f64>> = states[..=k].iter().map(|s| xy(&s.p)).collect();
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

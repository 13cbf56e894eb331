//! Greedy line-of-sight shortcutting of a roadmap path (Fast-Planner's `shortcutPath` behaviour).
//!
//! The path is discretized at the resolution; walking along it, the current anchor jumps to a far
//! point it sees (found by galloping search and bisection rather than the anchor's point-by-point
//! walk, which needs a visibility test per point). Where the sight line to the next point is blocked, the first blocked point
//! of that line is pushed one resolution step along the obstacle distance gradient's component
//! orthogonal to the line; the pushed point becomes a waypoint when it is free and sees both the anchor
//! and the next point. Otherwise the last visible path point is used, so the result never leaves the
//! free space the input used.

use trust_core::{Aabb, Vec3};

use crate::visibility::Obstacles;

/// Points every `step` metres along `points` (ends and vertices' segments included; at least the
/// two ends). Non-finite or non-positive steps give the vertices; at most
/// `trust_core::scale::MAX_SAMPLE_COUNT` points in all, plus one per vertex.
pub fn discretize(points: &[Vec3], step: f64, out: &mut Vec<Vec3>) {
    out.clear();
    let Some(&first) = points.first() else {
        return;
    };
    out.push(first);
    // Total output capped at MAX_SAMPLE_COUNT points: later segments get their end vertex only.
    let cap = trust_core::scale::MAX_SAMPLE_COUNT;
    for w in points.windows(2) {
        let len = (w[1] - w[0]).norm();
        let room = cap.saturating_sub(out.len()).max(1);
        let pieces = if step.is_finite() && step > 0.0 && len.is_finite() {
            ((len / step).ceil() as usize).clamp(1, room)
        } else {
            1
        };
        for k in 1..pieces {
            out.push(w[0] + (w[1] - w[0]) * (k as f64 / pieces as f64));
        }
        out.push(w[1]);
    }
}

/// Shortcuts `points` against `obstacles`: segments must keep `threshold` from obstacles; pushed
/// waypoints must lie in `region`. The first and last points are kept exactly.
pub fn shortcut(
    points: &[Vec3],
    obstacles: &Obstacles<'_>,
    threshold: f64,
    resolution: f64,
    region: &Aabb,
) -> Vec<Vec3> {
    let mut dense = Vec::new();
    discretize(points, resolution, &mut dense);
    if dense.len() <= 2 {
        return dense;
    }
    let visible = |a: &Vec3, b: &Vec3| obstacles.segment_clear(a, b, threshold);
    let n = dense.len();
    let mut out = vec![dense[0]];
    let mut anchor = dense[0];
    // Dense points up to `behind` are behind the anchor.
    let mut behind = 0;
    let mut i = 1;
    while i < n {
        if visible(&anchor, &dense[i]) {
            i = farthest_visible(&anchor, &dense, i, &visible) + 1;
            continue;
        }
        if let Some(c) =
            pushed_waypoint(&anchor, &dense[i], obstacles, threshold, resolution, region)
                .filter(|c| visible(&anchor, c) && visible(c, &dense[i]))
        {
            out.push(c);
            anchor = c;
            behind = i - 1;
            i += 1;
            continue;
        }
        if i - 1 > behind {
            anchor = dense[i - 1];
            behind = i - 1;
            out.push(anchor);
        } else {
            // Consecutive points the input connected: keep them.
            anchor = dense[i];
            behind = i;
            out.push(anchor);
            i += 1;
        }
    }
    if out.last() != Some(&dense[n - 1]) {
        out.push(dense[n - 1]);
    }
    out
}

/// Given that `dense[seen]` is visible from `anchor`, a larger index `j` with `dense[j]` visible and
/// `dense[j + 1]` not (or the last index): galloping steps 1, 2, 4, … then bisection, so a long clear
/// stretch costs a logarithmic number of visibility tests.
fn farthest_visible(
    anchor: &Vec3,
    dense: &[Vec3],
    seen: usize,
    visible: &impl Fn(&Vec3, &Vec3) -> bool,
) -> usize {
    let last = dense.len() - 1;
    let mut good = seen;
    let mut step = 1;
    let bad = loop {
        let probe = good + step;
        if probe > last {
            if good == last || !visible(anchor, &dense[last]) {
                break last + usize::from(good == last);
            }
            return last;
        }
        if visible(anchor, &dense[probe]) {
            good = probe;
            step *= 2;
        } else {
            break probe;
        }
    };
    if bad > last {
        return last;
    }
    // Invariant: `good` visible, `bad` not.
    let (mut lo, mut hi) = (good, bad);
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if visible(anchor, &dense[mid]) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// The first point of `[a, b]` closer than `threshold` to an obstacle (found by sphere tracing: the
/// distance is 1-Lipschitz, so steps of `distance − threshold` skip no such point), pushed by
/// `resolution` along the distance gradient's component orthogonal to `b − a`.
fn pushed_waypoint(
    a: &Vec3,
    b: &Vec3,
    obstacles: &Obstacles<'_>,
    threshold: f64,
    resolution: f64,
    region: &Aabb,
) -> Option<Vec3> {
    let len = (b - a).norm();
    if len.is_nan() || len <= 0.0 || resolution.is_nan() || resolution <= 0.0 {
        return None;
    }
    let dir = (b - a) / len;
    let min_step = 0.25 * resolution;
    let mut t = 0.0_f64;
    let mut closest: Option<(f64, Vec3, Vec3)> = None;
    let (blocked, grad) = loop {
        let p = a + dir * t.min(len);
        let (d, g) = obstacles.distance_and_gradient(&p);
        if d < threshold {
            break (p, g);
        }
        if closest.is_none_or(|c| d < c.0) {
            closest = Some((d, p, g));
        }
        if t >= len {
            // Blocked between the traced points: use the closest approach.
            let (_, p, g) = closest?;
            break (p, g);
        }
        t += (d - threshold).max(min_step);
    };
    let ortho = grad - dir * grad.dot(&dir);
    let norm = ortho.norm();
    if norm.is_nan() || norm <= 1e-9 {
        return None;
    }
    let c = blocked + ortho * (resolution / norm);
    (region.contains(&c) && obstacles.is_free(&c, threshold)).then_some(c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::uvd::polyline_length;
    use trust_core::StaticMap;
    use trust_geometry::{Shape, Sphere};

    #[test]
    fn detour_is_tightened_and_stays_free() {
        let bounds =
            Aabb::new(Vec3::new(-10.0, -10.0, -10.0), Vec3::new(10.0, 10.0, 10.0)).unwrap();
        let map = StaticMap::from_shapes(
            bounds,
            vec![Shape::from(Sphere::new(Vec3::zeros(), 2.0).unwrap())],
        )
        .unwrap();
        let obs = Obstacles::new(&map);
        let path = vec![
            Vec3::new(-6.0, 0.0, 0.0),
            Vec3::new(-6.0, 6.0, 0.0),
            Vec3::new(6.0, 6.0, 0.0),
            Vec3::new(6.0, 0.0, 0.0),
        ];
        let short = shortcut(&path, &obs, 0.1, 0.1, &bounds);
        assert_eq!(short.first(), path.first());
        assert_eq!(short.last(), path.last());
        assert!(polyline_length(&short) < 0.7 * polyline_length(&path));
        for w in short.windows(2) {
            assert!(obs.segment_clear(&w[0], &w[1], 0.1), "{w:?}");
        }
        // Still above the ball (same side).
        assert!(short.iter().all(|p| p.y > -0.5));
    }

    #[test]
    fn free_path_becomes_one_segment_and_short_paths_survive() {
        let bounds = Aabb::new(Vec3::repeat(-1.0), Vec3::repeat(1.0)).unwrap();
        let map = StaticMap::new(bounds).unwrap();
        let obs = Obstacles::new(&map);
        let path = vec![
            Vec3::zeros(),
            Vec3::new(0.5, 0.5, 0.0),
            Vec3::new(0.9, 0.0, 0.0),
        ];
        assert_eq!(
            shortcut(&path, &obs, 0.1, 0.1, &bounds),
            vec![path[0], path[2]]
        );
        let tiny = vec![Vec3::zeros(), Vec3::new(0.01, 0.0, 0.0)];
        assert_eq!(shortcut(&tiny, &obs, 0.1, 0.1, &bounds), tiny);
        let single = vec![Vec3::zeros()];
        assert_eq!(shortcut(&single, &obs, 0.1, 0.1, &bounds), single);
    }
}

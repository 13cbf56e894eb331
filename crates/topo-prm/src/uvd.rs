//! Uniform visibility deformation (UVD): the homotopy test of Fast-Planner's topological planner
//! (Zhou et al., "Robust real-time UAV replanning using guided gradient-based optimization and
//! topological paths", 2020), the spatial ancestor of the paper's TVD (Sec. III-A).
//!
//! Two curves are UVD-equivalent iff, after resampling both by arc-length fraction into
//! `⌈max length / resolution⌉ + 1` points, every chord between matching points is visible. Unlike the
//! anchor, the point count never divides by zero: curves shorter than one resolution step (or of zero
//! length) are compared with two points (their ends).
//!
//! * [`equivalent`] — the free function over any [`Curve`] with a visibility closure.
//! * [`polylines_equivalent_among`] — the roadmap's test for polylines against an obstacle set,
//!   accelerated by GJK separation of whole chord ranges (same answer as testing every chord).
//! * [`Uvd`] — the [`HomotopyChecker`], against the static map and, with
//!   [`UvdParams::pdc_horizon_s`], the predictive directional cones of all forecasts, so that it also
//!   separates paths around moving obstacles.

use serde::{Deserialize, Serialize};

use trust_core::{Aabb, Curve, HomotopyChecker, PlanError, Scene, Vec3, check_positive};

use crate::gjk::{Hull, Inflated, separated_along};
use crate::visibility::{Obstacles, forecast_cones};
use trust_predict::CLEAR_TOLERANCE;

/// Upper bound on the resampled point count (guards against a tiny resolution on a huge curve).
/// The validating entry points ([`equivalent`], [`Uvd`]'s [`HomotopyChecker::equivalent`]) reject
/// curves that would need more ([`check_curves`]); the unchecked ones clamp to it.
pub const MAX_POINTS: usize = 1 << 14;

/// Checks two curves before a UVD comparison: both have points, finite lengths, and need at
/// most [`MAX_POINTS`] matched points at `resolution`. Returns that point count.
///
/// # Errors
/// [`PlanError::InvalidInput`] naming the empty or non-finite curve, [`PlanError::Count`] when the
/// longer curve divided by `resolution` exceeds [`MAX_POINTS`] (a coarser resolution or a shorter
/// curve is needed).
pub fn check_curves(a: &dyn Curve, b: &dyn Curve, resolution: f64) -> Result<usize, PlanError> {
    check_positive("uvd.resolution", resolution)?;
    let mut probe = Vec::new();
    for (name, c) in [("a", a), ("b", b)] {
        c.resample_by_arc_length(2, &mut probe);
        if probe.is_empty() {
            return Err(PlanError::invalid(
                format!("uvd curve {name}"),
                "no points",
                "a curve with at least one point",
            ));
        }
        let len = c.length();
        if !len.is_finite() || probe.iter().any(|p| !p.iter().all(|x| x.is_finite())) {
            return Err(PlanError::invalid(
                format!("uvd curve {name} length"),
                len,
                "a curve with finite points and length",
            ));
        }
    }
    let needed = (a.length().max(b.length()) / resolution).ceil() + 1.0;
    trust_core::scale::check_count(
        "uvd matched points (curve length / uvd.resolution)",
        needed.min(1e30) as u128,
        MAX_POINTS,
    )?;
    Ok(point_count(a.length(), b.length(), resolution))
}

/// A borrowed polyline, so that slices of points can be compared without building a
/// [`trust_core::GuidePath`].
#[derive(Debug, Clone, Copy)]
pub struct Polyline<'a>(pub &'a [Vec3]);

impl Curve for Polyline<'_> {
    fn length(&self) -> f64 {
        polyline_length(self.0)
    }

    fn resample_by_arc_length(&self, count: usize, out: &mut Vec<Vec3>) {
        resample_polyline(self.0, count, out);
    }

    fn time_span(&self) -> Option<(f64, f64)> {
        None
    }

    fn position_at_time(&self, _t: f64) -> Option<Vec3> {
        None
    }
}

/// Length of a polyline (0 for fewer than two points).
pub fn polyline_length(points: &[Vec3]) -> f64 {
    points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// Writes `count` (at least 2) points evenly spaced by arc length along `points`, ends included, into
/// `out` (cleared first). An empty polyline writes nothing; a zero-length one repeats its first point.
pub fn resample_polyline(points: &[Vec3], count: usize, out: &mut Vec<Vec3>) {
    out.clear();
    if let Some(mut walker) = ArcWalker::new(points, count) {
        out.extend(std::iter::from_fn(|| walker.next()));
    }
}

/// Streams the points of [`resample_polyline`] one at a time, without a buffer.
#[derive(Debug, Clone)]
pub struct ArcWalker<'a> {
    points: &'a [Vec3],
    count: usize,
    k: usize,
    step: f64,
    seg: usize,
    seg_start: f64,
    seg_len: f64,
}

impl<'a> ArcWalker<'a> {
    /// A walker producing `count` (at least 2) points along `points`; `None` for an empty polyline.
    pub fn new(points: &'a [Vec3], count: usize) -> Option<Self> {
        points.first()?;
        let count = count.max(2);
        let total = polyline_length(points);
        let step = if total > 0.0 && total.is_finite() {
            total / (count - 1) as f64
        } else {
            0.0
        };
        Some(ArcWalker {
            points,
            count,
            k: 0,
            step,
            seg: 0,
            seg_start: 0.0,
            seg_len: points.get(1).map_or(0.0, |p| (p - points[0]).norm()),
        })
    }

    /// The next point, `None` after `count` points.
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> Option<Vec3> {
        if self.k >= self.count {
            return None;
        }
        let k = self.k;
        self.k += 1;
        let pts = self.points;
        if self.step == 0.0 {
            return Some(pts[0]);
        }
        if k + 1 == self.count {
            return Some(pts[pts.len() - 1]);
        }
        let target = k as f64 * self.step;
        while self.seg + 2 < pts.len() && self.seg_start + self.seg_len < target {
            self.seg_start += self.seg_len;
            self.seg += 1;
            self.seg_len = (pts[self.seg + 1] - pts[self.seg]).norm();
        }
        let u = if self.seg_len > 0.0 {
            ((target - self.seg_start) / self.seg_len).clamp(0.0, 1.0)
        } else {
            0.0
        };
        Some(pts[self.seg] + (pts[self.seg + 1] - pts[self.seg]) * u)
    }
}

/// The number of matched points UVD uses for curves of lengths `len_a`, `len_b`:
/// `⌈max(len_a, len_b) / resolution⌉ + 1`, at least 2 and at most [`MAX_POINTS`]. Never divides by
/// zero: a non-positive or non-finite ratio gives 2.
pub fn point_count(len_a: f64, len_b: f64, resolution: f64) -> usize {
    let ratio = len_a.max(len_b) / resolution;
    if ratio.is_finite() && ratio > 0.0 {
        (ratio.ceil() as usize)
            .saturating_add(1)
            .clamp(2, MAX_POINTS)
    } else {
        2
    }
}

/// Reusable buffers for [`equivalent_with`] and [`equivalent_among`].
#[derive(Debug, Clone, Default)]
pub struct UvdScratch {
    a: Vec<Vec3>,
    b: Vec<Vec3>,
    near: Vec<usize>,
    local: Vec<usize>,
    levels: Vec<Vec<usize>>,
    cum_a: Vec<f64>,
    cum_b: Vec<f64>,
    shapes: Vec<usize>,
    hull: Vec<Vec3>,
    splits: Vec<usize>,
    map_relevant: bool,
}

/// UVD equivalence of two curves: resample both into [`point_count`] points by arc-length fraction and
/// test every chord with `visible`. Errors if `resolution` is not finite and positive.
pub fn equivalent(
    a: &dyn Curve,
    b: &dyn Curve,
    resolution: f64,
    visible: impl FnMut(&Vec3, &Vec3) -> bool,
) -> Result<bool, PlanError> {
    check_curves(a, b, resolution)?;
    Ok(equivalent_with(
        a,
        b,
        resolution,
        &mut UvdScratch::default(),
        visible,
    ))
}

/// [`equivalent`] with caller-provided buffers and no validation (a bad `resolution` falls back to two
/// points per curve).
pub fn equivalent_with(
    a: &dyn Curve,
    b: &dyn Curve,
    resolution: f64,
    scratch: &mut UvdScratch,
    visible: impl FnMut(&Vec3, &Vec3) -> bool,
) -> bool {
    let n = point_count(a.length(), b.length(), resolution);
    a.resample_by_arc_length(n, &mut scratch.a);
    b.resample_by_arc_length(n, &mut scratch.b);
    chords_visible(&scratch.a, &scratch.b, visible)
}

/// UVD equivalence against an obstacle set, with a broad phase: every chord lies in the bounding box
/// of the matched points, so only the cones (and static shapes) meeting that box are tested, and two
/// curves with nothing in that box are equivalent without a single chord query. Same answer as
/// [`equivalent_with`] with `obstacles.segment_clear(p, q, threshold)` as the closure.
pub fn equivalent_among(
    obstacles: &Obstacles<'_>,
    a: &dyn Curve,
    b: &dyn Curve,
    resolution: f64,
    threshold: f64,
    scratch: &mut UvdScratch,
) -> bool {
    let n = point_count(a.length(), b.length(), resolution);
    a.resample_by_arc_length(n, &mut scratch.a);
    b.resample_by_arc_length(n, &mut scratch.b);
    let (Some(ra), Some(rb)) = (Aabb::from_points(&scratch.a), Aabb::from_points(&scratch.b))
    else {
        return true;
    };
    if !gather_near(obstacles, &ra.union(&rb), threshold, scratch) {
        return true;
    }
    matched_chords_clear(obstacles, threshold, scratch)
}

/// [`equivalent_among`] for polylines given by their vertices (same answer), by subdivision of the
/// matched index range. The chords of a range lie in the convex hull of the two sub-polylines it
/// covers, so a cone whose box misses that hull's box, or whose blocking region
/// ([`crate::gjk::Inflated`]: the cone grown by `threshold` as the chord test grows it, with a square
/// rim for a cylinder) [`crate::gjk::separated`] proves to miss the hull, blocks none of them and is
/// dropped for the whole range.
/// The range is first cut at the vertices of both polylines, so that each piece's hull is the
/// tetrahedron of its four end points (a triangle where the polylines share an end): for two paths of
/// the same class that hull is usually clear, and the test costs a few GJK steps instead of a
/// hundred chords. Ranges with cones left are split in halves (middle chord first), down to blocks
/// of at most 16 chords tested one by one. Curves with nothing near them cost one box test.
pub fn polylines_equivalent_among(
    obstacles: &Obstacles<'_>,
    a: &[Vec3],
    b: &[Vec3],
    resolution: f64,
    threshold: f64,
    scratch: &mut UvdScratch,
) -> bool {
    if a.is_empty() || b.is_empty() {
        return true;
    }
    if !a.iter().chain(b).all(|p| p.iter().all(|x| x.is_finite())) {
        return false;
    }
    let (Some(ra), Some(rb)) = (Aabb::from_points(a), Aabb::from_points(b)) else {
        return true;
    };
    if !gather_near(obstacles, &ra.union(&rb), threshold, scratch) {
        return true;
    }
    let mut cum_a = std::mem::take(&mut scratch.cum_a);
    let mut cum_b = std::mem::take(&mut scratch.cum_b);
    let ma = Metric::new(a, &mut cum_a);
    let mb = Metric::new(b, &mut cum_b);
    let n = point_count(ma.total, mb.total, resolution);
    let walk = MatchedWalk {
        a,
        b,
        cum_a: &cum_a,
        cum_b: &cum_b,
        step_a: ma.total / (n - 1) as f64,
        step_b: mb.total / (n - 1) as f64,
        last: n - 1,
    };
    // Split the matched range at the vertices of both polylines, so that on every piece both sides
    // are straight and the chords lie in the tetrahedron of the piece's four end points.
    let mut splits = std::mem::take(&mut scratch.splits);
    splits.clear();
    knee_splits(&cum_a, walk.step_a, walk.last, &mut splits);
    knee_splits(&cum_b, walk.step_b, walk.last, &mut splits);
    splits.sort_unstable();
    splits.dedup();
    let near = std::mem::take(&mut scratch.near);
    let c = threshold.max(0.0);
    // The middle chord of the whole range first: paths of different classes usually part there.
    let (p, q) = walk.pair(walk.last / 2);
    let mut clear = pair_clear(obstacles, &near, scratch.map_relevant, c, &p, &q);
    let mut from = 0;
    for &to in splits.iter().chain(std::iter::once(&walk.last)) {
        if !clear {
            break;
        }
        if to < from {
            continue;
        }
        if !range_clear(obstacles, c, &walk, from, to, &near, scratch, 0) {
            clear = false;
            break;
        }
        from = to + 1;
    }
    scratch.splits = splits;
    let mut near = near;
    near.clear();
    scratch.near = near;
    scratch.cum_a = cum_a;
    scratch.cum_b = cum_b;
    clear
}

/// Appends the matched indices `k` after which an interior vertex of a polyline lies (its arc length
/// is in `[k·step, (k+1)·step)`), for a polyline with cumulative vertex distances `cum`.
fn knee_splits(cum: &[f64], step: f64, last: usize, out: &mut Vec<usize>) {
    if !(step.is_finite() && step > 0.0) || cum.len() < 3 {
        return;
    }
    for &c in &cum[1..cum.len() - 1] {
        let k = (c / step).floor();
        if k.is_finite() && k >= 0.0 {
            out.push((k as usize).min(last.saturating_sub(1)));
        }
    }
}

/// Length of a polyline with its cumulative vertex distances written to a buffer.
struct Metric {
    total: f64,
}

impl Metric {
    fn new(points: &[Vec3], cum: &mut Vec<f64>) -> Self {
        cum.clear();
        let mut acc = 0.0;
        cum.push(0.0);
        for w in points.windows(2) {
            acc += (w[1] - w[0]).norm();
            cum.push(acc);
        }
        Metric { total: acc }
    }
}

/// The matched points of two polylines by index (arc-length fraction `k / last`).
struct MatchedWalk<'a> {
    a: &'a [Vec3],
    b: &'a [Vec3],
    cum_a: &'a [f64],
    cum_b: &'a [f64],
    step_a: f64,
    step_b: f64,
    last: usize,
}

impl MatchedWalk<'_> {
    fn point(points: &[Vec3], cum: &[f64], step: f64, k: usize, last: usize) -> Vec3 {
        if k >= last || !step.is_finite() || step <= 0.0 {
            return if k >= last && step > 0.0 {
                points[points.len() - 1]
            } else {
                points[0]
            };
        }
        let t = k as f64 * step;
        // Segment i with cum[i] <= t < cum[i + 1].
        let i = cum
            .partition_point(|&c| c <= t)
            .saturating_sub(1)
            .min(points.len().saturating_sub(2));
        if points.len() < 2 {
            return points[0];
        }
        let len = cum[i + 1] - cum[i];
        let u = if len > 0.0 {
            ((t - cum[i]) / len).clamp(0.0, 1.0)
        } else {
            0.0
        };
        points[i] + (points[i + 1] - points[i]) * u
    }

    /// Calls `f` on the matched pairs `k0..=k1` in order, stopping at the first `false`; walks the
    /// segments incrementally instead of searching for each point.
    fn all_pairs(&self, k0: usize, k1: usize, mut f: impl FnMut(&Vec3, &Vec3) -> bool) -> bool {
        let mut ca = SegmentCursor::new(self.a, self.cum_a, self.step_a, self.last);
        let mut cb = SegmentCursor::new(self.b, self.cum_b, self.step_b, self.last);
        (k0..=k1).all(|k| f(&ca.point(k), &cb.point(k)))
    }

    fn pair(&self, k: usize) -> (Vec3, Vec3) {
        (
            Self::point(self.a, self.cum_a, self.step_a, k, self.last),
            Self::point(self.b, self.cum_b, self.step_b, k, self.last),
        )
    }

    /// Appends to `out` the points of the sub-polyline of `points` between matched indices
    /// `k0 <= k1`: both ends and the vertices in between.
    fn sub_points(
        points: &[Vec3],
        cum: &[f64],
        step: f64,
        (k0, k1): (usize, usize),
        last: usize,
        out: &mut Vec<Vec3>,
    ) {
        out.push(Self::point(points, cum, step, k0, last));
        let (t0, t1) = (k0 as f64 * step, k1 as f64 * step);
        for (p, &c) in points.iter().zip(cum) {
            if c > t0 && c < t1 {
                out.push(*p);
            }
        }
        out.push(Self::point(points, cum, step, k1, last));
    }

    /// The points whose convex hull contains every chord `k0..=k1` (written to `out`, cleared
    /// first): the two sub-polylines.
    fn range_points(&self, k0: usize, k1: usize, out: &mut Vec<Vec3>) {
        out.clear();
        Self::sub_points(self.a, self.cum_a, self.step_a, (k0, k1), self.last, out);
        Self::sub_points(self.b, self.cum_b, self.step_b, (k0, k1), self.last, out);
    }
}

/// Forward-only evaluation of [`MatchedWalk::point`] for increasing indices.
struct SegmentCursor<'a> {
    points: &'a [Vec3],
    cum: &'a [f64],
    step: f64,
    last: usize,
    seg: usize,
}

impl<'a> SegmentCursor<'a> {
    fn new(points: &'a [Vec3], cum: &'a [f64], step: f64, last: usize) -> Self {
        SegmentCursor {
            points,
            cum,
            step,
            last,
            seg: 0,
        }
    }

    fn point(&mut self, k: usize) -> Vec3 {
        let pts = self.points;
        if k >= self.last || pts.len() < 2 || !self.step.is_finite() || self.step <= 0.0 {
            return MatchedWalk::point(pts, self.cum, self.step, k, self.last);
        }
        let t = k as f64 * self.step;
        while self.seg + 2 < pts.len() && self.cum[self.seg + 1] <= t {
            self.seg += 1;
        }
        let i = self.seg;
        let len = self.cum[i + 1] - self.cum[i];
        let u = if len > 0.0 {
            ((t - self.cum[i]) / len).clamp(0.0, 1.0)
        } else {
            0.0
        };
        pts[i] + (pts[i + 1] - pts[i]) * u
    }
}

/// Whether chord `[p, q]` keeps `c` from the cones `cones[i]`, `i ∈ which`, and (if `map_relevant`)
/// from the static map.
fn pair_clear(
    obstacles: &Obstacles<'_>,
    which: &[usize],
    map_relevant: bool,
    c: f64,
    p: &Vec3,
    q: &Vec3,
) -> bool {
    if p == q {
        return true;
    }
    let seg_box = Aabb::from_segment(p, q);
    which
        .iter()
        .all(|&i| obstacles.cone_segment_clear(i, p, q, c, &seg_box))
        && (!map_relevant || obstacles.map_segment_clear(p, q, c))
}

/// Whether the matched chords `k0..=k1` are clear of the cones in `parent` (indices into
/// `obstacles.cones()`) and of the static map.
///
/// The middle chord is tested first (paths in different classes are usually separated mid-way, so a
/// blocked chord is found before anything else is done); then the cones that cannot block any chord
/// of the range are dropped, and what is left is decided chord by chord (short ranges) or by halves.
#[allow(clippy::too_many_arguments)]
fn range_clear(
    obstacles: &Obstacles<'_>,
    c: f64,
    walk: &MatchedWalk<'_>,
    k0: usize,
    k1: usize,
    parent: &[usize],
    scratch: &mut UvdScratch,
    depth: usize,
) -> bool {
    let mid = k0 + (k1 - k0) / 2;
    if k1 - k0 >= CHORD_BLOCK {
        let (p, q) = walk.pair(mid);
        if !pair_clear(obstacles, parent, scratch.map_relevant, c, &p, &q) {
            return false;
        }
    }
    let mut hull = std::mem::take(&mut scratch.hull);
    walk.range_points(k0, k1, &mut hull);
    let tight = Aabb::from_points(&hull).unwrap_or(Aabb {
        min: Vec3::zeros(),
        max: Vec3::zeros(),
    });
    // The chord test blocks a chord coming within `c + CLEAR_TOLERANCE` of a cone (for a cylinder
    // in its square-rim distance, which is 1-Lipschitz, never more than the Euclidean distance and
    // never less than the gap to the cone's box), so every filter below keeps a cone unless it is
    // more than that away from every chord of the range.
    let reach = c + CLEAR_TOLERANCE;
    let bx = tight.inflated(reach);
    // Every chord of the range lies in the ball around the box centre through its corners: a cone
    // more than `reach` outside that ball cannot block any of them. Cones that pass that cheap test
    // are tested against the convex hull of the two sub-polylines, which contains every chord: the
    // hull must be separated from the region the chord test blocks ([`Inflated`]: the cone grown by
    // `reach`, with a square rim for a cylinder), not merely `c` away from the cone in Euclidean
    // distance — a chord passing a cylinder's rim at `c` to `√2·c` is blocked (issue 18).
    let center = tight.center();
    let ball = 0.5 * tight.extent().norm();
    let cones = obstacles.cones();
    let mut local = scratch
        .levels
        .get_mut(depth)
        .map(std::mem::take)
        .unwrap_or_default();
    local.clear();
    local.extend(parent.iter().copied().filter(|&i| {
        cones[i].aabb().intersects(&bx)
            && cones[i].signed_distance(&center) <= ball + reach
            && !separated_along(
                &Hull(&hull),
                &Inflated {
                    cone: &cones[i],
                    clearance: c,
                },
                0.0,
                &(center - cones[i].aabb().center()),
            )
    }));
    scratch.hull = hull;
    let map = obstacles.map();
    let map_relevant = scratch.map_relevant && {
        map.esdf().is_some_and(|e| e.occupied_count() > 0) || {
            map.shapes_near(&bx, &mut scratch.shapes);
            !scratch.shapes.is_empty()
        }
    };
    let clear = if local.is_empty() && !map_relevant {
        true
    } else if k1 - k0 < CHORD_BLOCK {
        walk.all_pairs(k0, k1, |p, q| {
            pair_clear(obstacles, &local, map_relevant, c, p, q)
        })
    } else {
        range_clear(obstacles, c, walk, k0, mid, &local, scratch, depth + 1)
            && range_clear(obstacles, c, walk, mid + 1, k1, &local, scratch, depth + 1)
    };
    if scratch.levels.len() <= depth {
        scratch.levels.resize_with(depth + 1, Vec::new);
    }
    scratch.levels[depth] = local;
    clear
}

/// Chords tested per block: the block's chords lie in the box of its end points, so obstacles that
/// miss that box are skipped for the whole block.
const CHORD_BLOCK: usize = 16;

/// Collects into `scratch.near` the cones whose boxes meet `region` (grown by `threshold`); returns
/// whether anything (a cone, a static shape or a voxel map) may block a chord inside `region`.
fn gather_near(
    obstacles: &Obstacles<'_>,
    region: &Aabb,
    threshold: f64,
    scratch: &mut UvdScratch,
) -> bool {
    // The chord test blocks within `threshold + CLEAR_TOLERANCE` of a cone (never less than the gap
    // to its box).
    let region = region.inflated(threshold.max(0.0) + CLEAR_TOLERANCE);
    scratch.near.clear();
    scratch.near.extend(
        obstacles
            .cones()
            .iter()
            .enumerate()
            .filter(|(_, c)| c.aabb().intersects(&region))
            .map(|(i, _)| i),
    );
    let map = obstacles.map();
    scratch.map_relevant = map.esdf().is_some_and(|e| e.occupied_count() > 0) || {
        map.shapes_near(&region, &mut scratch.shapes);
        !scratch.shapes.is_empty()
    };
    !scratch.near.is_empty() || scratch.map_relevant
}

/// Tests the chords between `scratch.a` and `scratch.b` against the gathered obstacles, block by block.
fn matched_chords_clear(
    obstacles: &Obstacles<'_>,
    threshold: f64,
    scratch: &mut UvdScratch,
) -> bool {
    let a = std::mem::take(&mut scratch.a);
    let b = std::mem::take(&mut scratch.b);
    let clear = a
        .chunks(CHORD_BLOCK)
        .zip(b.chunks(CHORD_BLOCK))
        .all(|(pa, pb)| block_clear(obstacles, threshold, scratch, pa, pb));
    scratch.a = a;
    scratch.b = b;
    clear
}

/// Tests one block of matched chords against the cones in `scratch.near` that meet the block's box
/// (and the static map when it is relevant).
fn block_clear(
    obstacles: &Obstacles<'_>,
    threshold: f64,
    scratch: &mut UvdScratch,
    pa: &[Vec3],
    pb: &[Vec3],
) -> bool {
    if !pa.iter().chain(pb).all(|p| p.iter().all(|x| x.is_finite())) {
        return false;
    }
    let c = threshold.max(0.0);
    let (Some(ba), Some(bb)) = (Aabb::from_points(pa), Aabb::from_points(pb)) else {
        return true;
    };
    let block = ba.union(&bb).inflated(c + CLEAR_TOLERANCE);
    let cones = obstacles.cones();
    scratch.local.clear();
    scratch.local.extend(
        scratch
            .near
            .iter()
            .copied()
            .filter(|&i| cones[i].aabb().intersects(&block)),
    );
    let map = obstacles.map();
    let map_relevant = scratch.map_relevant && {
        map.esdf().is_some_and(|e| e.occupied_count() > 0) || {
            map.shapes_near(&block, &mut scratch.shapes);
            !scratch.shapes.is_empty()
        }
    };
    if scratch.local.is_empty() && !map_relevant {
        return true;
    }
    let local = &scratch.local;
    chords_visible(pa, pb, |p, q| {
        let seg_box = Aabb::from_segment(p, q);
        local
            .iter()
            .all(|&i| obstacles.cone_segment_clear(i, p, q, c, &seg_box))
            && (!map_relevant || obstacles.map_segment_clear(p, q, c))
    })
}

/// True if every chord between matching points is visible (pairs beyond the shorter slice are ignored;
/// identical matched points count as visible without a query).
pub fn chords_visible(
    a: &[Vec3],
    b: &[Vec3],
    mut visible: impl FnMut(&Vec3, &Vec3) -> bool,
) -> bool {
    a.iter().zip(b).all(|(p, q)| p == q || visible(p, q))
}

/// Parameters of the [`Uvd`] checker.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct UvdParams {
    /// Arc-length step of the matched points (m). Default 0.1 m: Fast-Planner's map resolution, which
    /// its UVD uses as the step.
    /// Accepted: `[1e-9, 1e6]` m; the matched points (`curve length / resolution`) are capped at [`MAX_POINTS`].
    pub resolution: f64,
    /// A chord is blocked if it comes closer than this to an obstacle (m). Default 0: Fast-Planner's
    /// UVD visibility threshold.
    /// Accepted: `[0, 1e6]` m.
    pub clearance: f64,
    /// When set, the predictive directional cones of all forecasts over this horizon (s, from
    /// `scene.t0`) are obstacles too (`"uvd+pdc"`), so the checker sees moving obstacles. Cones that
    /// contain the first or last point of either curve are ignored (both curves must cross them, so
    /// they cannot separate the curves). Default `None`: the static map only, as in Fast-Planner.
    /// Accepted: `[1e-9, 1e7]` s, or `None`.
    pub pdc_horizon_s: Option<f64>,
    /// See the moving obstacles frozen where they are at `scene.t0` (`"uvd+frozen"`; V-PRM's own
    /// view with `VprmParams::freeze_forecasts`). Exclusive with `pdc_horizon_s`. Default `false`.
    pub freeze_forecasts: bool,
}

impl Default for UvdParams {
    fn default() -> Self {
        UvdParams {
            resolution: 0.1,
            clearance: 0.0,
            pdc_horizon_s: None,
            freeze_forecasts: false,
        }
    }
}

impl UvdParams {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), PlanError> {
        use trust_core::scale::Quantity;
        crate::ranges::quantity("uvd.resolution", self.resolution, Quantity::PositiveLength)?;
        crate::ranges::quantity("uvd.clearance", self.clearance, Quantity::Length)?;
        if let Some(h) = self.pdc_horizon_s {
            crate::ranges::quantity("uvd.pdc_horizon_s", h, Quantity::PositiveDuration)?;
            if self.freeze_forecasts {
                return Err(PlanError::invalid(
                    "uvd.freeze_forecasts",
                    true,
                    "false when uvd.pdc_horizon_s is set (frozen obstacles or their cones, not both)",
                ));
            }
        }
        Ok(())
    }
}

/// Uniform visibility deformation as a [`HomotopyChecker`] (paths and trajectories alike: both are
/// matched by arc-length fraction).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Uvd {
    params: UvdParams,
}

impl Uvd {
    /// A checker with validated parameters.
    pub fn new(params: UvdParams) -> Result<Self, PlanError> {
        params.validate()?;
        Ok(Uvd { params })
    }

    /// A checker that also treats the predictive directional cones over `horizon_s` as obstacles.
    pub fn with_pdc(horizon_s: f64) -> Result<Self, PlanError> {
        Uvd::new(UvdParams {
            pdc_horizon_s: Some(horizon_s),
            ..UvdParams::default()
        })
    }

    /// The parameters.
    pub fn params(&self) -> &UvdParams {
        &self.params
    }

    /// The obstacles this checker tests chords against for curves `a`, `b` in `scene`: the static map,
    /// plus the frozen obstacles or their cones minus those containing an end of either curve.
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] naming the forecast if one is invalid.
    pub fn obstacles<'s>(
        &self,
        a: &dyn Curve,
        b: &dyn Curve,
        scene: &Scene<'s>,
    ) -> Result<Obstacles<'s>, PlanError> {
        let cones = match (self.params.pdc_horizon_s, self.params.freeze_forecasts) {
            (Some(h), _) => forecast_cones(scene.forecasts, scene.t0, h)?,
            (None, true) => forecast_cones(scene.forecasts, scene.t0, 0.0)?,
            (None, false) => return Ok(Obstacles::new(scene.map)),
        };
        let mut obs = Obstacles::with_cones(scene.map, cones);
        let mut ends = Vec::with_capacity(4);
        let mut pts = Vec::with_capacity(2);
        for c in [a, b] {
            c.resample_by_arc_length(2, &mut pts);
            ends.extend_from_slice(&pts);
        }
        let clearance = self.params.clearance;
        obs.drop_cones(|cone| ends.iter().any(|p| !cone.point_clear(p, clearance)));
        Ok(obs)
    }
}

impl HomotopyChecker for Uvd {
    fn name(&self) -> &str {
        match (self.params.pdc_horizon_s, self.params.freeze_forecasts) {
            (Some(_), _) => "uvd+pdc",
            (None, true) => "uvd+frozen",
            (None, false) => "uvd",
        }
    }

    fn equivalent(
        &self,
        a: &dyn Curve,
        b: &dyn Curve,
        scene: &Scene<'_>,
    ) -> Result<bool, PlanError> {
        self.params.validate()?;
        check_curves(a, b, self.params.resolution)?;
        let obs = self.obstacles(a, b, scene)?;
        Ok(equivalent_among(
            &obs,
            a,
            b,
            self.params.resolution,
            self.params.clearance,
            &mut UvdScratch::default(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use trust_core::{Forecast, GuidePath, ObstacleShape, StaticMap};
    use trust_geometry::{Shape, Sphere};

    fn pillar_map() -> StaticMap {
        let bounds =
            Aabb::new(Vec3::new(-10.0, -10.0, -10.0), Vec3::new(10.0, 10.0, 10.0)).unwrap();
        StaticMap::from_shapes(
            bounds,
            vec![Shape::from(Sphere::new(Vec3::zeros(), 1.0).unwrap())],
        )
        .unwrap()
    }

    fn path(points: &[[f64; 3]]) -> GuidePath {
        GuidePath::new(points.iter().map(|p| Vec3::new(p[0], p[1], p[2])).collect()).unwrap()
    }

    #[test]
    fn resample_matches_core_guide_path() {
        let g = path(&[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 2.0, 0.0],
            [1.0, 2.0, 0.0],
        ]);
        let mut mine = Vec::new();
        for count in [2, 3, 7, 31] {
            resample_polyline(&g.points, count, &mut mine);
            let theirs = g.resample(count);
            for (p, q) in mine.iter().zip(&theirs) {
                assert_relative_eq!(p, q, epsilon = 1e-12);
            }
        }
    }

    #[test]
    fn paths_around_opposite_sides_are_distinct() {
        let map = pillar_map();
        let scene = Scene::new(&map, &[], 0.0).unwrap();
        let above = path(&[[-3.0, 0.0, 0.0], [0.0, 2.0, 0.0], [3.0, 0.0, 0.0]]);
        let above2 = path(&[[-3.0, 0.0, 0.0], [0.0, 3.0, 0.0], [3.0, 0.0, 0.0]]);
        let below = path(&[[-3.0, 0.0, 0.0], [0.0, -2.0, 0.0], [3.0, 0.0, 0.0]]);
        let uvd = Uvd::default();
        assert!(uvd.equivalent(&above, &above2, &scene).unwrap());
        assert!(!uvd.equivalent(&above, &below, &scene).unwrap());
        assert_eq!(uvd.name(), "uvd");
    }

    #[test]
    fn paths_shorter_than_one_step_do_not_divide_by_zero() {
        let map = pillar_map();
        let scene = Scene::new(&map, &[], 0.0).unwrap();
        let a = path(&[[5.0, 5.0, 5.0], [5.0, 5.0, 5.01]]);
        let b = path(&[[5.0, 5.0, 5.0]]);
        assert_eq!(point_count(0.01, 0.0, 0.1), 2);
        assert_eq!(point_count(0.0, 0.0, 0.1), 2);
        assert_eq!(point_count(1.0, 0.0, 0.0), 2);
        assert_eq!(point_count(f64::NAN, 0.0, 0.1), 2);
        assert!(Uvd::default().equivalent(&a, &b, &scene).unwrap());
        assert!(Uvd::default().equivalent(&b, &b, &scene).unwrap());
    }

    #[test]
    fn bad_resolution_is_an_error() {
        let a = path(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]);
        let e = equivalent(&a, &a, 0.0, |_, _| true)
            .unwrap_err()
            .to_string();
        assert!(e.contains("uvd.resolution"), "{e}");
        assert!(
            Uvd::new(UvdParams {
                resolution: -1.0,
                ..UvdParams::default()
            })
            .is_err()
        );
        assert!(Uvd::with_pdc(f64::NAN).is_err());
    }

    fn v3(lo: f64, hi: f64) -> impl proptest::strategy::Strategy<Value = Vec3> {
        use proptest::prelude::*;
        prop::array::uniform3(lo..hi).prop_map(|a| Vec3::new(a[0], a[1], a[2]))
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig {
            cases: 128,
            ..proptest::prelude::ProptestConfig::default()
        })]

        /// The accelerated test (pieces between vertices, hull-versus-cone separation, recursive
        /// ranges) gives exactly the answer of the definition: every matched chord tested.
        #[test]
        fn accelerated_uvd_agrees_with_testing_every_chord(
            mid_a in proptest::collection::vec(v3(-4.0, 4.0), 1..4),
            mid_b in proptest::collection::vec(v3(-4.0, 4.0), 1..4),
            cones in proptest::collection::vec(
                (v3(-3.0, 3.0), v3(-1.5, 1.5), 0.2..1.2f64, 0.0..0.6f64, proptest::bool::ANY),
                1..4,
            ),
            threshold in proptest::sample::select(vec![0.0, 0.1, 0.3]),
        ) {
            let map = pillar_map();
            let map = StaticMap::new(*map.bounds()).unwrap();
            let (start, goal) = (Vec3::new(-6.0, 0.0, 0.0), Vec3::new(6.0, 0.0, 0.0));
            let a: Vec<Vec3> = std::iter::once(start).chain(mid_a).chain([goal]).collect();
            let b: Vec<Vec3> = std::iter::once(start).chain(mid_b).chain([goal]).collect();
            let forecasts: Vec<Forecast> = cones
                .into_iter()
                .map(|(c, v, r, grow, cyl)| {
                    let shape = if cyl {
                        ObstacleShape::Cylinder { half_height: 1.0 }
                    } else {
                        ObstacleShape::Sphere
                    };
                    Forecast::new(shape, c, v, 0.0, r, 0.0, grow).unwrap()
                })
                .collect();
            let obs = Obstacles::with_forecast_cones(&map, &forecasts, 0.0, 1.0).unwrap();
            let fast = polylines_equivalent_among(
                &obs, &a, &b, 0.1, threshold, &mut UvdScratch::default(),
            );
            let n = point_count(polyline_length(&a), polyline_length(&b), 0.1);
            let (mut ra, mut rb) = (Vec::new(), Vec::new());
            resample_polyline(&a, n, &mut ra);
            resample_polyline(&b, n, &mut rb);
            let slow = chords_visible(&ra, &rb, |p, q| obs.segment_clear(p, q, threshold));
            proptest::prop_assert_eq!(fast, slow);
        }
    }

    /// Issue 18: the shrunk counterexample of `accelerated_uvd_agrees_with_testing_every_chord`
    /// (a cylinder cone moving vertically; the accelerated test said "equivalent" where a chord is
    /// blocked).
    #[test]
    fn accelerated_uvd_regression_vertical_cylinder_cone() {
        let map = StaticMap::new(*pillar_map().bounds()).unwrap();
        let (start, goal) = (Vec3::new(-6.0, 0.0, 0.0), Vec3::new(6.0, 0.0, 0.0));
        let a = vec![start, Vec3::zeros(), goal];
        let b = vec![
            start,
            Vec3::new(3.788733526087845, 0.0, 2.1959919954404175),
            goal,
        ];
        let forecast = Forecast::new(
            ObstacleShape::Cylinder { half_height: 1.0 },
            Vec3::new(0.07457004516634778, 0.3452869392712231, 2.622563865225167),
            Vec3::new(0.0, 0.0, 0.6137439797585048),
            0.0,
            0.7167979029051007,
            0.0,
            0.0,
        )
        .unwrap();
        let obs = Obstacles::with_forecast_cones(&map, &[forecast], 0.0, 1.0).unwrap();
        let threshold = 0.1;
        let n = point_count(polyline_length(&a), polyline_length(&b), 0.1);
        let (mut ra, mut rb) = (Vec::new(), Vec::new());
        resample_polyline(&a, n, &mut ra);
        resample_polyline(&b, n, &mut rb);
        let slow = chords_visible(&ra, &rb, |p, q| obs.segment_clear(p, q, threshold));
        assert!(!slow, "a matched chord is blocked by the cone");
        let fast =
            polylines_equivalent_among(&obs, &a, &b, 0.1, threshold, &mut UvdScratch::default());
        assert_eq!(fast, slow);
        let mid = equivalent_among(
            &obs,
            &Polyline(&a),
            &Polyline(&b),
            0.1,
            threshold,
            &mut UvdScratch::default(),
        );
        assert_eq!(mid, slow);
    }

    #[test]
    fn params_reject_unknown_fields() {
        assert!(serde_json::from_str::<UvdParams>(r#"{"resolution": 0.2}"#).is_ok());
        assert!(serde_json::from_str::<UvdParams>(r#"{"resolutoin": 0.2}"#).is_err());
    }
}

//! [`GlobalRoute`]: the route polyline and the arc-length queries a mission manager needs.

use trust_geometry::StaticMap;

use crate::Vec3;
use crate::error::{RouteError, check_point, check_range};

/// Largest planning horizon accepted by [`GlobalRoute::local_goal`], in metres.
const MAX_HORIZON_M: f64 = 1.0e6;

/// A route: a polyline from the start towards the goal, with its arc-length parametrisation.
///
/// Arc length `s` runs from 0 at the first point to [`GlobalRoute::length`] at the last. Every
/// segment is clear of the static map at [`GlobalRoute::clearance_m`], except the first when
/// [`GlobalRoute::start_inside_clearance`] (the start itself was inside the inflated obstacles).
#[derive(Debug, Clone, PartialEq)]
pub struct GlobalRoute {
    points: Vec<Vec3>,
    /// `cum[i]`: arc length at `points[i]`.
    cum: Vec<f64>,
    clearance_m: f64,
    cell_m: Option<f64>,
    expanded_count: usize,
    start_inside_clearance: bool,
    goal_gap_m: f64,
}

/// The closest point of a route to a position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// Arc length of the closest point, in metres.
    pub s: f64,
    /// The closest point.
    pub point: Vec3,
    /// Distance from the position to it, in metres.
    pub distance_m: f64,
}

/// A point on the route, with its arc length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoutePoint {
    /// Arc length, in metres.
    pub s: f64,
    /// The point.
    pub point: Vec3,
}

/// A stretch of the route found blocked by [`GlobalRoute::first_blocked`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Blocked {
    /// Index of the blocked segment (`points[segment]` to `points[segment + 1]`).
    pub segment: usize,
    /// Arc length where the checked part of the segment starts, in metres.
    pub from_s: f64,
    /// Arc length where the segment ends, in metres.
    pub to_s: f64,
}

impl GlobalRoute {
    /// Adds `n` to the expansion count (cells another search expanded besides this one).
    pub(crate) fn add_expanded(&mut self, n: usize) {
        self.expanded_count += n;
    }

    /// Builds a route from its points (at least one; the planner guarantees it).
    pub(crate) fn new(
        points: Vec<Vec3>,
        clearance_m: f64,
        cell_m: Option<f64>,
        expanded_count: usize,
        start_inside_clearance: bool,
        goal_gap_m: f64,
    ) -> Self {
        let mut cum = Vec::with_capacity(points.len());
        let mut s = 0.0;
        for (i, p) in points.iter().enumerate() {
            if i > 0 {
                s += (p - points[i - 1]).norm();
            }
            cum.push(s);
        }
        Self {
            points,
            cum,
            clearance_m,
            cell_m,
            expanded_count,
            start_inside_clearance,
            goal_gap_m,
        }
    }

    /// A route along the given points (e.g. to replay a logged route, or the straight line when a
    /// caller chooses not to plan). Errors if `points` is empty or holds a non-finite point.
    /// Nothing is checked against a map: [`GlobalRoute::clearance_m`] is 0.
    pub fn from_points(points: Vec<Vec3>) -> Result<Self, RouteError> {
        if points.is_empty() {
            return Err(RouteError::InvalidParam {
                field: "points.len".to_owned(),
                value: 0.0,
                expected: "at least one point".to_owned(),
            });
        }
        for (i, p) in points.iter().enumerate() {
            check_point(&format!("points[{i}]"), p)?;
        }
        Ok(Self::new(points, 0.0, None, 0, false, 0.0))
    }

    /// The vertices, start first.
    pub fn points(&self) -> &[Vec3] {
        &self.points
    }

    /// Total arc length, in metres (0 for a one-point route).
    pub fn length(&self) -> f64 {
        self.cum.last().copied().unwrap_or(0.0)
    }

    /// The inflated clearance the route keeps from the static map, in metres.
    pub fn clearance_m(&self) -> f64 {
        self.clearance_m
    }

    /// The grid cell size used, in metres; `None` when the straight segment was clear (no grid).
    pub fn cell_m(&self) -> Option<f64> {
        self.cell_m
    }

    /// Cells expanded by the search (0 without a grid).
    pub fn expanded_count(&self) -> usize {
        self.expanded_count
    }

    /// True if the start lay inside the inflated obstacles, so that the first segment (to the
    /// nearest free cell) may be closer than [`GlobalRoute::clearance_m`].
    pub fn start_inside_clearance(&self) -> bool {
        self.start_inside_clearance
    }

    /// Distance from the route's end to the goal, in metres: 0 unless the goal lay inside the
    /// inflated obstacles (then the route ends at the nearest free cell).
    pub fn goal_gap_m(&self) -> f64 {
        self.goal_gap_m
    }

    /// The point at arc length `s`, clamped to `[0, length]` (a NaN `s` gives the start).
    pub fn point_at(&self, s: f64) -> Vec3 {
        let s = if s.is_nan() {
            0.0
        } else {
            s.clamp(0.0, self.length())
        };
        // First vertex with cum > s; the segment before it holds s.
        let k = self.cum.partition_point(|&c| c <= s);
        if k == 0 {
            return self.points[0];
        }
        if k >= self.points.len() {
            return self.points[self.points.len() - 1];
        }
        let (a, b) = (self.points[k - 1], self.points[k]);
        let seg = self.cum[k] - self.cum[k - 1];
        if seg <= 0.0 {
            return a;
        }
        a + (b - a) * ((s - self.cum[k - 1]) / seg).clamp(0.0, 1.0)
    }

    /// The closest point of the route to `position` with arc length at least `s_min` (ties to the
    /// smallest arc length). Errors on a non-finite `position`.
    pub fn project_after(&self, position: &Vec3, s_min: f64) -> Result<Projection, RouteError> {
        let p = check_point("position", position)?;
        let s_min = if s_min.is_nan() {
            0.0
        } else {
            s_min.clamp(0.0, self.length())
        };
        let first = self.point_at(s_min);
        let mut best = Projection {
            s: s_min,
            point: first,
            distance_m: (p - first).norm(),
        };
        for i in 0..self.points.len().saturating_sub(1) {
            if self.cum[i + 1] < s_min {
                continue;
            }
            let (a, b) = (self.points[i], self.points[i + 1]);
            let seg = self.cum[i + 1] - self.cum[i];
            if seg <= 0.0 {
                continue;
            }
            let t_min = ((s_min - self.cum[i]) / seg).clamp(0.0, 1.0);
            let t = ((p - a).dot(&(b - a)) / (seg * seg)).clamp(t_min, 1.0);
            let q = a + (b - a) * t;
            let d = (p - q).norm();
            if d < best.distance_m {
                best = Projection {
                    s: self.cum[i] + t * seg,
                    point: q,
                    distance_m: d,
                };
            }
        }
        Ok(best)
    }

    /// The closest point of the route to `position` (ties to the smallest arc length).
    pub fn project(&self, position: &Vec3) -> Result<Projection, RouteError> {
        self.project_after(position, 0.0)
    }

    /// Progress along the route: the arc length of the closest point to `position`, in metres.
    /// For a point of the route at arc length `s` it is `s` (the route never crosses itself
    /// closer than its clearance in practice), so it grows as the vehicle follows the route.
    /// A manager that wants progress never to go back uses [`GlobalRoute::project_after`] with
    /// the last value.
    pub fn progress(&self, position: &Vec3) -> Result<f64, RouteError> {
        Ok(self.project(position)?.s)
    }

    /// Route length left after the closest point to `position`, in metres.
    pub fn remaining_length(&self, position: &Vec3) -> Result<f64, RouteError> {
        Ok(self.length() - self.progress(position)?)
    }

    /// The local goal for a vehicle at `position` with a planning horizon of `horizon_m`: the
    /// first point after the vehicle's projection on the route where the route leaves the ball
    /// of radius `horizon_m` around that projection, or the route's end if it never does. The
    /// result lies on the route, at most `horizon_m` from the projection.
    ///
    /// Errors on a non-finite `position` or a horizon outside `(0, 1e6]` m.
    pub fn local_goal(&self, position: &Vec3, horizon_m: f64) -> Result<RoutePoint, RouteError> {
        let proj = self.project(position)?;
        self.local_goal_from(proj.s, horizon_m)
    }

    /// The first vertex with arc length in `(from_s, to_s)` where the route turns by more than
    /// `min_turn_rad` within `span_m` (m) of it, or `None`: the angle between the chord from the
    /// route's point `span_m` before the vertex to the vertex and the chord from the vertex to the
    /// point `span_m` after it (each chord at least the vertex's own segment, so with `span_m` = 0
    /// the angle between the incoming and the outgoing segment). A hairpin of short segments,
    /// none turning much, is a corner too. A local planner that aims beyond such a corner cuts
    /// it (its trajectory pieces are longer than the corner is sharp); aiming at the corner
    /// first brings the vehicle round it. A non-finite or negative `span_m` counts as 0.
    pub fn first_sharp_turn(
        &self,
        from_s: f64,
        to_s: f64,
        min_turn_rad: f64,
        span_m: f64,
    ) -> Option<RoutePoint> {
        let span = if span_m.is_finite() {
            span_m.max(0.0)
        } else {
            0.0
        };
        (1..self.points.len().saturating_sub(1))
            .filter(|&i| self.cum[i] > from_s && self.cum[i] < to_s)
            .find(|&i| {
                let p = self.points[i];
                let before = self.point_at((self.cum[i] - span).min(self.cum[i - 1]));
                let after = self.point_at((self.cum[i] + span).max(self.cum[i + 1]));
                let (a, b) = (p - before, after - p);
                let (na, nb) = (a.norm(), b.norm());
                na > 0.0
                    && nb > 0.0
                    && (a.dot(&b) / (na * nb)).clamp(-1.0, 1.0).acos() > min_turn_rad
            })
            .map(|i| RoutePoint {
                s: self.cum[i],
                point: self.points[i],
            })
    }

    /// [`GlobalRoute::local_goal`] for a vehicle whose projection is already known to be at arc
    /// length `s` (e.g. from [`GlobalRoute::project_after`]).
    pub fn local_goal_from(&self, s: f64, horizon_m: f64) -> Result<RoutePoint, RouteError> {
        if !(horizon_m > 0.0 && horizon_m <= MAX_HORIZON_M) {
            return Err(RouteError::InvalidParam {
                field: "horizon_m".to_owned(),
                value: horizon_m,
                expected: format!("a finite value in (0, {MAX_HORIZON_M}]"),
            });
        }
        let s0 = if s.is_nan() {
            0.0
        } else {
            s.clamp(0.0, self.length())
        };
        let c = self.point_at(s0);
        let r2 = horizon_m * horizon_m;
        for i in 0..self.points.len().saturating_sub(1) {
            if self.cum[i + 1] <= s0 {
                continue;
            }
            let seg = self.cum[i + 1] - self.cum[i];
            if seg <= 0.0 {
                continue;
            }
            let (a, b) = (self.points[i], self.points[i + 1]);
            let t0 = ((s0 - self.cum[i]) / seg).clamp(0.0, 1.0);
            // |a - c + t·d|² = r², d = b - a: the exit is the larger root.
            let d = b - a;
            let w = a - c;
            let (qa, qb, qc) = (d.dot(&d), 2.0 * w.dot(&d), w.dot(&w) - r2);
            let disc = qb * qb - 4.0 * qa * qc;
            if disc < 0.0 {
                continue;
            }
            let t = (-qb + disc.sqrt()) / (2.0 * qa);
            if t >= t0 && t <= 1.0 {
                let q = a + d * t;
                // Guard the rounding of the root: never beyond the horizon.
                let q = if (q - c).norm() > horizon_m {
                    c + (q - c) * (horizon_m / (q - c).norm())
                } else {
                    q
                };
                return Ok(RoutePoint {
                    s: self.cum[i] + t * seg,
                    point: q,
                });
            }
        }
        let last = self.points.len() - 1;
        Ok(RoutePoint {
            s: self.length(),
            point: self.points[last],
        })
    }

    /// The farthest point of the route from arc length `from_s` up to `to` that a straight line
    /// from `position` reaches clear of `map` at `clearance_m`: the route's vertices in order
    /// while each is in sight, then a bisection (12 halvings) on the route between the last one
    /// in sight and the next. `to` itself when it is in sight, or when not even the route's point
    /// at `from_s` is (the vehicle is off its route: nothing better to aim at). For a vehicle that
    /// stalls in front of a route corner: an aim beyond the corner puts the building between the
    /// vehicle and its aim, and every trajectory pulled straight at it cuts the corner.
    pub fn last_in_sight(
        &self,
        map: &StaticMap,
        position: &Vec3,
        from_s: f64,
        to: RoutePoint,
        clearance_m: f64,
    ) -> RoutePoint {
        let seen = |p: &Vec3| map.segment_clear(position, p, clearance_m);
        if seen(&to.point) {
            return to;
        }
        let s0 = if from_s.is_nan() {
            0.0
        } else {
            from_s.clamp(0.0, self.length())
        };
        let mut lo = RoutePoint {
            s: s0,
            point: self.point_at(s0),
        };
        if !seen(&lo.point) {
            return to;
        }
        let mut hi = to;
        for i in 1..self.points.len() {
            if self.cum[i] <= s0 {
                continue;
            }
            if self.cum[i] >= to.s {
                break;
            }
            let vertex = RoutePoint {
                s: self.cum[i],
                point: self.points[i],
            };
            if seen(&vertex.point) {
                lo = vertex;
            } else {
                hi = vertex;
                break;
            }
        }
        for _ in 0..12 {
            let s = 0.5 * (lo.s + hi.s);
            let mid = RoutePoint {
                s,
                point: self.point_at(s),
            };
            if seen(&mid.point) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// The first segment, from arc length `from_s` on, that is no longer clear at `clearance_m`
    /// on `map` (e.g. a re-check after the map was updated, to decide a re-route), or `None`.
    /// Only the part of each segment after `from_s` is checked, so a vehicle that has passed a
    /// segment does not re-route for it. Errors on a clearance outside `[0, 1e3]` m.
    pub fn first_blocked(
        &self,
        map: &StaticMap,
        clearance_m: f64,
        from_s: f64,
    ) -> Result<Option<Blocked>, RouteError> {
        let clearance = check_range("clearance_m", clearance_m, 0.0, 1.0e3)?;
        let s0 = if from_s.is_nan() {
            0.0
        } else {
            from_s.clamp(0.0, self.length())
        };
        if self.points.len() == 1 {
            return Ok(
                (!map.is_free(&self.points[0], clearance)).then_some(Blocked {
                    segment: 0,
                    from_s: 0.0,
                    to_s: 0.0,
                }),
            );
        }
        for i in 0..self.points.len() - 1 {
            if self.cum[i + 1] <= s0 && i + 2 < self.points.len() {
                continue;
            }
            let from = s0.max(self.cum[i]);
            let a = self.point_at(from);
            if !map.segment_clear(&a, &self.points[i + 1], clearance) {
                return Ok(Some(Blocked {
                    segment: i,
                    from_s: from,
                    to_s: self.cum[i + 1],
                }));
            }
        }
        Ok(None)
    }

    /// True if some part of the route after arc length `from_s` is closer than `clearance_m` to
    /// the static obstacles of `map` ([`GlobalRoute::first_blocked`]).
    pub fn is_blocked(
        &self,
        map: &StaticMap,
        clearance_m: f64,
        from_s: f64,
    ) -> Result<bool, RouteError> {
        Ok(self.first_blocked(map, clearance_m, from_s)?.is_some())
    }
}

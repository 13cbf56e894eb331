//! [`SparseAStar`]: the paper's baseline 2 (Sec. IV-D) — one shortest path by an A* search with
//! sparse, heading-limited expansions at a fixed step, against the static map and the predictive
//! directional cones of all forecasts. "It can be regarded as a single topological guidance method."
//!
//! Each expansion moves `step` metres in a few directions within `max_turn_deg` of the current heading
//! (yaw) and `climb_deg` up or down (pitch), plus straight toward the terminal when that is within the
//! turn limit; the start expands in every direction. States are merged on a grid of `step / 2` cells and
//! eight heading sectors. The search ends when a node within one step sees the terminal (the goal, or
//! the goal guidance surface as in DEV-PRM); the path is then shortcut by line of sight.

use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashSet};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use trust_core::{
    GuidePath, PathFrontend, PathQuery, PlanError, Rng, Scene, SearchResult, SearchStats, Vec3,
};

use crate::ggs::Terminal;
use crate::prm::check_or_trivial_answer;
use crate::ranges;
use crate::shortcut::shortcut;
use crate::visibility::Obstacles;
use trust_core::scale;

/// Yaw directions of the first expansion (from the start, which has no heading).
const START_YAW_COUNT: usize = 16;
/// Heading sectors of the closed set.
const HEADING_SECTORS: f64 = 8.0;

/// Parameters of [`SparseAStar`]. The paper cites Sparse A* without its settings; the values are ours.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SparseAStarParams {
    /// Expansion step (m). Ours: 1.0.
    /// Accepted: `[1e-3, 1e6]` m ([`crate::ranges::MIN_RESOLUTION_M`]).
    pub step: f64,
    /// Largest yaw change per step (degrees). Ours: 45.
    /// Accepted: `[0, 180]`.
    pub max_turn_deg: f64,
    /// Yaw directions per expansion, spread evenly over `±max_turn_deg` (1 = straight on only). Ours: 5.
    /// Accepted: `[1, 64]` ([`MAX_TURN_BRANCHES`]).
    pub turn_branches: usize,
    /// Pitch offset of the climbing and descending expansions (degrees; 0 = level flight only).
    /// Ours: 30.
    /// Accepted: `[0, 90]`.
    pub climb_deg: f64,
    /// Nodes and edges keep this distance from obstacles (m). Ours: 0.3, the PRMs' sample clearance.
    /// Accepted: `[0, 1e6]` m.
    pub clearance: f64,
    /// Time budget (ms, monotonic clock). Ours: 5, the PRMs' default budget.
    /// Accepted: `(0, 6e5]` ms ([`crate::ranges::MAX_BUDGET_MS`]).
    pub budget_ms: f64,
    /// Expansion budget. Ours: 20 000.
    /// Accepted: `[1, 1e6]` ([`crate::ranges::MAX_EXPANSIONS`]).
    pub max_expansions: usize,
    /// Avoid the predictive directional cones of all forecasts. Default `true`.
    pub pdc: bool,
    /// Stop on the goal guidance surface (as DEV-PRM does) instead of at the goal. Default `true`.
    pub goal_guidance_surface: bool,
    /// Shortcut the lattice path by line of sight. Default `true`.
    pub shortcut: bool,
}

/// Largest accepted [`SparseAStarParams::turn_branches`].
pub const MAX_TURN_BRANCHES: usize = 64;

impl Default for SparseAStarParams {
    fn default() -> Self {
        SparseAStarParams {
            step: 1.0,
            max_turn_deg: 45.0,
            turn_branches: 5,
            climb_deg: 30.0,
            clearance: 0.3,
            budget_ms: 5.0,
            max_expansions: 20_000,
            pdc: true,
            goal_guidance_surface: true,
            shortcut: true,
        }
    }
}

impl SparseAStarParams {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), PlanError> {
        self.budget().map(|_| ())
    }

    fn budget(&self) -> Result<Duration, PlanError> {
        ranges::range(
            "sparse_astar.step",
            self.step,
            ranges::MIN_RESOLUTION_M,
            scale::MAX_LENGTH_M,
            "m",
        )?;
        if !(self.max_turn_deg.is_finite() && (0.0..=180.0).contains(&self.max_turn_deg)) {
            return Err(PlanError::invalid(
                "sparse_astar.max_turn_deg",
                self.max_turn_deg,
                "a number in [0, 180]",
            ));
        }
        if !(self.climb_deg.is_finite() && (0.0..=90.0).contains(&self.climb_deg)) {
            return Err(PlanError::invalid(
                "sparse_astar.climb_deg",
                self.climb_deg,
                "a number in [0, 90]",
            ));
        }
        // Each expansion tries this many headings.
        ranges::count(
            "sparse_astar.turn_branches",
            self.turn_branches,
            1,
            MAX_TURN_BRANCHES,
        )?;
        ranges::count(
            "sparse_astar.max_expansions",
            self.max_expansions,
            1,
            ranges::MAX_EXPANSIONS,
        )?;
        ranges::quantity(
            "sparse_astar.clearance",
            self.clearance,
            scale::Quantity::Length,
        )?;
        ranges::budget_ms("sparse_astar.budget_ms", self.budget_ms)?;
        Duration::try_from_secs_f64(self.budget_ms / 1000.0).map_err(|_| {
            PlanError::invalid(
                "sparse_astar.budget_ms",
                self.budget_ms,
                "a duration representable in std::time::Duration",
            )
        })
    }
}

/// Baseline 2 as a [`PathFrontend`] (`"sparse-astar"`): at most one path.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SparseAStar {
    params: SparseAStarParams,
}

impl SparseAStar {
    /// A planner with validated parameters.
    pub fn new(params: SparseAStarParams) -> Result<Self, PlanError> {
        params.validate()?;
        Ok(SparseAStar { params })
    }

    /// The parameters.
    pub fn params(&self) -> &SparseAStarParams {
        &self.params
    }
}

/// A search node.
#[derive(Debug, Clone, Copy)]
struct Node {
    pos: Vec3,
    heading: Option<Vec3>,
    g: f64,
    parent: Option<usize>,
}

/// An open-list entry: smallest `f` first, then first inserted.
#[derive(Debug, Clone, Copy)]
struct Open {
    f: f64,
    seq: usize,
}

impl PartialEq for Open {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Open {}
impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Open {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .f
            .total_cmp(&self.f)
            .then_with(|| other.seq.cmp(&self.seq))
    }
}

/// Unit direction from yaw and pitch (radians).
fn direction(yaw: f64, pitch: f64) -> Vec3 {
    Vec3::new(
        pitch.cos() * yaw.cos(),
        pitch.cos() * yaw.sin(),
        pitch.sin(),
    )
}

/// The expansion directions from a node with heading `heading` (`None`: every direction).
fn expansion_directions(p: &SparseAStarParams, heading: Option<Vec3>, out: &mut Vec<Vec3>) {
    out.clear();
    let climb = p.climb_deg.to_radians();
    let pitches: &[f64] = if climb > 0.0 {
        &[0.0, 1.0, -1.0]
    } else {
        &[0.0]
    };
    match heading {
        None => {
            for k in 0..START_YAW_COUNT {
                let yaw = std::f64::consts::TAU * k as f64 / START_YAW_COUNT as f64;
                for s in pitches {
                    out.push(direction(yaw, s * climb));
                }
            }
            out.push(Vec3::z());
            out.push(-Vec3::z());
        }
        Some(h) => {
            let yaw0 = h.y.atan2(h.x);
            let pitch0 = h.z.clamp(-1.0, 1.0).asin();
            let turn = p.max_turn_deg.to_radians();
            let n = p.turn_branches;
            for i in 0..n {
                let dyaw = if n == 1 {
                    0.0
                } else {
                    -turn + 2.0 * turn * i as f64 / (n - 1) as f64
                };
                for s in pitches {
                    let pitch = (pitch0 + s * climb)
                        .clamp(-std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2);
                    out.push(direction(yaw0 + dyaw, pitch));
                }
            }
        }
    }
}

/// Closed-set key: grid cell of `step / 2` and heading sector.
fn state_key(pos: &Vec3, heading: &Vec3, cell: f64) -> (i64, i64, i64, i64) {
    let q = |x: f64| (x / cell).floor() as i64;
    let sector = ((heading.y.atan2(heading.x) + std::f64::consts::PI) / std::f64::consts::TAU
        * HEADING_SECTORS)
        .floor() as i64;
    (q(pos.x), q(pos.y), q(pos.z), sector)
}

impl PathFrontend for SparseAStar {
    fn name(&self) -> &str {
        "sparse-astar"
    }

    fn search(
        &self,
        query: &PathQuery,
        scene: &Scene<'_>,
        _rng: &mut Rng,
    ) -> Result<SearchResult, PlanError> {
        let since = Instant::now();
        let budget = self.params.budget()?;
        if let Some(answer) = check_or_trivial_answer(query, scene, since)? {
            return Ok(answer);
        }
        let p = &self.params;
        let start = query.start.p;
        let deadline = since + budget;
        let terminal = if p.goal_guidance_surface {
            Terminal::goal_guidance_surface(
                &start,
                &query.goal,
                query.horizon_s,
                query.limits.v_max,
            )
        } else {
            Terminal::Point(query.goal)
        };
        let cones = if p.pdc {
            crate::visibility::forecast_cones(scene.forecasts, query.start.t, query.horizon_s)?
        } else {
            Vec::new()
        };
        let mut obstacles = Obstacles::with_cones(scene.map, cones);
        obstacles.drop_cones(|c| {
            c.contains(&start) || matches!(terminal, Terminal::Point(g) if c.contains(&g))
        });
        let start_clearance = obstacles.clearance(&start);
        let start_threshold = if start_clearance.is_finite() {
            p.clearance.min(0.5 * start_clearance).max(0.0)
        } else {
            p.clearance
        };
        let bounds = *scene.map.bounds();
        let cell = 0.5 * p.step;

        let mut stats = SearchStats::default();
        let mut nodes = vec![Node {
            pos: start,
            heading: None,
            g: 0.0,
            parent: None,
        }];
        let mut open = BinaryHeap::new();
        open.push(Open {
            f: terminal.distance_from(&start),
            seq: 0,
        });
        let mut closed: HashSet<(i64, i64, i64, i64)> = HashSet::new();
        let mut dirs = Vec::new();
        let mut found: Option<(usize, Vec3)> = None;
        while let Some(Open { seq: idx, .. }) = open.pop() {
            if stats.node_count >= p.max_expansions || Instant::now() >= deadline {
                stats.budget_exhausted = true;
                break;
            }
            stats.node_count += 1;
            let node = nodes[idx];
            let threshold = if idx == 0 {
                start_threshold
            } else {
                p.clearance
            };
            // Goal test: within one step and in sight of the terminal.
            if terminal.distance_from(&node.pos) <= p.step {
                let end = terminal.nearest_point(&node.pos);
                if obstacles.segment_clear(&node.pos, &end, threshold) {
                    found = Some((idx, end));
                    break;
                }
            }
            expansion_directions(p, node.heading, &mut dirs);
            let to_goal = terminal.nearest_point(&node.pos) - node.pos;
            if to_goal.norm() > 0.0 {
                let d = to_goal.normalize();
                let within = node
                    .heading
                    .is_none_or(|h| h.dot(&d) >= p.max_turn_deg.to_radians().cos() - 1e-12);
                if within {
                    dirs.push(d);
                }
            }
            for d in &dirs {
                let q = node.pos + d * p.step;
                if !bounds.contains(&q) {
                    continue;
                }
                let key = state_key(&q, d, cell);
                if closed.contains(&key) || !obstacles.segment_clear(&node.pos, &q, threshold) {
                    continue;
                }
                closed.insert(key);
                let g = node.g + p.step;
                nodes.push(Node {
                    pos: q,
                    heading: Some(*d),
                    g,
                    parent: Some(idx),
                });
                open.push(Open {
                    f: g + terminal.distance_from(&q),
                    seq: nodes.len() - 1,
                });
            }
        }
        let Some((last, end)) = found else {
            stats.elapsed = since.elapsed();
            return Ok(SearchResult {
                paths: Vec::new(),
                stats,
            });
        };
        let mut points = vec![end];
        let mut cur = Some(last);
        while let Some(i) = cur {
            points.push(nodes[i].pos);
            cur = nodes[i].parent;
        }
        points.reverse();
        if points.last() == points.get(points.len().wrapping_sub(2)) {
            points.pop();
        }
        if p.shortcut {
            points = shortcut(&points, &obstacles, start_threshold, 0.5 * cell, &bounds);
        }
        stats.raw_path_count = 1;
        stats.elapsed = since.elapsed();
        Ok(SearchResult {
            paths: vec![GuidePath::new(points)?],
            stats,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_respect_the_heading_limit() {
        let p = SparseAStarParams::default();
        let mut out = Vec::new();
        expansion_directions(&p, Some(Vec3::x()), &mut out);
        assert_eq!(out.len(), 15);
        for d in &out {
            assert!((d.norm() - 1.0).abs() < 1e-12);
            // Yaw within 45°, pitch within 30°: the angle to x is at most ~53°.
            assert!(
                d.x >= (45f64.to_radians().cos() * 30f64.to_radians().cos()) - 1e-9,
                "{d:?}"
            );
        }
        expansion_directions(&p, None, &mut out);
        assert_eq!(out.len(), 16 * 3 + 2);
        // A vertical heading clamps the pitch instead of wrapping.
        expansion_directions(&p, Some(Vec3::z()), &mut out);
        assert!(out.iter().all(|d| d.iter().all(|c| c.is_finite())));
    }

    #[test]
    fn open_list_pops_smallest_then_oldest() {
        let mut h = BinaryHeap::new();
        h.push(Open { f: 2.0, seq: 0 });
        h.push(Open { f: 1.0, seq: 2 });
        h.push(Open { f: 1.0, seq: 1 });
        assert_eq!(h.pop().unwrap().seq, 1);
        assert_eq!(h.pop().unwrap().seq, 2);
        assert_eq!(h.pop().unwrap().seq, 0);
    }

    #[test]
    fn params_validate() {
        assert!(SparseAStarParams::default().validate().is_ok());
        let e = SparseAStar::new(SparseAStarParams {
            max_turn_deg: 200.0,
            ..SparseAStarParams::default()
        })
        .unwrap_err()
        .to_string();
        assert!(e.contains("sparse_astar.max_turn_deg"), "{e}");
        assert!(serde_json::from_str::<SparseAStarParams>(r#"{"stpe": 1.0}"#).is_err());
    }
}

//! Graph searches over a [`Roadmap`] from [`START`] to [`GOAL`], returning node sequences.
//!
//! * [`depth_first_paths`] — V-PRM: depth-first enumeration of simple paths (Fast-Planner), bounded by
//!   a raw-path count and an expansion count.
//! * [`beam_paths`] — DEV-PRM (Algorithm 2, `BeamSearch`): level-by-level expansion of simple partial
//!   paths, keeping the `width` best by estimated length (length so far plus the straight-line
//!   distance to the terminal).
//!
//! Both are deterministic: neighbours are visited in insertion order and ties keep that order.

use std::time::Instant;

use crate::roadmap::{GOAL, Roadmap, START};
use crate::uvd::polyline_length;

/// Bounds on a search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchLimits {
    /// Stop after this many complete paths.
    pub max_raw_paths: usize,
    /// Stop after this many node expansions.
    pub max_expansions: usize,
    /// Stop at this instant (monotonic clock), if set.
    pub deadline: Option<Instant>,
}

impl SearchLimits {
    fn expired(&self, expansions: usize) -> bool {
        expansions >= self.max_expansions || self.deadline.is_some_and(|d| Instant::now() >= d)
    }
}

/// Simple paths from [`START`] to [`GOAL`] by depth-first search (iterative, no recursion depth
/// limit), in discovery order.
pub fn depth_first_paths(graph: &Roadmap, limits: &SearchLimits) -> Vec<Vec<usize>> {
    let mut raw = Vec::new();
    if limits.max_raw_paths == 0 {
        return raw;
    }
    let mut on_path = vec![false; graph.node_count()];
    let mut path = vec![START];
    let mut next = vec![0usize];
    on_path[START] = true;
    let mut expansions = 0;
    while let Some(&top) = path.last() {
        let i = next.last_mut().expect("`next` has one entry per path node");
        let Some(&nb) = graph.neighbors(top).get(*i) else {
            on_path[top] = false;
            path.pop();
            next.pop();
            continue;
        };
        *i += 1;
        if nb == GOAL {
            let mut p = path.clone();
            p.push(GOAL);
            raw.push(p);
            if raw.len() >= limits.max_raw_paths {
                break;
            }
            continue;
        }
        if on_path[nb] {
            continue;
        }
        expansions += 1;
        if limits.expired(expansions) {
            break;
        }
        on_path[nb] = true;
        path.push(nb);
        next.push(0);
    }
    raw
}

/// A partial path of the beam search.
#[derive(Debug, Clone)]
struct Partial {
    nodes: Vec<usize>,
    length: f64,
    key: f64,
}

/// Simple paths from [`START`] to [`GOAL`] by beam search of the given `width` (at least 1), in
/// discovery order (shorter estimated paths first within a level).
pub fn beam_paths(graph: &Roadmap, width: usize, limits: &SearchLimits) -> Vec<Vec<usize>> {
    let mut raw = Vec::new();
    if limits.max_raw_paths == 0 {
        return raw;
    }
    let width = width.max(1);
    let terminal = *graph.terminal();
    let mut beam = vec![Partial {
        nodes: vec![START],
        length: 0.0,
        key: terminal.distance_from(&graph.position(START)),
    }];
    let mut expansions = 0;
    'levels: while !beam.is_empty() {
        let mut children = Vec::new();
        for partial in &beam {
            let last = *partial.nodes.last().expect("partial paths are never empty");
            let from = graph.position(last);
            for &nb in graph.neighbors(last) {
                if nb == GOAL {
                    let mut p = partial.nodes.clone();
                    p.push(GOAL);
                    raw.push(p);
                    if raw.len() >= limits.max_raw_paths {
                        break 'levels;
                    }
                    continue;
                }
                if partial.nodes.contains(&nb) {
                    continue;
                }
                expansions += 1;
                if limits.expired(expansions) {
                    break 'levels;
                }
                let to = graph.position(nb);
                let length = partial.length + (to - from).norm();
                let mut nodes = Vec::with_capacity(partial.nodes.len() + 1);
                nodes.extend_from_slice(&partial.nodes);
                nodes.push(nb);
                children.push(Partial {
                    nodes,
                    length,
                    key: length + terminal.distance_from(&to),
                });
            }
        }
        children.sort_by(|a, b| a.key.total_cmp(&b.key));
        children.truncate(width);
        beam = children;
    }
    raw
}

/// Keeps the `keep` paths with the fewest nodes (stable: earlier paths win ties) — Fast-Planner's
/// raw-path reduction.
pub fn keep_fewest_nodes(mut raw: Vec<Vec<usize>>, keep: usize) -> Vec<Vec<usize>> {
    raw.sort_by_key(Vec::len);
    raw.truncate(keep);
    raw
}

/// Keeps the `keep` shortest paths (by polyline length, stable).
pub fn keep_shortest(graph: &Roadmap, raw: Vec<Vec<usize>>, keep: usize) -> Vec<Vec<usize>> {
    let mut scored: Vec<(f64, Vec<usize>)> = raw
        .into_iter()
        .map(|p| (polyline_length(&graph.path_points(&p)), p))
        .collect();
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    scored.truncate(keep);
    scored.into_iter().map(|(_, p)| p).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ggs::Terminal;
    use crate::roadmap::{RoadmapBuilder, RoadmapParams, SampleOutcome};
    use crate::visibility::Obstacles;
    use trust_core::{Aabb, StaticMap, Vec3};
    use trust_geometry::{AaBox, Shape};

    /// A wall between start and goal with three gaps, and one connector in each gap.
    fn three_gaps() -> (StaticMap, Vec<Vec3>) {
        let b = Aabb::new(Vec3::new(-10.0, -10.0, -10.0), Vec3::new(10.0, 10.0, 10.0)).unwrap();
        let piece = |y0: f64, y1: f64| {
            Shape::from(AaBox::new(Vec3::new(-0.2, y0, -10.0), Vec3::new(0.2, y1, 10.0)).unwrap())
        };
        let map = StaticMap::from_shapes(
            b,
            vec![
                piece(-10.0, -6.0),
                piece(-4.0, -1.0),
                piece(1.0, 4.0),
                piece(6.0, 10.0),
            ],
        )
        .unwrap();
        let samples = vec![
            Vec3::new(0.0, 5.0, 0.0),
            Vec3::new(0.0, -5.0, 0.0),
            Vec3::new(0.0, 0.0, 0.0),
        ];
        (map, samples)
    }

    fn build(map: &StaticMap, samples: &[Vec3]) -> Roadmap {
        let obs = Obstacles::new(map);
        let mut b = RoadmapBuilder::new(
            Vec3::new(-5.0, 0.0, 0.0),
            Terminal::Point(Vec3::new(5.0, 0.0, 0.0)),
            &obs,
            RoadmapParams {
                sample_clearance: 0.3,
                edge_threshold: 0.1,
                uvd_resolution: 0.1,
                uvd_threshold: 0.0,
            },
            *map.bounds(),
        );
        for s in samples {
            assert_eq!(b.add_sample(*s), SampleOutcome::Connector);
        }
        b.finish()
    }

    fn limits(max_raw_paths: usize) -> SearchLimits {
        SearchLimits {
            max_raw_paths,
            max_expansions: 10_000,
            deadline: None,
        }
    }

    #[test]
    fn dfs_finds_every_simple_path() {
        let (map, samples) = three_gaps();
        let g = build(&map, &samples);
        let raw = depth_first_paths(&g, &limits(300));
        assert_eq!(raw.len(), 3);
        assert!(
            raw.iter()
                .all(|p| p.first() == Some(&START) && p.last() == Some(&GOAL))
        );
        assert_eq!(depth_first_paths(&g, &limits(2)).len(), 2);
        assert!(depth_first_paths(&g, &limits(0)).is_empty());
    }

    #[test]
    fn beam_prefers_short_paths_and_respects_its_width() {
        let (map, samples) = three_gaps();
        let g = build(&map, &samples);
        let all = beam_paths(&g, 8, &limits(300));
        assert_eq!(all.len(), 3);
        // The straight gap (node 4) is expanded first.
        assert_eq!(all[0], vec![START, 4, GOAL]);
        let narrow = beam_paths(&g, 1, &limits(300));
        assert_eq!(narrow, vec![vec![START, 4, GOAL]]);
        let kept = keep_shortest(&g, all.clone(), 2);
        assert_eq!(kept.len(), 2);
        assert_eq!(kept[0], vec![START, 4, GOAL]);
        assert_eq!(keep_fewest_nodes(all, 1).len(), 1);
    }
}

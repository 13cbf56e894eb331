//! The visibility roadmap: guards and connectors (Fast-Planner's topological PRM; paper Algorithm 2,
//! `ConstructRoadMap`).
//!
//! For each sample the builder finds the guards it sees (stopping at three):
//! * none → the sample becomes a guard;
//! * exactly two → a candidate connector between them. If an existing connector of the same two
//!   guards gives a UVD-equivalent path, the sample is redundant (and that connector moves to the
//!   sample when the path through the sample is shorter); otherwise it becomes a connector;
//! * one or three → discarded; except that a sample added with
//!   [`RoadmapBuilder::add_persistent_sample`] that sees exactly one guard waits for a second one:
//!   it is tested against every guard added later, and the first it sees makes it a connector
//!   candidate, as if it had been sampled at that moment.
//!
//! The start and the terminal (goal point or goal guidance surface) are guards. [`RoadmapBuilder::finish`]
//! then removes dead ends (non-terminal nodes with at most one neighbour) until none is left.

use std::collections::HashMap;

use trust_core::{Aabb, Vec3};

use crate::ggs::Terminal;
use crate::uvd::{UvdScratch, polylines_equivalent_among};
use crate::visibility::Obstacles;

/// Index of the start node.
pub const START: usize = 0;
/// Index of the terminal node (goal point or GGS).
pub const GOAL: usize = 1;

/// Most guards a sample is tested against before it is discarded (Fast-Planner stops at three).
const MAX_VISIBLE_GUARDS: usize = 3;

/// What a node is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NodeKind {
    /// The start (a guard).
    Start,
    /// The terminal (a guard): goal point or GGS.
    Goal,
    /// A guard: a sample that saw no other guard.
    Guard,
    /// A connector: a sample that saw exactly two guards.
    Connector,
}

/// What happened to one sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleOutcome {
    /// Too close to an obstacle, out of the region, or beyond the GGS.
    Rejected,
    /// Became a guard.
    Guard,
    /// Became a connector.
    Connector,
    /// Equivalent to an existing connector of the same guards (which may have moved to it).
    Redundant,
    /// Saw one or at least three guards.
    Discarded,
    /// Saw exactly one guard and was kept to be retried against later guards
    /// ([`RoadmapBuilder::add_persistent_sample`]).
    Pending,
}

/// Thresholds of the roadmap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoadmapParams {
    /// Samples closer than this to an obstacle are rejected (m).
    pub sample_clearance: f64,
    /// Roadmap edges must keep this distance from obstacles (m).
    pub edge_threshold: f64,
    /// Arc-length step of the UVD test between connectors (m).
    pub uvd_resolution: f64,
    /// Chord threshold of the UVD test (m).
    pub uvd_threshold: f64,
}

/// An undirected roadmap over guards and connectors.
#[derive(Debug, Clone)]
pub struct Roadmap {
    pos: Vec<Vec3>,
    kind: Vec<NodeKind>,
    adj: Vec<Vec<usize>>,
    /// For nodes adjacent to [`GOAL`]: the point of the terminal their edge ends at.
    attach: Vec<Option<Vec3>>,
    alive: Vec<bool>,
    terminal: Terminal,
}

impl Roadmap {
    /// Total nodes ever added (including pruned ones).
    pub fn node_count(&self) -> usize {
        self.pos.len()
    }

    /// Nodes still in the graph.
    pub fn alive_count(&self) -> usize {
        self.alive.iter().filter(|a| **a).count()
    }

    /// Position of node `n` (for [`GOAL`] with a GGS: the global goal).
    pub fn position(&self, n: usize) -> Vec3 {
        self.pos[n]
    }

    /// Kind of node `n`.
    pub fn kind(&self, n: usize) -> NodeKind {
        self.kind[n]
    }

    /// Neighbours of node `n`, in insertion order.
    pub fn neighbors(&self, n: usize) -> &[usize] {
        &self.adj[n]
    }

    /// Whether node `n` survived pruning.
    pub fn is_alive(&self, n: usize) -> bool {
        self.alive[n]
    }

    /// The terminal.
    pub fn terminal(&self) -> &Terminal {
        &self.terminal
    }

    /// The point where the edge from `n` to [`GOAL`] ends.
    pub fn attach_point(&self, n: usize) -> Vec3 {
        self.attach[n].unwrap_or(self.pos[GOAL])
    }

    /// The polyline of a node sequence that starts at [`START`] (the last point is the attach point
    /// when the sequence ends at [`GOAL`]).
    pub fn path_points(&self, nodes: &[usize]) -> Vec<Vec3> {
        let mut out = Vec::with_capacity(nodes.len());
        for (i, &n) in nodes.iter().enumerate() {
            if n == GOAL && i > 0 {
                out.push(self.attach_point(nodes[i - 1]));
            } else {
                out.push(self.pos[n]);
            }
        }
        out
    }

    fn add_node(&mut self, p: Vec3, kind: NodeKind) -> usize {
        self.pos.push(p);
        self.kind.push(kind);
        self.adj.push(Vec::new());
        self.attach.push(None);
        self.alive.push(true);
        self.pos.len() - 1
    }

    fn connect(&mut self, a: usize, b: usize) {
        self.adj[a].push(b);
        self.adj[b].push(a);
    }

    /// Removes non-terminal nodes with at most one neighbour until none is left.
    fn prune_dead_ends(&mut self) {
        let mut queue: Vec<usize> = (2..self.pos.len()).collect();
        while let Some(n) = queue.pop() {
            if !self.alive[n] || self.adj[n].len() > 1 {
                continue;
            }
            self.alive[n] = false;
            let neighbours = std::mem::take(&mut self.adj[n]);
            for m in neighbours {
                self.adj[m].retain(|&x| x != n);
                if m >= 2 && self.alive[m] && self.adj[m].len() <= 1 {
                    queue.push(m);
                }
            }
        }
    }
}

/// The expensive operations a [`RoadmapBuilder`] did: samples tested against the obstacles, visibility
/// queries (line of sight from a sample to a guard, against the static map and the cones) and UVD
/// equivalence tests of connector candidates. Deterministic for a given sample sequence, so a cap on
/// them is a work budget that does not depend on the machine.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RoadmapWork {
    /// Samples inserted (each costs one clearance query).
    pub sample_count: usize,
    /// Visibility tests of a sample against a guard (line of sight against the static map and the
    /// cones; for the terminal, to its candidate end points until one is visible).
    pub visibility_count: usize,
    /// UVD equivalence tests of a new connector against the existing ones of its guard pair.
    pub uvd_count: usize,
}

impl RoadmapWork {
    /// Cost of one sample's bookkeeping beyond its obstacle queries (drawing, guard lookups,
    /// graph updates), in work units ([`crate::QueryWork`]: estimated ns of the development
    /// machine, fitted with the query weights).
    pub const SAMPLE_UNITS: u64 = 123;
}

/// Builds a [`Roadmap`] one sample at a time.
#[derive(Debug)]
pub struct RoadmapBuilder<'o, 'm> {
    graph: Roadmap,
    obstacles: &'o Obstacles<'m>,
    params: RoadmapParams,
    /// Region all roadmap points must lie in (sampling region ∪ start ∪ goal, inside the map bounds).
    region: Aabb,
    start_threshold: f64,
    goal_threshold: f64,
    guards: Vec<usize>,
    pairs: HashMap<(usize, usize), Vec<usize>>,
    uvd: UvdScratch,
    candidates: Vec<Vec3>,
    visible: Vec<(usize, Option<Vec3>)>,
    /// Persistent samples that saw exactly one guard: the point and that guard (with its attach point).
    pending: Vec<(Vec3, (usize, Option<Vec3>))>,
    work: RoadmapWork,
}

impl<'o, 'm> RoadmapBuilder<'o, 'm> {
    /// A roadmap with the start and terminal guards. `region` bounds every node and attach point.
    ///
    /// Edges touching the start or a goal point use a threshold no larger than half the clearance of
    /// that point, so that a start closer than `edge_threshold` to an obstacle still sees its
    /// surroundings.
    pub fn new(
        start: Vec3,
        terminal: Terminal,
        obstacles: &'o Obstacles<'m>,
        params: RoadmapParams,
        region: Aabb,
    ) -> Self {
        let mut graph = Roadmap {
            pos: Vec::new(),
            kind: Vec::new(),
            adj: Vec::new(),
            attach: Vec::new(),
            alive: Vec::new(),
            terminal,
        };
        graph.add_node(start, NodeKind::Start);
        let goal_pos = match terminal {
            Terminal::Point(g) => g,
            Terminal::Surface { center, .. } => center,
        };
        graph.add_node(goal_pos, NodeKind::Goal);
        let relaxed = |p: &Vec3| {
            let c = obstacles.clearance(p);
            if c.is_finite() {
                params.edge_threshold.min(0.5 * c).max(0.0)
            } else {
                params.edge_threshold
            }
        };
        let start_threshold = relaxed(&start);
        let goal_threshold = match terminal {
            Terminal::Point(g) => relaxed(&g),
            Terminal::Surface { .. } => params.edge_threshold,
        };
        RoadmapBuilder {
            graph,
            obstacles,
            params,
            region,
            start_threshold,
            goal_threshold,
            guards: vec![START, GOAL],
            pairs: HashMap::new(),
            uvd: UvdScratch::default(),
            candidates: Vec::new(),
            visible: Vec::new(),
            pending: Vec::new(),
            work: RoadmapWork::default(),
        }
    }

    /// The graph so far.
    pub fn graph(&self) -> &Roadmap {
        &self.graph
    }

    /// The expensive operations done so far.
    pub fn work(&self) -> RoadmapWork {
        self.work
    }

    /// Whether `p` sees guard `g`; for the terminal, the end point of that edge.
    fn sees(&mut self, p: &Vec3, g: usize) -> Option<Option<Vec3>> {
        let obs = self.obstacles;
        self.work.visibility_count += 1;
        match g {
            START => obs
                .segment_clear(p, &self.graph.pos[START], self.start_threshold)
                .then_some(None),
            GOAL => {
                let terminal = self.graph.terminal;
                terminal.candidates(p, &mut self.candidates);
                let threshold = self.goal_threshold;
                let region = self.region;
                self.candidates
                    .iter()
                    .find(|q| region.contains(q) && obs.segment_clear(p, q, threshold))
                    .map(|q| Some(*q))
            }
            _ => obs
                .segment_clear(p, &self.graph.pos[g], self.params.edge_threshold)
                .then_some(None),
        }
    }

    /// The polyline `g1 → via → g2` (with the terminal's attach point when `g2` is [`GOAL`]).
    fn connector_path(&self, g1: usize, via: Vec3, g2: usize, attach: Option<Vec3>) -> [Vec3; 3] {
        let end = if g2 == GOAL {
            attach.unwrap_or(self.graph.pos[GOAL])
        } else {
            self.graph.pos[g2]
        };
        let first = if g1 == GOAL {
            attach.unwrap_or(self.graph.pos[GOAL])
        } else {
            self.graph.pos[g1]
        };
        [first, via, end]
    }

    /// Adds one sample.
    pub fn add_sample(&mut self, p: Vec3) -> SampleOutcome {
        self.insert(p, false)
    }

    /// Adds one sample that is not discarded when it sees exactly one guard: it is kept and tested
    /// against every later guard, and the first later guard it sees makes it a connector candidate of
    /// the two (exactly as if it had been sampled then). DEV-PRM inserts its obstacle-aware samples
    /// this way, because they come first, when only the start and the terminal are guards and the
    /// obstacle they hug hides one of them.
    pub fn add_persistent_sample(&mut self, p: Vec3) -> SampleOutcome {
        self.insert(p, true)
    }

    /// Samples waiting for a second guard ([`RoadmapBuilder::add_persistent_sample`]).
    #[cfg(test)]
    pub(crate) fn pending_count(&self) -> usize {
        self.pending.len()
    }

    fn insert(&mut self, p: Vec3, persistent: bool) -> SampleOutcome {
        self.work.sample_count += 1;
        if !self.region.contains(&p)
            || self.graph.terminal.is_beyond(&p)
            || !self.obstacles.is_free(&p, self.params.sample_clearance)
        {
            return SampleOutcome::Rejected;
        }
        self.visible.clear();
        for i in 0..self.guards.len() {
            let g = self.guards[i];
            if let Some(attach) = self.sees(&p, g) {
                self.visible.push((g, attach));
                if self.visible.len() >= MAX_VISIBLE_GUARDS {
                    break;
                }
            }
        }
        match self.visible.len() {
            0 => {
                let n = self.graph.add_node(p, NodeKind::Guard);
                self.guards.push(n);
                self.retry_pending(n);
                SampleOutcome::Guard
            }
            1 if persistent => {
                self.pending.push((p, self.visible[0]));
                SampleOutcome::Pending
            }
            2 => self.try_connect(p),
            _ => SampleOutcome::Discarded,
        }
    }

    /// Tests the pending samples against the new guard `g`; those that see it become connector
    /// candidates of their first guard and `g`.
    fn retry_pending(&mut self, g: usize) {
        if self.pending.is_empty() {
            return;
        }
        let pending = std::mem::take(&mut self.pending);
        let mut still = Vec::with_capacity(pending.len());
        for (p, first) in pending {
            match self.sees(&p, g) {
                Some(attach) => {
                    self.visible.clear();
                    self.visible.push(first);
                    self.visible.push((g, attach));
                    self.try_connect(p);
                }
                None => still.push((p, first)),
            }
        }
        // Connections made above add no guards, so nothing was queued meanwhile.
        self.pending = still;
    }

    fn try_connect(&mut self, p: Vec3) -> SampleOutcome {
        let (mut a, mut b) = (self.visible[0], self.visible[1]);
        if a.0 > b.0 {
            std::mem::swap(&mut a, &mut b);
        }
        let (g1, g2) = (a.0, b.0);
        let attach = a.1.or(b.1);
        let new_path = self.connector_path(g1, p, g2, attach);
        let new_len = crate::uvd::polyline_length(&new_path);
        let existing: Vec<usize> = self.pairs.get(&(g1, g2)).cloned().unwrap_or_default();
        for c in existing {
            self.work.uvd_count += 1;
            let old_path = self.connector_path(g1, self.graph.pos[c], g2, self.graph.attach[c]);
            let same = polylines_equivalent_among(
                self.obstacles,
                &new_path,
                &old_path,
                self.params.uvd_resolution,
                self.params.uvd_threshold,
                &mut self.uvd,
            );
            if same {
                if new_len < crate::uvd::polyline_length(&old_path) {
                    self.graph.pos[c] = p;
                    self.graph.attach[c] = attach;
                }
                return SampleOutcome::Redundant;
            }
        }
        let c = self.graph.add_node(p, NodeKind::Connector);
        self.graph.attach[c] = attach;
        self.graph.connect(g1, c);
        self.graph.connect(c, g2);
        self.pairs.entry((g1, g2)).or_default().push(c);
        SampleOutcome::Connector
    }

    /// The finished roadmap with dead ends removed.
    pub fn finish(mut self) -> Roadmap {
        self.graph.prune_dead_ends();
        self.graph
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use trust_core::StaticMap;
    use trust_geometry::{Shape, Sphere};

    fn params() -> RoadmapParams {
        RoadmapParams {
            sample_clearance: 0.3,
            edge_threshold: 0.1,
            uvd_resolution: 0.1,
            uvd_threshold: 0.0,
        }
    }

    fn world(shapes: Vec<Shape>) -> StaticMap {
        let b = Aabb::new(Vec3::new(-10.0, -10.0, -5.0), Vec3::new(10.0, 10.0, 5.0)).unwrap();
        StaticMap::from_shapes(b, shapes).unwrap()
    }

    #[test]
    fn guards_and_connectors_around_a_ball() {
        let map = world(vec![Shape::from(Sphere::new(Vec3::zeros(), 2.0).unwrap())]);
        let obs = Obstacles::new(&map);
        let start = Vec3::new(-5.0, 0.0, 0.0);
        let goal = Vec3::new(5.0, 0.0, 0.0);
        let mut b =
            RoadmapBuilder::new(start, Terminal::Point(goal), &obs, params(), *map.bounds());
        // Inside the ball: rejected. Above and below: connectors of start and goal.
        assert_eq!(b.add_sample(Vec3::zeros()), SampleOutcome::Rejected);
        assert_eq!(
            b.add_sample(Vec3::new(0.0, 4.0, 0.0)),
            SampleOutcome::Connector
        );
        assert_eq!(
            b.add_sample(Vec3::new(0.0, -4.0, 0.0)),
            SampleOutcome::Connector
        );
        // Same side as the first connector but shorter: redundant, and the connector moves.
        assert_eq!(
            b.add_sample(Vec3::new(0.0, 3.0, 0.0)),
            SampleOutcome::Redundant
        );
        assert_eq!(b.graph().position(2), Vec3::new(0.0, 3.0, 0.0));
        // A point that sees only the start: hidden from the goal by the ball.
        assert_eq!(
            b.add_sample(Vec3::new(-3.0, 0.0, 0.0)),
            SampleOutcome::Discarded
        );
        let g = b.finish();
        assert_eq!(g.alive_count(), 4);
        assert_eq!(g.neighbors(START), &[2, 3]);
        assert_eq!(
            g.path_points(&[START, 2, GOAL]),
            vec![start, Vec3::new(0.0, 3.0, 0.0), goal]
        );
    }

    #[test]
    fn dead_ends_are_pruned() {
        // Two full walls: a sample between them sees neither start nor goal and becomes a guard with
        // no neighbour; a sample on the start side sees only the start and is discarded. The lone
        // guard is pruned.
        let wall = |x: f64| {
            Shape::from(
                trust_geometry::AaBox::new(
                    Vec3::new(x - 0.2, -10.0, -5.0),
                    Vec3::new(x + 0.2, 10.0, 5.0),
                )
                .unwrap(),
            )
        };
        let map = world(vec![wall(-2.0), wall(2.0)]);
        let obs = Obstacles::new(&map);
        let mut b = RoadmapBuilder::new(
            Vec3::new(-5.0, 0.0, 0.0),
            Terminal::Point(Vec3::new(5.0, 0.0, 0.0)),
            &obs,
            params(),
            *map.bounds(),
        );
        assert_eq!(b.add_sample(Vec3::new(0.0, 0.0, 0.0)), SampleOutcome::Guard);
        assert_eq!(
            b.add_sample(Vec3::new(-4.0, 1.0, 0.0)),
            SampleOutcome::Discarded
        );
        assert_eq!(b.graph().node_count(), 3);
        let g = b.finish();
        assert_eq!(g.alive_count(), 2);
        assert!(g.neighbors(START).is_empty());
    }

    #[test]
    fn persistent_samples_wait_for_a_second_guard() {
        // Left wall with a gap at y ∈ [3, 5], right wall without: the goal is hidden from the left.
        let slab = |x: f64, y0: f64, y1: f64| {
            Shape::from(
                trust_geometry::AaBox::new(
                    Vec3::new(x - 0.2, y0, -5.0),
                    Vec3::new(x + 0.2, y1, 5.0),
                )
                .unwrap(),
            )
        };
        let map = world(vec![
            slab(-2.0, -10.0, 3.0),
            slab(-2.0, 5.0, 10.0),
            slab(2.0, -10.0, 10.0),
        ]);
        let obs = Obstacles::new(&map);
        let mut b = RoadmapBuilder::new(
            Vec3::new(-5.0, 0.0, 0.0),
            Terminal::Point(Vec3::new(5.0, 0.0, 0.0)),
            &obs,
            params(),
            *map.bounds(),
        );
        // Sees only the start: an ordinary sample is discarded, a persistent one waits.
        let p = Vec3::new(-4.0, 4.0, 0.0);
        assert_eq!(b.add_sample(p), SampleOutcome::Discarded);
        assert_eq!(b.add_persistent_sample(p), SampleOutcome::Pending);
        assert_eq!(b.pending_count(), 1);
        // A guard between the walls that `p` sees through the gap: `p` becomes its connector with
        // the start.
        assert_eq!(b.add_sample(Vec3::new(0.0, 4.0, 0.0)), SampleOutcome::Guard);
        assert_eq!(b.pending_count(), 0);
        let g = b.graph();
        assert_eq!(g.node_count(), 4);
        assert_eq!(g.kind(3), NodeKind::Connector);
        assert_eq!(g.position(3), p);
        assert_eq!(g.neighbors(3), &[START, 2]);
    }

    #[test]
    fn ggs_terminal_attaches_on_the_sphere() {
        let map = world(vec![]);
        let obs = Obstacles::new(&map);
        let terminal = Terminal::Surface {
            center: Vec3::new(9.0, 0.0, 0.0),
            radius: 4.0,
        };
        let mut b = RoadmapBuilder::new(
            Vec3::new(-9.0, 0.0, 0.0),
            terminal,
            &obs,
            params(),
            *map.bounds(),
        );
        assert_eq!(
            b.add_sample(Vec3::new(7.0, 0.0, 0.0)),
            SampleOutcome::Rejected
        );
        assert_eq!(
            b.add_sample(Vec3::new(0.0, 1.0, 0.0)),
            SampleOutcome::Connector
        );
        let g = b.finish();
        let pts = g.path_points(&[START, 2, GOAL]);
        assert!(terminal.reaches(pts.last().unwrap(), 1e-9));
    }
}

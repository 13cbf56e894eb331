//! The pipeline V-PRM and DEV-PRM share: validate → region and obstacles → roadmap (obstacle-aware
//! samples, then random samples under a time and sample budget, optionally until the roadmap stalls)
//! → graph search → shortcut → `TopoPathSelect`.

use std::time::{Duration, Instant};

use trust_core::{
    Aabb, GuidePath, PathQuery, PlanError, Rng, Scene, SearchResult, SearchStats, Vec3,
    check_finite, check_finite_vec, check_non_negative,
};

use crate::ggs::Terminal;
use crate::roadmap::{RoadmapBuilder, RoadmapParams, RoadmapWork, SampleOutcome};
use crate::sampling::SamplingBox;
use crate::search::{
    SearchLimits, beam_paths, depth_first_paths, keep_fewest_nodes, keep_shortest,
};
use crate::select::select_distinct_short_paths;
use crate::shortcut::shortcut;
use crate::uvd::{UvdScratch, polylines_equivalent_among};
use crate::visibility::{Obstacles, forecast_cones};

/// Start and goal closer than this (m) are treated as the same point: the answer is the path
/// `[start, goal]` without any sampling.
pub const COINCIDENT_M: f64 = 1e-9;

/// Margin (m) added around the sampling region when selecting the cones that can matter.
const REGION_MARGIN_M: f64 = 1.0;

/// The work of a search so far, in units: its obstacle queries' ([`crate::QueryWork::units`]) plus the
/// roadmap's own bookkeeping per sample ([`RoadmapWork::SAMPLE_UNITS`]).
pub(crate) fn search_units(obstacles: &Obstacles<'_>, roadmap: RoadmapWork) -> u64 {
    let own = (roadmap.sample_count as u64).saturating_mul(RoadmapWork::SAMPLE_UNITS);
    obstacles.work().units().saturating_add(own)
}

/// Appends one line per search to the file named by `TRUST_PRM_WORK_TRACE` (fit of the unit
/// weights; see `examples/prm_work_fit.rs`): elapsed ns, then the counts.
fn trace_work(obstacles: &Obstacles<'_>, roadmap: RoadmapWork, elapsed: Duration) {
    use std::io::Write;
    let Some(path) = std::env::var_os("TRUST_PRM_WORK_TRACE") else {
        return;
    };
    let w = obstacles.work();
    if let Ok(mut f) = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
    {
        let _ = writeln!(
            f,
            "{} {} {} {} {} {} {} {} {}",
            elapsed.as_nanos(),
            w.map.queries,
            w.map.esdf_samples,
            w.map.shape_tests,
            w.cone_boxes,
            w.cone_tests,
            roadmap.sample_count,
            roadmap.visibility_count,
            roadmap.uvd_count
        );
    }
}

/// Part of the work budget the roadmap may use; the rest is left to shortcutting and selection.
const ROADMAP_WORK_SHARE: f64 = 0.8;

/// Validates a path query against a scene, as every frontend of this crate does first:
/// [`PathQuery::validate`], finite forecasts with non-negative sizes, start and goal inside the map
/// bounds ([`PlanError::OutOfBounds`]) and not inside a static obstacle ([`PlanError::InCollision`]).
pub fn check_query(query: &PathQuery, scene: &Scene<'_>) -> Result<(), PlanError> {
    query.validate()?;
    check_finite("scene.t0", scene.t0)?;
    for (i, f) in scene.forecasts.iter().enumerate() {
        check_finite_vec(&format!("scene.forecasts[{i}].p0"), &f.p0)?;
        check_finite_vec(&format!("scene.forecasts[{i}].v0"), &f.v0)?;
        check_finite(&format!("scene.forecasts[{i}].t0"), f.t0)?;
        check_non_negative(&format!("scene.forecasts[{i}].r_o"), f.r_o)?;
        check_non_negative(&format!("scene.forecasts[{i}].r_safe"), f.r_safe)?;
        check_non_negative(&format!("scene.forecasts[{i}].mu"), f.mu)?;
        if let trust_core::ObstacleShape::Cylinder { half_height } = f.shape {
            check_non_negative(
                &format!("scene.forecasts[{i}].shape.half_height"),
                half_height,
            )?;
        }
    }
    scene.check_in_bounds("query.start.p", &query.start.p)?;
    scene.check_in_bounds("query.goal", &query.goal)?;
    scene.check_static_free("query.start.p", &query.start.p, 0.0)?;
    scene.check_static_free("query.goal", &query.goal, 0.0)?;
    Ok(())
}

/// What every frontend of this crate does before it plans: validates the query ([`check_query`])
/// and answers coincident start and goal (closer than [`COINCIDENT_M`]) with one zero-length path
/// `[start, goal]` without any sampling — `Some(answer)` then, `None` when there is something to
/// plan. `since` is when the search call began (for [`SearchStats::elapsed`]).
pub(crate) fn check_or_trivial_answer(
    query: &PathQuery,
    scene: &Scene<'_>,
    since: Instant,
) -> Result<Option<SearchResult>, PlanError> {
    check_query(query, scene)?;
    if (query.goal - query.start.p).norm() > COINCIDENT_M {
        return Ok(None);
    }
    Ok(Some(SearchResult {
        paths: vec![GuidePath::new(vec![query.start.p, query.goal])?],
        stats: SearchStats {
            elapsed: since.elapsed(),
            ..SearchStats::default()
        },
    }))
}

/// How the moving obstacles enter the roadmap's visibility test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum ConeMode {
    /// Ignored.
    Ignore,
    /// Frozen where they are at the query time (an occupancy-map snapshot).
    Frozen,
    /// Predictive directional cones over the query horizon, capped at `pdc_horizon_s` (s;
    /// `f64::INFINITY` for no cap).
    Predictive { pdc_horizon_s: f64 },
}

/// Graph search of the pipeline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum GraphSearch {
    /// Fast-Planner's DFS; the raw paths with the fewest nodes are kept.
    DepthFirst,
    /// Algorithm 2's beam search; the shortest raw paths are kept.
    Beam { width: usize },
}

/// Obstacle-aware sampling on cone surfaces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SurfaceSampling {
    pub slices: usize,
    pub per_slice: usize,
    pub offset: f64,
}

/// Everything the pipeline needs (validated by the frontends' params).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PrmSetup {
    pub inflate: Vec3,
    pub clearance: f64,
    pub resolution: f64,
    /// Time budget of the search (ms; checked by [`PrmSetup::check_shared`]).
    pub budget_ms: f64,
    /// Work units ([`RoadmapWork::units`]) per ms of `budget_ms`: the deterministic work budget.
    pub work_per_ms: f64,
    /// Also stop on the monotonic clock at `budget_ms`.
    pub wall_clock: bool,
    pub max_samples: usize,
    pub stall_samples: usize,
    pub search: GraphSearch,
    pub max_raw_paths: usize,
    pub keep_raw_paths: usize,
    pub max_paths: usize,
    pub length_ratio: f64,
    pub max_expansions: usize,
    pub cones: ConeMode,
    pub surface_sampling: Option<SurfaceSampling>,
    pub goal_surface: bool,
}

impl PrmSetup {
    /// This setup for a query that explores `factor` (≥ 1) times as widely
    /// ([`PathQuery::exploration`]): the sampling box's inflation, the sample budgets and the time
    /// budget multiplied by it (counts capped at the scale policy's sample count).
    fn explored(&self, factor: f64) -> PrmSetup {
        let count = |n: usize| {
            ((n as f64 * factor).round() as usize).min(trust_core::scale::MAX_SAMPLE_COUNT)
        };
        PrmSetup {
            inflate: self.inflate * factor,
            budget_ms: self.budget_ms * factor,
            max_samples: count(self.max_samples),
            stall_samples: count(self.stall_samples),
            ..*self
        }
    }

    /// The deterministic work budget: `budget_ms · work_per_ms` units.
    fn work_budget(&self) -> u64 {
        let units = (self.budget_ms * self.work_per_ms).ceil();
        if units >= u64::MAX as f64 {
            u64::MAX
        } else {
            units as u64
        }
    }

    /// The search's time budget.
    fn budget(&self, prefix: &str) -> Result<Duration, PlanError> {
        Duration::try_from_secs_f64(self.budget_ms / 1000.0).map_err(|_| {
            PlanError::invalid(
                format!("{prefix}.budget_ms"),
                self.budget_ms,
                "a duration representable in std::time::Duration",
            )
        })
    }

    /// Checks the fields V-PRM and DEV-PRM share (errors name `prefix.field`); the planners check
    /// their own fields.
    pub(crate) fn check_shared(&self, prefix: &str) -> Result<(), PlanError> {
        use crate::ranges;
        use trust_core::scale::{MAX_LENGTH_M, MAX_SAMPLE_COUNT, Quantity};
        let field = |name: &str| format!("{prefix}.{name}");
        ranges::lengths(&field("inflate"), &self.inflate)?;
        ranges::quantity(&field("clearance"), self.clearance, Quantity::Length)?;
        ranges::range(
            &field("resolution"),
            self.resolution,
            ranges::MIN_RESOLUTION_M,
            MAX_LENGTH_M,
            "m",
        )?;
        ranges::budget_ms(&field("budget_ms"), self.budget_ms)?;
        self.budget(prefix)?;
        ranges::range(
            &field("work_per_ms"),
            self.work_per_ms,
            trust_core::scale::MIN_POSITIVE,
            ranges::MAX_WORK_PER_MS,
            "units/ms",
        )?;
        ranges::count(&field("max_samples"), self.max_samples, 0, MAX_SAMPLE_COUNT)?;
        for (name, value, cap) in [
            ("max_raw_paths", self.max_raw_paths, ranges::MAX_PATH_COUNT),
            (
                "keep_raw_paths",
                self.keep_raw_paths,
                ranges::MAX_PATH_COUNT,
            ),
            ("max_paths", self.max_paths, ranges::MAX_PATH_COUNT),
            (
                "max_expansions",
                self.max_expansions,
                ranges::MAX_EXPANSIONS,
            ),
        ] {
            ranges::count(&field(name), value, 1, cap)?;
        }
        ranges::range(
            &field("length_ratio"),
            self.length_ratio,
            1.0,
            ranges::MAX_LENGTH_RATIO,
            "(dimensionless)",
        )?;
        Ok(())
    }
}

/// Implements `fn shared_setup(&self) -> PrmSetup` for a params struct that has the fields V-PRM
/// and DEV-PRM share under the same names ([`crate::VprmParams`], [`crate::DevPrmParams`]): those
/// fields, and V-PRM's choices for the rest — depth-first search, no stall stop, moving obstacles
/// ignored, no surface samples, paths ending at the goal — for the planner to override. Unchecked:
/// see [`PrmSetup::check_shared`].
macro_rules! impl_shared_setup {
    ($params:ty) => {
        impl $params {
            fn shared_setup(&self) -> $crate::prm::PrmSetup {
                $crate::prm::PrmSetup {
                    inflate: self.inflate,
                    clearance: self.clearance,
                    resolution: self.resolution,
                    budget_ms: self.budget_ms,
                    work_per_ms: self.work_per_ms,
                    wall_clock: self.wall_clock_budget,
                    max_samples: self.max_samples,
                    stall_samples: 0,
                    search: $crate::prm::GraphSearch::DepthFirst,
                    max_raw_paths: self.max_raw_paths,
                    keep_raw_paths: self.keep_raw_paths,
                    max_paths: self.max_paths,
                    length_ratio: self.length_ratio,
                    max_expansions: self.max_expansions,
                    cones: $crate::prm::ConeMode::Ignore,
                    surface_sampling: None,
                    goal_surface: false,
                }
            }
        }
    };
}
pub(crate) use impl_shared_setup;

/// Intersection of two boxes, or `None` if they do not meet.
fn intersection(a: &Aabb, b: &Aabb) -> Option<Aabb> {
    let min = a.min.sup(&b.min);
    let max = a.max.inf(&b.max);
    (0..3)
        .all(|i| min[i] <= max[i])
        .then_some(Aabb { min, max })
}

/// The axis-aligned box of the oriented sampling box plus `extra` points.
fn box_aabb(b: &SamplingBox, extra: &[Vec3]) -> Aabb {
    let mut corners = Vec::with_capacity(8 + extra.len());
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            for sz in [-1.0, 1.0] {
                corners.push(b.point(&Vec3::new(sx, sy, sz)));
            }
        }
    }
    corners.extend_from_slice(extra);
    Aabb::from_points(&corners).unwrap_or(Aabb {
        min: b.center,
        max: b.center,
    })
}

/// The coverage-based stop of the random sampling phase: consecutive free samples that added neither
/// a guard nor a connector (rejected samples neither count nor reset it).
#[derive(Debug, Clone, Copy)]
struct StallCounter {
    limit: usize,
    run: usize,
}

impl StallCounter {
    /// A counter that stalls after `limit` useless samples in a row (`0`: never).
    fn new(limit: usize) -> Self {
        StallCounter { limit, run: 0 }
    }

    fn record(&mut self, outcome: SampleOutcome) {
        match outcome {
            SampleOutcome::Guard | SampleOutcome::Connector => self.run = 0,
            SampleOutcome::Rejected => {}
            SampleOutcome::Redundant | SampleOutcome::Discarded | SampleOutcome::Pending => {
                self.run += 1;
            }
        }
    }

    fn stalled(&self) -> bool {
        self.limit > 0 && self.run >= self.limit
    }
}

/// Runs the pipeline.
pub(crate) fn run(
    setup: &PrmSetup,
    query: &PathQuery,
    scene: &Scene<'_>,
    rng: &mut Rng,
) -> Result<SearchResult, PlanError> {
    let since = Instant::now();
    if let Some(answer) = check_or_trivial_answer(query, scene, since)? {
        return Ok(answer);
    }
    let explored;
    let setup = if query.exploration > 1.0 {
        explored = setup.explored(query.exploration);
        &explored
    } else {
        setup
    };
    let start = query.start.p;
    let deadline = since + setup.budget("prm")?;
    let work_budget = setup.work_budget();
    let roadmap_work_budget = (work_budget as f64 * ROADMAP_WORK_SHARE) as u64;

    let terminal = if setup.goal_surface {
        Terminal::goal_guidance_surface(&start, &query.goal, query.horizon_s, query.limits.v_max)
    } else {
        Terminal::Point(query.goal)
    };
    let local_goal = terminal.nearest_point(&start);
    let sampling = SamplingBox::between(&start, &local_goal, &setup.inflate);
    let region = intersection(
        &box_aabb(&sampling, &[start, local_goal]),
        scene.map.bounds(),
    )
    .unwrap_or(Aabb {
        min: start,
        max: start,
    });

    // Obstacles: static map plus the cones that can touch the region; cones that swallow the start
    // (or a goal point) cannot be avoided in space and are left to the trajectory backend.
    let t_query = query.start.t;
    let cones = match setup.cones {
        ConeMode::Ignore => Vec::new(),
        ConeMode::Frozen => forecast_cones(scene.forecasts, t_query, 0.0)?,
        ConeMode::Predictive { pdc_horizon_s } => {
            forecast_cones(scene.forecasts, t_query, query.horizon_s.min(pdc_horizon_s))?
        }
    };
    let mut obstacles =
        Obstacles::with_cones(scene.map, cones).restricted_to(&region.inflated(REGION_MARGIN_M));
    let goal_point = match terminal {
        Terminal::Point(g) => Some(g),
        Terminal::Surface { .. } => None,
    };
    obstacles.drop_cones(|c| c.contains(&start) || goal_point.is_some_and(|g| c.contains(&g)));

    let params = RoadmapParams {
        sample_clearance: setup.clearance,
        edge_threshold: setup.resolution,
        uvd_resolution: setup.resolution,
        uvd_threshold: 0.0,
    };
    let mut builder = RoadmapBuilder::new(start, terminal, &obstacles, params, region);
    let mut stats = SearchStats::default();
    let out_of_budget = |work: RoadmapWork| {
        search_units(&obstacles, work) >= roadmap_work_budget
            || (setup.wall_clock && Instant::now() >= deadline)
    };

    // Obstacle-aware samples first (Algorithm 2, ConstructRoadMap(G, P_PDC)). They are persistent:
    // one that sees a single guard now is retried against the guards random sampling adds.
    if let Some(s) = setup.surface_sampling {
        let mut samples = Vec::new();
        for (i, cone) in obstacles.cones().iter().enumerate() {
            cone.surface_samples_into(s.slices, s.per_slice, s.offset, &region, &mut samples)
                .map_err(|e| {
                    PlanError::invalid(
                        format!("devprm surface samples of scene.forecasts[{i}]"),
                        s,
                        e.to_string(),
                    )
                })?;
        }
        for p in samples {
            if out_of_budget(builder.work()) {
                stats.budget_exhausted = true;
                break;
            }
            builder.add_persistent_sample(p);
            stats.sample_count += 1;
        }
    }
    // Random samples until the time or sample budget runs out, or until the roadmap stalls.
    let mut random = 0;
    let mut stall = StallCounter::new(setup.stall_samples);
    while random < setup.max_samples && !stall.stalled() {
        if out_of_budget(builder.work()) {
            stats.budget_exhausted = true;
            break;
        }
        stall.record(builder.add_sample(sampling.sample(rng)));
        random += 1;
        stats.sample_count += 1;
    }
    if random >= setup.max_samples {
        stats.budget_exhausted = true;
    }
    stats.stalled = stall.stalled();
    let roadmap_work = builder.work();
    let graph = builder.finish();
    stats.node_count = graph.alive_count();

    let limits = SearchLimits {
        max_raw_paths: setup.max_raw_paths,
        max_expansions: setup.max_expansions,
        deadline: None,
    };
    let raw = match setup.search {
        GraphSearch::DepthFirst => {
            let raw = depth_first_paths(&graph, &limits);
            stats.raw_path_count = raw.len();
            keep_fewest_nodes(raw, setup.keep_raw_paths)
        }
        GraphSearch::Beam { width } => {
            let raw = beam_paths(&graph, width, &limits);
            stats.raw_path_count = raw.len();
            keep_shortest(&graph, raw, setup.keep_raw_paths)
        }
    };

    // Shortcut the raw paths shortest (beam) or fewest-nodes (DFS) first while the work budget
    // lasts; the first is always shortcut, so a search that found a path returns one.
    let mut short: Vec<Vec<Vec3>> = Vec::with_capacity(raw.len());
    for nodes in &raw {
        let points = graph.path_points(nodes);
        if !short.is_empty()
            && (search_units(&obstacles, roadmap_work) >= work_budget
                || (setup.wall_clock && Instant::now() >= deadline))
        {
            stats.budget_exhausted = true;
            break;
        }
        short.push(shortcut(
            &points,
            &obstacles,
            setup.resolution,
            setup.resolution,
            &region,
        ));
    }
    let mut scratch = UvdScratch::default();
    let selected =
        select_distinct_short_paths(short, setup.length_ratio, setup.max_paths, |a, b| {
            polylines_equivalent_among(&obstacles, a, b, setup.resolution, 0.0, &mut scratch)
        });
    let paths = selected
        .into_iter()
        .map(GuidePath::new)
        .collect::<Result<Vec<_>, _>>()?;
    stats.elapsed = since.elapsed();
    trace_work(&obstacles, roadmap_work, stats.elapsed);
    Ok(SearchResult { paths, stats })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stall_counter_counts_useless_free_samples_in_a_row() {
        let mut c = StallCounter::new(3);
        for o in [
            SampleOutcome::Redundant,
            SampleOutcome::Rejected,
            SampleOutcome::Discarded,
        ] {
            c.record(o);
        }
        assert!(!c.stalled());
        c.record(SampleOutcome::Connector);
        for _ in 0..2 {
            c.record(SampleOutcome::Discarded);
        }
        assert!(!c.stalled());
        c.record(SampleOutcome::Pending);
        assert!(c.stalled());
        let mut off = StallCounter::new(0);
        for _ in 0..10_000 {
            off.record(SampleOutcome::Redundant);
        }
        assert!(!off.stalled());
    }
}

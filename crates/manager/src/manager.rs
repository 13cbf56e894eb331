//! [`Manager`]: Algorithm 1 of the paper, one cycle per [`Manager::step`].

use std::time::{Duration, Instant};

use rand::SeedableRng;
use rayon::prelude::*;
use trust_core::{
    Aabb, Forecast, GuidePath, HomotopyChecker, InitialGuess, Limits, PathFrontend, PathQuery,
    PlanError, PolyTraj, RankingWeights, Rng, Scene, Solution, State, TrajRequest,
    TrajectoryBackend, Vec3, check_finite, check_finite_vec,
};

use crate::ManagerParams;
use crate::brake::{brake_along, brake_straight};
use crate::report::{
    BranchId, BranchReport, CycleTiming, Event, FallbackReport, FrontendReport, LimitExcess,
    Origin, StepReport,
};
use crate::safety::{SafetyVerdict, assess_trajectory, check_trajectory, window_bounds};

/// One kept trajectory branch.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    /// Stable id ([`BranchId`]).
    pub id: BranchId,
    /// The backend's solution (trajectory, cost terms, statistics).
    pub solution: Solution,
    /// Ranking cost `J`.
    pub j: f64,
    /// How the trajectory was made in the last cycle.
    pub origin: Origin,
    /// Whether that solve was warm-started.
    pub warm_started: bool,
    /// Its safety check in the last cycle.
    pub verdict: SafetyVerdict,
}

impl Branch {
    /// The branch's trajectory.
    pub fn traj(&self) -> &PolyTraj {
        &self.solution.traj
    }

    fn report(&self, main: bool) -> BranchReport {
        BranchReport {
            id: self.id,
            main,
            origin: self.origin,
            j: self.j,
            costs: self.solution.costs,
            status: self.solution.stats.status,
            solve_ms: ms(self.solution.stats.elapsed),
            evaluation_count: self.solution.stats.evaluation_count,
            warm_started: self.warm_started,
            min_margin_m: self.verdict.min_margin_m(),
            duration_s: self.solution.traj.duration(),
        }
    }
}

/// A solved (or failed) candidate of this cycle.
struct Candidate {
    result: Result<(Solution, SafetyVerdict), PlanError>,
    check_time: Duration,
    /// The other solve of a repair attempt ([`ManagerParams::repair_margin_m`]): the narrowly
    /// unsafe first solve when the re-solve passed and replaced it, the failed re-solve when it
    /// did not. Its solve time, evaluations and check time count in the cycle's timing.
    other_solve: Option<(Duration, usize, Duration)>,
    /// The re-solve of a repair attempt passed and is this candidate.
    repaired: bool,
}

/// Whether `v` failed by at most `margin` (m) of clearance, or only on the limits.
fn narrowly_unsafe(v: &SafetyVerdict, margin: f64) -> bool {
    !v.safe
        && match &v.violation {
            Some(x) => x.margin_m >= -margin,
            None => true,
        }
}

/// The multi-branch spatio-temporal trajectory manager (paper Sec. III-A, Algorithm 1), generic
/// over the frontend `F`, the backend `B` and the homotopy checker `H`.
///
/// It keeps up to `N` branches of distinct spatio-temporal homotopy sorted by the ranking cost
/// `J = λ_t·H_t + λ_s·H_s + λ_e·I_e` and commits the main branch as the plan the vehicle flies.
/// Each [`Manager::step`] is one cycle:
///
/// 1. **Replan start.** The new trajectories start from the state the vehicle will be in when they
///    take effect: the committed plan at `now + latency` (so consecutive plans join with continuous
///    position, velocity and acceleration). If the measured state has drifted from the committed
///    plan by more than [`crate::ReanchorParams`], the replan starts instead from the measured state
///    propagated over the latency at constant acceleration (`Reanchored` event): continuity is then
///    given up in favour of the truth.
/// 2. **FwdMarch** of the main branch and **BwdReplan** of every sub-branch: warm-started re-solves
///    from the replan start (the main branch's free terminal moves on toward the goal as the goal
///    guidance surface shrinks), run in parallel with **FwdExplore**: the frontend's paths from the
///    replan start, each solved cold. With `history = false` only FwdExplore runs.
/// 3. **Safety.** Every result is checked continuously in time ([`check_trajectory`]) against the
///    static map, the bounds and the *current* forecasts, and against the limits; a failing branch
///    is dropped (`DroppedCollision`).
/// 4. **Distinct classes.** Re-solved branches that slid into the same class as a better one are
///    merged (`MergedEquivalent`); then **AddNewBranch** for each explored trajectory, in the frontend's order: if the checker finds
///    it equivalent to a kept branch with a `J` at least as low it is discarded; if it is equivalent
///    only to worse branches it replaces the best-ranked of them (which keeps its id); otherwise it
///    is added. Beyond `N` branches the worst is dropped (`PopBack`), never the main branch.
/// 5. **Main branch.** The incumbent stays main unless a challenger's excess cost is below the
///    hysteresis factor times the incumbent's, or the incumbent was dropped.
/// 6. **Fallback.** With no feasible branch the plan is a braking trajectory ([`crate::brake`]):
///    along the committed plan (or along a rejected trajectory of this cycle, or straight), the first
///    that passes the safety check against the current forecasts, else the one with the largest
///    margin. The report says which and whether it is collision-free; it is collision-free for as
///    long as the forecasts hold only in the first case.
///
/// Optimizations of one cycle run in parallel on the current rayon pool; results are merged in a
/// fixed order (warm branches by rank, then explored paths by the frontend's order), so the outcome
/// does not depend on the number of threads or their timing as long as no time budget binds (set
/// [`ManagerParams::enforce_budget`] to `false` and give the frontend count-based budgets for
/// bit-reproducible runs).
pub struct Manager<F, B, H> {
    frontend: F,
    backend: B,
    checker: H,
    limits: Limits,
    params: ManagerParams,
    rng: Rng,
    branches: Vec<Branch>,
    main: Option<BranchId>,
    committed: Option<PolyTraj>,
    next_id: BranchId,
    cycle_count: u64,
}

impl<F, B, H> std::fmt::Debug for Manager<F, B, H> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Manager")
            .field("limits", &self.limits)
            .field("params", &self.params)
            .field("branches", &self.branches.len())
            .field("main", &self.main)
            .finish_non_exhaustive()
    }
}

impl<F: PathFrontend, B: TrajectoryBackend, H: HomotopyChecker> Manager<F, B, H> {
    /// A manager with no branches and no plan yet.
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] naming the invalid field of `limits` or `params`.
    pub fn new(
        frontend: F,
        backend: B,
        checker: H,
        limits: Limits,
        params: ManagerParams,
    ) -> Result<Self, PlanError> {
        limits.validate()?;
        params.validate()?;
        Ok(Manager {
            frontend,
            backend,
            checker,
            limits,
            rng: Rng::seed_from_u64(params.seed),
            params,
            branches: Vec::new(),
            main: None,
            committed: None,
            next_id: 0,
            cycle_count: 0,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &ManagerParams {
        &self.params
    }

    /// The vehicle's limits.
    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// The kept branches, sorted by `J`.
    pub fn branches(&self) -> &[Branch] {
        &self.branches
    }

    /// The main branch's id (`None` before the first plan and while braking).
    pub fn main(&self) -> Option<BranchId> {
        self.main
    }

    /// The committed plan: the main branch's trajectory or the braking fallback.
    pub fn plan(&self) -> Option<&PolyTraj> {
        self.committed.as_ref()
    }

    /// Forgets every branch and the plan (a new flight); the random stream continues.
    pub fn reset(&mut self) {
        self.cycle_count = 0;
        self.branches.clear();
        self.main = None;
        self.committed = None;
    }

    /// Runs one cycle of Algorithm 1 at time `now` with the measured vehicle state (taken at
    /// `now`), toward `goal`, seeing `scene` (the static map and the current forecasts).
    ///
    /// Planning failures are reported in the [`StepReport`] (events, fallback); the committed plan
    /// afterwards is [`Manager::plan`].
    ///
    /// # Errors
    /// Only for invalid input: non-finite `now`, state or goal (named), a goal outside the map
    /// bounds ([`PlanError::OutOfBounds`]) or inside a static obstacle
    /// ([`PlanError::InCollision`]).
    pub fn step(
        &mut self,
        now: f64,
        measured: &State,
        goal: &Vec3,
        scene: &Scene<'_>,
    ) -> Result<StepReport, PlanError> {
        let started = Instant::now();
        check_finite("now", now)?;
        measured.validate("state")?;
        check_finite_vec("goal", goal)?;
        scene.check_in_bounds("goal", goal)?;
        scene.check_static_free("goal", goal, 0.0)?;

        let weights = self.params.ranking_weights(&self.limits);
        let mut events = Vec::new();
        let (start, reanchored) = self.replan_start(now, measured, &mut events);
        let deadline = self
            .params
            .enforce_budget
            .then(|| started + Duration::from_secs_f64(self.params.cycle_budget_ms * 1e-3));

        // Warm re-solves (FwdMarch, BwdReplan) in parallel with the frontend, then the cold solves.
        let history = self.params.history;
        let warm: Vec<(BranchId, Origin, PolyTraj)> = if history {
            self.branches
                .iter()
                .map(|b| {
                    let origin = if Some(b.id) == self.main {
                        Origin::Marched
                    } else {
                        Origin::Replanned
                    };
                    (b.id, origin, b.solution.traj.clone())
                })
                .collect()
        } else {
            Vec::new()
        };
        let query = PathQuery {
            start,
            goal: *goal,
            limits: self.limits,
            horizon_s: self.params.horizon_s,
        };
        let solver = Solver {
            backend: &self.backend,
            scene,
            start,
            goal: *goal,
            limits: self.limits,
            horizon_s: self.params.horizon_s,
            deadline,
            params: &self.params,
        };
        let explore = !history
            || self
                .cycle_count
                .is_multiple_of(self.params.explore_period_cycles as u64)
            || self.branches.len() < 2
            || self.main.is_none();
        self.cycle_count += 1;
        let frontend = &self.frontend;
        let rng = &mut self.rng;
        let (search, warm_out) = rayon::join(
            || {
                let t = Instant::now();
                let r = if explore {
                    Some(frontend.search(&query, scene, rng))
                } else {
                    None
                };
                (r, t.elapsed())
            },
            || {
                warm.par_iter()
                    .map(|(_, origin, traj)| {
                        let budget = match origin {
                            Origin::Replanned => solver.params.sub_branch_max_evaluations,
                            _ => None,
                        }
                        .or(solver.params.warm_max_evaluations);
                        solver.repaired(solver.solve_with(InitialGuess::WarmStart(traj), budget))
                    })
                    .collect::<Vec<_>>()
            },
        );
        let (search, frontend_time) = search;
        let (paths, frontend_report) = match search {
            None => (Vec::new(), None),
            Some(Ok(mut result)) => {
                let path_count = result.paths.len();
                result.paths.truncate(self.params.max_explored_paths);
                let report = FrontendReport {
                    name: self.frontend.name().to_string(),
                    path_count,
                    explored_count: result.paths.len(),
                    stats: result.stats,
                };
                (result.paths, Some(report))
            }
            Some(Err(e)) => {
                events.push(Event::FrontendFailed {
                    error: e.to_string(),
                });
                (Vec::new(), None)
            }
        };
        let mut paths = paths;
        let mut fallback_guide = false;
        if explore && paths.is_empty() && self.params.straight_guide_when_empty {
            // Beyond the paper: never explore empty-handed. The frontend's cones are
            // conservative (an obstacle's whole sweep over the horizon), so in crowded moments it
            // may find no path while a trajectory that passes behind an obstacle exists; the
            // straight guide lets the backend look for it in time.
            let reach = self.params.horizon_s * self.limits.v_max;
            let d = (goal - start.p).norm();
            let end = if d <= reach || d == 0.0 {
                *goal
            } else {
                start.p + (goal - start.p) * (reach / d)
            };
            if let Ok(g) = GuidePath::new(vec![start.p, end]) {
                paths.push(g);
                fallback_guide = true;
            }
        }
        let cold_out: Vec<Candidate> = paths
            .par_iter()
            .map(|p: &GuidePath| {
                solver.repaired(
                    solver.solve_with(InitialGuess::Guide(p), self.params.cold_max_evaluations),
                )
            })
            .collect();

        let mut timing = CycleTiming {
            frontend_ms: ms(frontend_time),
            ..CycleTiming::default()
        };
        let mut rejected: Vec<(&'static str, PolyTraj)> = Vec::new();

        // Kept branches, re-solved.
        let mut kept: Vec<Branch> = Vec::new();
        for ((id, origin, _), cand) in warm.into_iter().zip(warm_out) {
            timing.add(&cand, false);
            if cand.repaired {
                events.push(Event::Repaired { id: Some(id) });
            }
            let failed = match cand.result {
                Err(e) => {
                    events.push(Event::SolveFailed {
                        id: Some(id),
                        error: e.to_string(),
                    });
                    true
                }
                Ok((solution, verdict)) if verdict.safe => {
                    kept.push(Branch {
                        id,
                        j: solution.costs.ranking_cost(&weights),
                        solution,
                        origin,
                        warm_started: true,
                        verdict,
                    });
                    false
                }
                Ok((solution, verdict)) => {
                    events.push(dropped_collision(Some(id), &verdict, &self.limits));
                    rejected.push(("branch", solution.traj));
                    true
                }
            };
            if failed && origin == Origin::Marched && !reanchored {
                let t = Instant::now();
                if let Some(b) = self.keep_committed(id, &start, scene, &weights) {
                    events.push(Event::KeptCommitted { id });
                    kept.push(b);
                }
                timing.checker_ms += ms(t.elapsed());
            }
        }
        sort_by_j(&mut kept);
        let mut check_time = Duration::ZERO;
        if kept.len() > 1 {
            let t = Instant::now();
            kept = self.dedupe(kept, scene, &mut events);
            check_time += t.elapsed();
        }

        // AddNewBranch for each explored trajectory.
        let incumbent = if history { self.main } else { None };
        for cand in cold_out {
            timing.add(&cand, true);
            if cand.repaired {
                events.push(Event::Repaired { id: None });
            }
            match cand.result {
                Err(e) => events.push(Event::SolveFailed {
                    id: None,
                    error: e.to_string(),
                }),
                Ok((solution, verdict)) if !verdict.safe => {
                    events.push(dropped_collision(None, &verdict, &self.limits));
                    rejected.push(("candidate", solution.traj));
                }
                Ok((solution, verdict)) => {
                    let t = Instant::now();
                    let new = Branch {
                        id: 0,
                        j: solution.costs.ranking_cost(&weights),
                        solution,
                        origin: Origin::Explored,
                        warm_started: false,
                        verdict,
                    };
                    self.add_new_branch(&mut kept, new, scene, incumbent, &mut events);
                    check_time += t.elapsed();
                }
            }
        }
        timing.checker_ms += ms(check_time);

        // The main branch, with hysteresis.
        let new_main = self.select_main(&kept, &start, goal, &weights, &mut events);
        pop_back(&mut kept, self.params.max_branches, new_main, &mut events);

        let mut fallback = None;
        match new_main.and_then(|id| kept.iter().find(|b| b.id == id)) {
            Some(main) => {
                self.committed = Some(main.solution.traj.clone());
                self.main = Some(main.id);
            }
            None => {
                let t = Instant::now();
                let report = self.fallback(&start, reanchored, &rejected, scene, &mut events);
                timing.checker_ms += ms(t.elapsed());
                fallback = report;
                self.main = None;
            }
        }
        self.branches = kept;
        timing.wall_ms = ms(started.elapsed());
        Ok(StepReport {
            t: now,
            replan_start: start,
            main: self.main,
            branches: self
                .branches
                .iter()
                .map(|b| b.report(Some(b.id) == self.main))
                .collect(),
            events,
            frontend: frontend_report,
            straight_guide: fallback_guide,
            timing,
            fallback,
        })
    }

    /// The state the new plan starts from, and whether it was re-anchored on the measurement.
    fn replan_start(&self, now: f64, measured: &State, events: &mut Vec<Event>) -> (State, bool) {
        let latency = self.params.latency();
        let t_eff = now + latency;
        if let Some(plan) = &self.committed {
            let expected = plan.state(now);
            let dp = (measured.p - expected.p).norm();
            let dv = (measured.v - expected.v).norm();
            if dp <= self.params.reanchor.position_m && dv <= self.params.reanchor.velocity_mps {
                let mut s = plan.state(t_eff);
                s.t = t_eff;
                return (s, false);
            }
            events.push(Event::Reanchored {
                position_drift_m: dp,
                velocity_drift_mps: dv,
            });
        }
        let l = latency;
        let start = State {
            t: t_eff,
            p: measured.p + measured.v * l + measured.a * (0.5 * l * l),
            v: measured.v + measured.a * l,
            a: measured.a,
        };
        (start, self.committed.is_some())
    }

    /// The main branch with its previous (committed) trajectory, if that still passes the safety
    /// check from the replan start under the current forecasts: a re-solve that fails (pushed into
    /// a squeeze, or out of budget) must not throw away a plan that is still good.
    fn keep_committed(
        &self,
        id: BranchId,
        start: &State,
        scene: &Scene<'_>,
        weights: &RankingWeights,
    ) -> Option<Branch> {
        let plan = self.committed.as_ref()?;
        let previous = self.branches.iter().find(|b| b.id == id)?;
        if previous.solution.traj != *plan || plan.t_end() <= start.t {
            return None;
        }
        let verdict = check_trajectory(
            plan,
            scene,
            start.t,
            plan.t_end(),
            &self.limits,
            &self.params.safety,
        );
        verdict.safe.then(|| Branch {
            id,
            j: previous.solution.costs.ranking_cost(weights),
            solution: previous.solution.clone(),
            origin: Origin::Kept,
            warm_started: false,
            verdict,
        })
    }

    /// Keeps the re-solved branches homotopy-distinct: a warm re-solve can slide into another
    /// branch's class, and the queue must hold one branch per class. Walking in `J` order, a
    /// branch equivalent to an already kept one is dropped (`MergedEquivalent`).
    fn dedupe(
        &self,
        sorted: Vec<Branch>,
        scene: &Scene<'_>,
        events: &mut Vec<Event>,
    ) -> Vec<Branch> {
        let mut out: Vec<Branch> = Vec::with_capacity(sorted.len());
        'branches: for b in sorted {
            for k in &out {
                match self.equivalent(&b.solution.traj, &k.solution.traj, scene) {
                    Ok(true) => {
                        events.push(Event::MergedEquivalent {
                            dropped: b.id,
                            kept: k.id,
                        });
                        continue 'branches;
                    }
                    Ok(false) => {}
                    Err(e) => events.push(Event::CheckerFailed {
                        error: e.to_string(),
                    }),
                }
            }
            out.push(b);
        }
        out
    }

    /// AddNewBranch of Algorithm 1 (see the type's docs), then PopBack beyond `N` protecting the
    /// incumbent main branch.
    fn add_new_branch(
        &mut self,
        kept: &mut Vec<Branch>,
        mut new: Branch,
        scene: &Scene<'_>,
        incumbent: Option<BranchId>,
        events: &mut Vec<Event>,
    ) {
        let mut worse_equivalent = None;
        for (i, b) in kept.iter().enumerate() {
            match self.equivalent(&new.solution.traj, &b.solution.traj, scene) {
                Ok(true) if b.j <= new.j => {
                    events.push(Event::DiscardedEquivalent {
                        equivalent_to: b.id,
                    });
                    return;
                }
                Ok(true) => {
                    worse_equivalent.get_or_insert(i);
                }
                Ok(false) => {}
                Err(e) => events.push(Event::CheckerFailed {
                    error: e.to_string(),
                }),
            }
        }
        match worse_equivalent {
            Some(i) => {
                new.id = kept[i].id;
                events.push(Event::Replaced {
                    id: new.id,
                    j_old: kept[i].j,
                    j_new: new.j,
                });
                kept[i] = new;
            }
            None => {
                new.id = self.next_id;
                self.next_id += 1;
                events.push(Event::Added { id: new.id });
                kept.push(new);
            }
        }
        sort_by_j(kept);
        pop_back(kept, self.params.max_branches, incumbent, events);
    }

    /// The checker on a scene restricted to the forecasts that can reach the two trajectories.
    fn equivalent(&self, a: &PolyTraj, b: &PolyTraj, scene: &Scene<'_>) -> Result<bool, PlanError> {
        let from = a.t_start().min(b.t_start());
        let until = a.t_end().max(b.t_end());
        let (_, box_a) = window_bounds(a, from, until);
        let (_, box_b) = window_bounds(b, from, until);
        let region: Aabb = box_a.union(&box_b);
        let near: Vec<Forecast> = scene
            .forecasts
            .iter()
            .filter(|f| {
                f.aabb_over(from, until)
                    .map(|x| x.intersects(&region))
                    .unwrap_or(true)
            })
            .copied()
            .collect();
        let sub = Scene {
            map: scene.map,
            forecasts: &near,
            t0: scene.t0,
        };
        self.checker.equivalent(a, b, &sub)
    }

    /// The new main branch (hysteresis), with its event.
    fn select_main(
        &self,
        kept: &[Branch],
        start: &State,
        goal: &Vec3,
        weights: &RankingWeights,
        events: &mut Vec<Event>,
    ) -> Option<BranchId> {
        let ideal =
            weights.lambda_s.min(weights.lambda_t / self.limits.v_max) * (start.p - goal).norm();
        let ranked: Vec<(BranchId, f64)> = kept.iter().map(|b| (b.id, b.j)).collect();
        let incumbent = self.main.filter(|_| self.params.history);
        let decision = choose_main(&ranked, incumbent, ideal, self.params.hysteresis)?;
        if decision.switched && self.params.history {
            let reason = match (incumbent, decision.incumbent_kept) {
                (None, _) => "first",
                (Some(_), true) => "better",
                (Some(_), false) => "incumbent_dropped",
            };
            events.push(Event::SwitchedMain {
                from: self.main,
                to: decision.main,
                reason: reason.into(),
            });
        }
        Some(decision.main)
    }

    /// Builds the braking fallback, commits it and reports it.
    fn fallback(
        &mut self,
        start: &State,
        reanchored: bool,
        rejected: &[(&'static str, PolyTraj)],
        scene: &Scene<'_>,
        events: &mut Vec<Event>,
    ) -> Option<FallbackReport> {
        let hold_s = self.params.horizon_s;
        let a_max = self.limits.a_max;
        let mut options: Vec<(&'static str, PolyTraj)> = Vec::new();
        if let Some(plan) = self.committed.as_ref().filter(|_| !reanchored)
            && let Ok(b) = brake_along(plan, start.t, a_max, hold_s)
        {
            options.push(("committed", b));
        }
        for (kind, traj) in rejected {
            if let Ok(b) = brake_along(traj, start.t, a_max, hold_s) {
                options.push((kind, b));
            }
        }
        if let Ok(b) = brake_straight(start, a_max, hold_s) {
            options.push(("straight", b));
        }
        // The first collision-free option; else the one that collides latest, then least deeply.
        let mut best: Option<(usize, SafetyVerdict)> = None;
        let rank =
            |v: &SafetyVerdict| (v.violation.map_or(f64::INFINITY, |x| x.t), v.min_margin_m());
        for (i, (_, traj)) in options.iter().enumerate() {
            let v = assess_trajectory(
                traj,
                scene,
                start.t,
                traj.t_end(),
                &self.limits,
                &self.params.safety,
            );
            if v.violation.is_none() {
                best = Some((i, v));
                break;
            }
            if best.as_ref().is_none_or(|(_, b)| {
                rank(&v).partial_cmp(&rank(b)) == Some(std::cmp::Ordering::Greater)
            }) {
                best = Some((i, v));
            }
        }
        let (i, verdict) = best?;
        let (along, traj) = options.swap_remove(i);
        let collision_free = verdict.violation.is_none();
        let stop_time = traj.t_end() - hold_s;
        events.push(Event::Fallback {
            along: along.into(),
            collision_free,
            min_margin_m: verdict.min_margin_m(),
        });
        self.committed = Some(traj);
        Some(FallbackReport {
            along: along.into(),
            collision_free,
            min_margin_m: verdict.min_margin_m(),
            stop_time,
        })
    }
}

/// The event of a trajectory dropped by the safety check with `verdict`.
fn dropped_collision(id: Option<BranchId>, verdict: &SafetyVerdict, limits: &Limits) -> Event {
    Event::DroppedCollision {
        id,
        violation: verdict.violation,
        braking_tail: verdict.braking_tail_violated,
        over_limits: verdict.over_limits.then_some(LimitExcess {
            max_speed_mps: verdict.max_speed,
            v_max: limits.v_max,
            max_accel_mps2: verdict.max_accel,
            a_max: limits.a_max,
        }),
    }
}

/// Everything a parallel solve needs, shared read-only.
struct Solver<'s, 'a, B> {
    backend: &'s B,
    scene: &'s Scene<'a>,
    start: State,
    goal: Vec3,
    limits: Limits,
    horizon_s: f64,
    deadline: Option<Instant>,
    params: &'s ManagerParams,
}

impl<B: TrajectoryBackend> Solver<'_, '_, B> {
    /// `cand` again, warm-started from its own trajectory, if it failed the safety check by at
    /// most `repair_margin_m` and the re-solve passes; otherwise `cand` unchanged.
    fn repaired(&self, cand: Candidate) -> Candidate {
        let margin = self.params.repair_margin_m;
        let first = match &cand.result {
            Ok((first, verdict)) if margin > 0.0 && narrowly_unsafe(verdict, margin) => first,
            _ => return cand,
        };
        // With the cold budget: a repair is rare and its first solve stopped short of clean.
        let again = self.solve_with(
            InitialGuess::WarmStart(&first.traj),
            self.params.cold_max_evaluations,
        );
        let spent = |c: &Candidate| {
            c.result
                .as_ref()
                .ok()
                .map(|(s, _)| (s.stats.elapsed, s.stats.evaluation_count, c.check_time))
        };
        match &again.result {
            Ok((_, verdict)) if verdict.safe => Candidate {
                other_solve: spent(&cand),
                repaired: true,
                ..again
            },
            _ => Candidate {
                other_solve: spent(&again),
                ..cand
            },
        }
    }

    fn solve_with(&self, initial: InitialGuess<'_>, max_evaluations: Option<usize>) -> Candidate {
        let req = TrajRequest {
            start: self.start,
            goal: self.goal,
            limits: self.limits,
            initial,
            deadline: self.deadline,
            horizon_s: Some(self.horizon_s),
            max_evaluations,
        };
        match self.backend.optimize(&req, self.scene) {
            Err(e) => Candidate {
                result: Err(e),
                check_time: Duration::ZERO,
                other_solve: None,
                repaired: false,
            },
            Ok(solution) => {
                let t = Instant::now();
                let traj = &solution.traj;
                let verdict = check_trajectory(
                    traj,
                    self.scene,
                    self.start.t,
                    traj.t_end(),
                    &self.limits,
                    &self.params.safety,
                );
                Candidate {
                    check_time: t.elapsed(),
                    result: Ok((solution, verdict)),
                    other_solve: None,
                    repaired: false,
                }
            }
        }
    }
}

impl CycleTiming {
    fn add(&mut self, cand: &Candidate, cold: bool) {
        self.checker_ms += ms(cand.check_time);
        if cand.repaired {
            self.repair_count += 1;
        }
        if let Some((solve, evaluations, check)) = cand.other_solve {
            self.checker_ms += ms(check);
            self.backend_ms += ms(solve);
            self.evaluations += evaluations;
            self.solve_count += 1;
            if cold {
                self.cold_backend_ms += ms(solve);
                self.cold_solve_count += 1;
            }
        }
        if let Ok((s, _)) = &cand.result {
            let solve = ms(s.stats.elapsed);
            self.backend_ms += solve;
            self.solve_count += 1;
            self.evaluations += s.stats.evaluation_count;
            if cold {
                self.cold_backend_ms += solve;
                self.cold_solve_count += 1;
            }
        }
    }
}

/// The outcome of [`choose_main`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MainDecision {
    /// The main branch.
    pub main: BranchId,
    /// Whether it differs from the incumbent (or there was none).
    pub switched: bool,
    /// Whether the incumbent is still among the ranked branches.
    pub incumbent_kept: bool,
}

/// The main-branch rule with hysteresis, on branches `ranked` by ascending `J` (`(id, J)`): the
/// incumbent stays unless the best branch's excess cost `J − ideal` is below `hysteresis` times the
/// incumbent's, or the incumbent is gone; without an incumbent the best branch is chosen. `None`
/// for no branches.
pub fn choose_main(
    ranked: &[(BranchId, f64)],
    incumbent: Option<BranchId>,
    ideal: f64,
    hysteresis: f64,
) -> Option<MainDecision> {
    let &(best, best_j) = ranked.first()?;
    let excess = |j: f64| (j - ideal).max(0.0);
    let kept = incumbent.and_then(|id| ranked.iter().find(|(i, _)| *i == id));
    Some(match kept {
        Some(&(inc, inc_j)) => {
            let switch = inc != best && excess(best_j) < hysteresis * excess(inc_j);
            MainDecision {
                main: if switch { best } else { inc },
                switched: switch,
                incumbent_kept: true,
            }
        }
        None => MainDecision {
            main: best,
            switched: true,
            incumbent_kept: false,
        },
    })
}

fn sort_by_j(branches: &mut [Branch]) {
    branches.sort_by(|a, b| a.j.total_cmp(&b.j).then(a.id.cmp(&b.id)));
}

/// Drops the worst branches beyond `n`, never `protect`.
fn pop_back(kept: &mut Vec<Branch>, n: usize, protect: Option<BranchId>, events: &mut Vec<Event>) {
    while kept.len() > n {
        let Some(i) = kept.iter().rposition(|b| Some(b.id) != protect) else {
            return;
        };
        let b = kept.remove(i);
        events.push(Event::DroppedPopBack { id: b.id });
    }
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_narrow_failures_are_repaired() {
        let verdict = |safe: bool, margin: Option<f64>| SafetyVerdict {
            safe,
            min_static_margin_m: f64::INFINITY,
            min_dynamic_margin_m: margin.unwrap_or(f64::INFINITY),
            violation: margin.map(|m| crate::safety::Violation {
                t: 1.0,
                with: crate::safety::Hit::Bounds,
                margin_m: m,
            }),
            escaping: false,
            max_speed: 1.0,
            max_accel: 1.0,
            over_limits: margin.is_none() && !safe,
            braking_tail_violated: false,
            sample_count: 10,
        };
        assert!(!narrowly_unsafe(&verdict(true, None), 0.05));
        assert!(narrowly_unsafe(&verdict(false, Some(-0.004)), 0.05));
        assert!(!narrowly_unsafe(&verdict(false, Some(-0.2)), 0.05));
        assert!(narrowly_unsafe(&verdict(false, None), 0.05), "limits only");
        assert!(!narrowly_unsafe(&verdict(false, Some(f64::NAN)), 0.05));
    }

    #[test]
    fn hysteresis_keeps_the_incumbent_unless_clearly_beaten() {
        // Ideal 20: excesses 1.0 (incumbent 7) and 0.8 (challenger 3).
        let ranked = [(3, 20.8), (7, 21.0)];
        let keep = choose_main(&ranked, Some(7), 20.0, 0.75).unwrap();
        assert_eq!((keep.main, keep.switched), (7, false));
        // Without hysteresis the better one wins.
        let switch = choose_main(&ranked, Some(7), 20.0, 1.0).unwrap();
        assert_eq!((switch.main, switch.switched), (3, true));
        // A clear win (excess 0.5 < 0.75) switches even with hysteresis.
        let ranked = [(3, 20.5), (7, 21.0)];
        let d = choose_main(&ranked, Some(7), 20.0, 0.75).unwrap();
        assert_eq!((d.main, d.switched, d.incumbent_kept), (3, true, true));
        // A dropped incumbent is replaced by the best.
        let d = choose_main(&ranked, Some(9), 20.0, 0.75).unwrap();
        assert_eq!((d.main, d.switched, d.incumbent_kept), (3, true, false));
        // First plan; no branches.
        assert_eq!(choose_main(&ranked, None, 20.0, 0.75).unwrap().main, 3);
        assert!(choose_main(&[], Some(1), 0.0, 0.75).is_none());
        // An incumbent at the ideal cost cannot be beaten by a better-ranked tie.
        let ranked = [(1, 20.0), (2, 20.0)];
        assert_eq!(choose_main(&ranked, Some(2), 20.0, 0.75).unwrap().main, 2);
    }
}

//! The worker thread of [`ManagerParams::background`]: as a cycle ends it takes the next cycle's
//! sub-branch re-solves (BwdReplan) and FwdExplore (or the deferred cold solves) from the next
//! cycle's replan start as the committed plan predicts it; the next cycle merges the results
//! ([`Manager::merge_job`]) and re-solves only the main branch itself.
//!
//! Determinism: a job owns everything it reads (a snapshot of the forecasts, the sub-branches'
//! trajectories, a copy of the random stream) and the next cycle waits for it, so the flight for
//! a seed does not depend on the worker's timing (unless a wall-clock deadline binds, as in
//! every solve with [`ManagerParams::enforce_budget`]).

use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use rayon::prelude::*;
use trust_core::{
    Forecast, GuidePath, Limits, PathFrontend, PathQuery, PolyTraj, Rng, Scene, State, StaticMap,
    TrajectoryBackend, Vec3,
};

use super::{Candidate, Explored, Solver, Spans, deadline_from, fwd_explore, solve_deferred};
use crate::ManagerParams;
use crate::report::BranchId;

/// A job under way: what it was started for, so the merging cycle can tell whether its results
/// still apply.
pub(super) struct Job {
    /// The replan start it solved from (the next cycle's, predicted).
    pub(super) start: State,
    /// The aim it solved toward.
    pub(super) aim: Vec3,
    /// Whether the flight was stalled when it started.
    pub(super) stalled: bool,
    pub(super) handle: JoinHandle<JobOutput>,
}

/// Everything a job reads, owned.
pub(super) struct JobInput<F, B> {
    pub(super) frontend: Arc<F>,
    pub(super) backend: Arc<B>,
    pub(super) map: Arc<StaticMap>,
    /// The forecasts of the cycle that started the job (growth stopped, wall images added).
    pub(super) forecasts: Vec<Forecast>,
    pub(super) t0: f64,
    pub(super) start: State,
    pub(super) aim: Vec3,
    pub(super) limits: Limits,
    pub(super) params: ManagerParams,
    /// Run FwdExplore (else solve the deferred guides).
    pub(super) explore: bool,
    pub(super) stalled: bool,
    /// The main branch's trajectory (re-solved first, FwdMarch).
    pub(super) main: Option<PolyTraj>,
    /// The sub-branches to re-solve, in rank order.
    pub(super) subs: Vec<(BranchId, PolyTraj)>,
    pub(super) deferred: Vec<GuidePath>,
    pub(super) route_guide: Option<GuidePath>,
    pub(super) rng: Rng,
}

/// What a job found.
pub(super) struct JobOutput {
    /// The random stream after the frontend's draws (the manager continues it).
    pub(super) rng: Rng,
    /// The main branch re-solved (FwdMarch), if there was one.
    pub(super) main: Option<Candidate>,
    /// The sub-branches re-solved, in the input's order.
    pub(super) subs: Vec<(BranchId, Candidate)>,
    pub(super) explored: Explored,
    pub(super) frontend_ms: f64,
    /// The job's wall time.
    pub(super) elapsed: Duration,
}

/// Runs a job on the calling thread (the worker): the same work as a cycle's
/// `solve_in_parallel` without the main branch, in parallel on the rayon pool.
pub(super) fn run<F: PathFrontend, B: TrajectoryBackend>(input: JobInput<F, B>) -> JobOutput {
    let started = Instant::now();
    let mut spans = Spans::start();
    let JobInput {
        frontend,
        backend,
        map,
        forecasts,
        t0,
        start,
        aim,
        limits,
        params,
        explore,
        stalled,
        main,
        subs,
        deferred,
        route_guide,
        mut rng,
    } = input;
    // The forecasts were validated when the cycle's scene was built.
    let scene = Scene {
        map: &map,
        forecasts: &forecasts,
        t0,
    };
    let solver = Solver::new(
        &*backend,
        &scene,
        (start, aim, limits),
        &params,
        deadline_from(started, &params),
        stalled,
        route_guide,
    );
    let query = PathQuery {
        start,
        goal: aim,
        limits,
        horizon_s: params.horizon_s,
        exploration: if stalled { 2.0 } else { 1.0 },
    };
    let (explored, (main, subs)) = rayon::join(
        || match explore {
            true => fwd_explore(&*frontend, &mut rng, &query, &solver, &mut spans),
            false => solve_deferred(deferred, &solver),
        },
        || {
            rayon::join(
                || {
                    let budget = params
                        .worker_march_max_evaluations
                        .or(params.warm_max_evaluations);
                    main.map(|traj| solver.fwd_march_within(&traj, budget))
                },
                || {
                    subs.par_iter()
                        .map(|(id, traj)| (*id, solver.bwd_replan(traj)))
                        .collect()
                },
            )
        },
    );
    JobOutput {
        rng,
        main,
        subs,
        explored,
        frontend_ms: spans.timing.frontend_ms,
        elapsed: started.elapsed(),
    }
}

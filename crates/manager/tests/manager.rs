//! The manager's public API on scripted scenes, with the real frontend, backend and checker
//! (DEV-PRM, UTF-MINCO, TVD) and with small test doubles where a situation must be forced.

use rand::SeedableRng;
use trust_core::{
    Aabb, CostBreakdown, Forecast, GuidePath, Limits, ObstacleShape, PathFrontend, PathQuery,
    PlanError, PolyTraj, Rng, Scene, SearchResult, Solution, SolveStats, SolveStatus, State,
    StaticMap, TrajRequest, TrajectoryBackend, Vec3,
};
use trust_geometry::{AaBox, Shape};
use trust_manager::{
    Event, FallbackKind, Manager, ManagerParams, Origin, StepReport, check_trajectory,
};
use trust_minco::UtfMinco;
use trust_topo_prm::scenes::{SceneParams, random_dynamic_scene};
use trust_topo_prm::{DevPrm, DevPrmParams, StraightLine, Tvd};

/// Count-bounded (machine-independent) parameters.
fn reproducible(mut p: ManagerParams) -> ManagerParams {
    p.enforce_budget = false;
    p.safety.static_clearance_m = 0.2;
    p
}

fn dev_prm() -> DevPrm {
    DevPrm::new(DevPrmParams {
        budget_ms: 10_000.0,
        ..DevPrmParams::default()
    })
    .expect("valid")
}

type Planner = Manager<DevPrm, UtfMinco, Tvd>;

/// UTF-MINCO keeping 0.3 m from the static map, more than the 0.2 m the safety check requires.
fn utf_minco() -> UtfMinco {
    let mut p = trust_minco::UtfMincoParams::default();
    p.penalty.static_clearance_m = 0.3;
    UtfMinco::new(p).expect("valid")
}

fn planner(params: ManagerParams) -> Planner {
    Manager::new(
        dev_prm(),
        utf_minco(),
        Tvd::default(),
        Limits::default(),
        reproducible(params),
    )
    .expect("valid")
}

/// A 40 × 12 × 6 m corridor with a wall at x ∈ [14, 15] that has two gaps, y ∈ [-4, -1] and
/// y ∈ [1, 4]: two homotopy classes from (2, 0, 3) to (38, 0, 3).
fn two_gap_corridor() -> StaticMap {
    let bounds = Aabb::new(Vec3::new(0.0, -6.0, 0.0), Vec3::new(40.0, 6.0, 6.0)).unwrap();
    let wall = |y0: f64, y1: f64| {
        Shape::AaBox(AaBox::new(Vec3::new(14.0, y0, 0.0), Vec3::new(15.0, y1, 6.0)).unwrap())
    };
    StaticMap::from_shapes(
        bounds,
        vec![wall(-6.0, -4.0), wall(-1.0, 1.0), wall(4.0, 6.0)],
    )
    .unwrap()
}

const START: Vec3 = Vec3::new(2.0, 0.0, 3.0);
const GOAL: Vec3 = Vec3::new(38.0, 0.0, 3.0);

/// Flies the plan perfectly for `cycles` cycles of 0.1 s, calling `scene_at(t)` for the forecasts.
fn fly<F, B, H>(
    m: &mut Manager<F, B, H>,
    map: &StaticMap,
    goal: Vec3,
    start: State,
    cycles: usize,
    forecasts_at: impl Fn(f64) -> Vec<Forecast>,
) -> Vec<StepReport>
where
    F: PathFrontend + 'static,
    B: TrajectoryBackend + 'static,
    H: trust_core::HomotopyChecker,
{
    let mut state = start;
    let mut reports = Vec::new();
    for k in 0..cycles {
        let t = start.t + 0.1 * k as f64;
        let forecasts = forecasts_at(t);
        let scene = Scene::new(map, &forecasts, t).unwrap();
        reports.push(m.step(t, &state, &goal, &scene).expect("valid input"));
        state = m.plan().expect("a plan").state(t + 0.1);
    }
    reports
}

fn gap_side(traj: &PolyTraj) -> f64 {
    // y where the trajectory crosses the wall's plane x = 14.5.
    let mut t = traj.t_start();
    while t < traj.t_end() {
        let p = traj.position(t);
        if p.x >= 14.5 {
            return p.y;
        }
        t += 0.01;
    }
    f64::NAN
}

#[test]
fn keeps_both_gaps_and_switches_to_the_kept_branch_when_the_main_gap_is_blocked() {
    let map = two_gap_corridor();
    let mut m = planner(ManagerParams::trust());
    let start = State::at_rest(0.0, START);
    let reports = fly(&mut m, &map, GOAL, start, 5, |_| Vec::new());
    let last = reports.last().unwrap();
    assert!(
        last.branches.len() >= 2,
        "both gap classes kept: {:?}",
        last.branches
    );
    let main_id = m.main().expect("a main branch");
    let main_side = gap_side(m.plan().unwrap()).signum();
    let sub = m
        .branches()
        .iter()
        .find(|b| b.id != main_id && gap_side(b.traj()).signum() == -main_side)
        .expect("a sub-branch through the other gap");
    let sub_id = sub.id;

    // An obstacle turns into the main branch's gap and parks there.
    let t = 0.5;
    let blocker = Forecast::new(
        ObstacleShape::Sphere,
        Vec3::new(14.5, 2.5 * main_side, 3.0),
        Vec3::zeros(),
        t,
        1.6,
        0.3,
        0.1,
    )
    .unwrap();
    let forecasts = [blocker];
    let scene = Scene::new(&map, &forecasts, t).unwrap();
    let state = m.plan().unwrap().state(t);
    let report = m.step(t, &state, &GOAL, &scene).unwrap();
    assert_eq!(report.main, Some(sub_id), "events: {:?}", report.events);
    assert!(report.switched(), "{:?}", report.events);
    let plan = m.plan().unwrap();
    assert_eq!(gap_side(plan).signum(), -main_side);
    let verdict = check_trajectory(
        plan,
        &scene,
        plan.t_start(),
        plan.t_end(),
        &Limits::default(),
        &m.params().safety,
    );
    assert!(verdict.safe, "{verdict:?}");
}

#[test]
fn consecutive_plans_join_continuously() {
    let map = two_gap_corridor();
    let mut m = planner(ManagerParams::trust());
    let mut state = State::at_rest(0.0, START);
    let mut previous: Option<PolyTraj> = None;
    for k in 0..12 {
        let t = 0.1 * k as f64;
        let scene = Scene::new(&map, &[], t).unwrap();
        let report = m.step(t, &state, &GOAL, &scene).unwrap();
        let plan = m.plan().unwrap().clone();
        let t0 = report.replan_start.t;
        assert_eq!(plan.t_start(), t0);
        if let Some(prev) = &previous {
            let (a, b) = (prev.state(t0), plan.state(t0));
            assert!((a.p - b.p).norm() < 1e-9, "position jump at {t0}");
            assert!((a.v - b.v).norm() < 1e-9, "velocity jump at {t0}");
            assert!((a.a - b.a).norm() < 1e-9, "acceleration jump at {t0}");
        }
        state = plan.state(t + 0.1);
        previous = Some(plan);
    }
}

#[test]
fn an_exploring_cycle_solves_at_most_cold_solves_per_cycle_and_leaves_the_rest_for_the_next() {
    // Every cycle explores with one cold solve at most: the frontend's other paths are solved
    // in the following (non-exploring) cycles, so the cold solves of a flight are spread.
    let map = two_gap_corridor();
    let limited = ManagerParams {
        cold_solves_per_cycle: Some(1),
        explore_period_cycles: 3,
        ..ManagerParams::trust()
    };
    let mut m = planner(limited);
    let reports = fly(&mut m, &map, GOAL, State::at_rest(0.0, START), 12, |_| {
        Vec::new()
    });
    assert!(
        reports
            .iter()
            .all(|r| r.timing.cold_solve_count <= 1 + r.timing.repair_count)
    );
    let explored: usize = reports
        .iter()
        .filter_map(|r| r.frontend.as_ref())
        .map(|f| f.explored_count)
        .sum();
    assert!(explored >= 2, "the frontend gave several paths");
    let later = reports
        .iter()
        .filter(|r| r.frontend.is_none() && r.timing.cold_solve_count > 0)
        .count();
    assert!(
        later >= 1,
        "deferred paths are solved in non-exploring cycles"
    );
    // Without the limit the first (exploring) cycle solves all its paths at once.
    let mut all = planner(ManagerParams {
        cold_solves_per_cycle: None,
        ..ManagerParams::trust()
    });
    let first = &fly(&mut all, &map, GOAL, State::at_rest(0.0, START), 1, |_| {
        Vec::new()
    })[0];
    assert!(first.timing.cold_solve_count >= 2, "{:?}", first.timing);
    assert!(
        ManagerParams {
            cold_solves_per_cycle: Some(0),
            ..ManagerParams::trust()
        }
        .validate()
        .is_err()
    );
}

#[test]
fn re_solves_respect_their_evaluation_budgets() {
    // The main branch's FwdMarch gets `warm_max_evaluations`, each sub-branch's BwdReplan the
    // smaller `sub_branch_max_evaluations` (repairs off: a repair re-solves with the cold budget).
    // The backend counts one more evaluation than the solver's: the one that packages the result.
    let map = two_gap_corridor();
    let mut m = planner(ManagerParams {
        warm_max_evaluations: Some(40),
        sub_branch_max_evaluations: Some(9),
        repair_margin_m: 0.0,
        ..ManagerParams::trust()
    });
    let reports = fly(&mut m, &map, GOAL, State::at_rest(0.0, START), 8, |_| {
        Vec::new()
    });
    let mut seen = (0, 0);
    for r in &reports {
        for b in &r.branches {
            match b.origin {
                Origin::Marched => {
                    assert!(b.evaluation_count <= 41, "main branch: {b:?}");
                    seen.0 += 1;
                }
                Origin::Replanned => {
                    assert!(b.evaluation_count <= 10, "sub-branch: {b:?}");
                    seen.1 += 1;
                }
                _ => {}
            }
        }
    }
    assert!(
        seen.0 > 0 && seen.1 > 0,
        "marched / replanned seen: {seen:?}"
    );
}

#[test]
fn with_the_worker_the_main_branch_is_re_solved_within_the_merge_budget() {
    // A cycle that merges the worker's job re-solves the main branch from the worker's re-solve
    // with `merge_max_evaluations`; the sub-branches come from the worker with theirs.
    let map = std::sync::Arc::new(two_gap_corridor());
    let mut m = planner(ManagerParams {
        warm_max_evaluations: Some(40),
        merge_max_evaluations: Some(6),
        sub_branch_max_evaluations: Some(9),
        repair_margin_m: 0.0,
        ..ManagerParams::trust()
    });
    m.share_map(std::sync::Arc::clone(&map));
    let reports = fly(&mut m, &map, GOAL, State::at_rest(0.0, START), 10, |_| {
        Vec::new()
    });
    let mut merged_mains = 0;
    for r in reports.iter().filter(|r| r.timing.worker_ms > 0.0) {
        for b in &r.branches {
            match b.origin {
                Origin::Marched => {
                    assert!(b.evaluation_count <= 7, "main branch: {b:?}");
                    merged_mains += 1;
                }
                Origin::Replanned => assert!(b.evaluation_count <= 10, "sub-branch: {b:?}"),
                _ => {}
            }
        }
    }
    assert!(
        merged_mains >= 5,
        "merged cycles with a main branch: {merged_mains}"
    );
}

#[test]
fn a_worker_that_converges_the_main_branch_leaves_the_cycle_little_to_re_solve() {
    // The cycle's own re-solve of the main branch starts from the worker's: the more of it the
    // worker did (`worker_march_max_evaluations`), the fewer evaluations remain on the cycle.
    let map = std::sync::Arc::new(two_gap_corridor());
    let in_cycle = |worker_budget: usize| {
        let mut m = planner(ManagerParams {
            warm_max_evaluations: Some(60),
            worker_march_max_evaluations: Some(worker_budget),
            repair_margin_m: 0.0,
            ..ManagerParams::trust()
        });
        m.share_map(std::sync::Arc::clone(&map));
        let reports = fly(&mut m, &map, GOAL, State::at_rest(0.0, START), 12, |_| {
            Vec::new()
        });
        let marched: Vec<usize> = reports
            .iter()
            .filter(|r| r.timing.worker_ms > 0.0)
            .flat_map(|r| r.branches.iter())
            .filter(|b| b.origin == Origin::Marched)
            .map(|b| b.evaluation_count)
            .collect();
        assert!(
            marched.len() >= 5,
            "merged cycles with a main branch: {marched:?}"
        );
        marched.iter().sum::<usize>() as f64 / marched.len() as f64
    };
    let (short, long) = (in_cycle(2), in_cycle(400));
    assert!(
        long < short,
        "mean in-cycle evaluations: worker budget 400 {long}, worker budget 2 {short}"
    );
}

fn summary(reports: &[StepReport]) -> Vec<String> {
    reports
        .iter()
        .map(|r| {
            let branches: Vec<String> = r
                .branches
                .iter()
                .map(|b| format!("{}:{}:{:016x}", b.id, b.main, b.j.to_bits()))
                .collect();
            format!("{:?} {:?} {}", r.main, r.event_tags(), branches.join(","))
        })
        .collect()
}

#[test]
fn same_seed_same_branches_with_one_and_two_threads() {
    let params = SceneParams {
        size: Vec3::new(40.0, 20.0, 10.0),
        r_safe: 0.3,
        ..SceneParams::default()
    };
    for seed in [3u64, 11] {
        let scene_rng = &mut Rng::seed_from_u64(seed);
        let sc = random_dynamic_scene(8, &params, scene_rng).unwrap();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut m = planner(ManagerParams {
                    seed,
                    ..ManagerParams::trust()
                });
                let reports = fly(&mut m, &sc.map, sc.query.goal, sc.query.start, 8, |_| {
                    sc.forecasts.clone()
                });
                (summary(&reports), m.plan().unwrap().clone())
            })
        };
        let (one, plan_one) = run(1);
        let (two, plan_two) = run(2);
        assert_eq!(one, two, "seed {seed}");
        assert_eq!(plan_one, plan_two, "seed {seed}");
    }
}

#[test]
fn never_more_than_n_branches() {
    // Two classes (the two gaps) but room for one branch: the other is popped every time it is
    // found, and the main branch is never the one popped.
    let map = two_gap_corridor();
    let mut m = planner(ManagerParams {
        max_branches: 1,
        ..ManagerParams::trust()
    });
    let reports = fly(&mut m, &map, GOAL, State::at_rest(0.0, START), 6, |_| {
        Vec::new()
    });
    assert!(reports.iter().all(|r| r.branches.len() <= 1));
    assert!(reports.iter().all(|r| r.main.is_some()));
    assert!(
        reports
            .iter()
            .flat_map(|r| &r.events)
            .any(|e| matches!(e, Event::DroppedPopBack { .. })),
        "the second class must have been found and popped"
    );
    let mut m = planner(ManagerParams {
        max_branches: 2,
        ..ManagerParams::trust()
    });
    let reports = fly(&mut m, &map, GOAL, State::at_rest(0.0, START), 6, |_| {
        Vec::new()
    });
    assert!(reports.iter().all(|r| r.branches.len() <= 2));
    assert_eq!(reports.last().unwrap().branches.len(), 2);
}

/// The axis-aligned box from `min` to `max`.
fn block(min: [f64; 3], max: [f64; 3]) -> Shape {
    Shape::AaBox(AaBox::new(Vec3::from(min), Vec3::from(max)).unwrap())
}

/// A safety check for contact only: no clearance, no braking tail.
fn contact_only() -> trust_manager::SafetyParams {
    trust_manager::SafetyParams {
        static_clearance_m: 0.0,
        braking_tail: false,
        ..Default::default()
    }
}

#[test]
fn flies_out_of_a_dead_end_around_it_to_the_goal() {
    // A cul-de-sac straight ahead: a 4 m wide, 14 m long corridor closed at its far end, with the
    // goal behind the closed end. The straight line to the goal leads into it; the vehicle must
    // go around its walls (they span the full height), and it must not touch them.
    let map = StaticMap::from_shapes(
        Aabb::new(Vec3::new(0.0, -10.0, 0.0), Vec3::new(40.0, 10.0, 6.0)).unwrap(),
        vec![
            block([6.0, 2.0, 0.0], [20.0, 2.5, 6.0]),
            block([6.0, -2.5, 0.0], [20.0, -2.0, 6.0]),
            block([20.0, -2.5, 0.0], [20.5, 2.5, 6.0]),
        ],
    )
    .unwrap();
    let goal = Vec3::new(36.0, 0.0, 3.0);
    let mut m = planner(ManagerParams::trust());
    let mut state = State::at_rest(0.0, START);
    let mut went_around = false;
    for k in 0..150 {
        let t = 0.1 * k as f64;
        let scene = Scene::new(&map, &[], t).unwrap();
        let report = m.step(t, &state, &goal, &scene).expect("valid input");
        assert!(report.fallback.is_none(), "cycle {k}: braking fallback");
        let plan = m.plan().expect("a plan");
        let verdict = check_trajectory(
            plan,
            &scene,
            t,
            t + 0.1,
            &Limits::default(),
            &contact_only(),
        );
        assert!(
            verdict.safe,
            "cycle {k}: the flown part collides: {verdict:?}"
        );
        state = plan.state(t + 0.1);
        went_around |= state.p.x > 21.0 && state.p.y.abs() > 2.5;
        if (state.p - goal).norm() < 0.5 {
            break;
        }
    }
    assert!(went_around, "never passed beside the dead end");
    assert!(
        (state.p - goal).norm() < 0.5,
        "did not reach the goal in 15 s: {:?}",
        state.p
    );
}

#[test]
fn an_enclosed_goal_is_approached_without_collision_and_never_reached() {
    // The goal lies in a closed room (walls over the full height): no trajectory reaches it.
    // The manager must keep the vehicle safe — stop short of the walls — not crash or loop.
    let map = StaticMap::from_shapes(
        Aabb::new(Vec3::new(0.0, -10.0, 0.0), Vec3::new(40.0, 10.0, 6.0)).unwrap(),
        vec![
            block([25.0, -5.0, 0.0], [25.5, 5.0, 6.0]),
            block([34.5, -5.0, 0.0], [35.0, 5.0, 6.0]),
            block([25.0, 4.5, 0.0], [35.0, 5.0, 6.0]),
            block([25.0, -5.0, 0.0], [35.0, -4.5, 6.0]),
        ],
    )
    .unwrap();
    let goal = Vec3::new(30.0, 0.0, 3.0);
    let mut m = planner(ManagerParams::trust());
    let mut state = State::at_rest(0.0, START);
    for k in 0..100 {
        let t = 0.1 * k as f64;
        let scene = Scene::new(&map, &[], t).unwrap();
        m.step(t, &state, &goal, &scene).expect("valid input");
        let plan = m.plan().expect("a plan");
        let verdict = check_trajectory(
            plan,
            &scene,
            t,
            t + 0.1,
            &Limits::default(),
            &contact_only(),
        );
        assert!(
            verdict.safe,
            "cycle {k}: the flown part collides: {verdict:?}"
        );
        state = plan.state(t + 0.1);
        assert!(state.p.iter().all(|c| c.is_finite()));
        let inside = (25.0..35.0).contains(&state.p.x) && (-5.0..5.0).contains(&state.p.y);
        assert!(
            !inside,
            "cycle {k}: inside the closed room at {:?}",
            state.p
        );
    }
}

/// A converged one-evaluation solution for `traj`: `H_t` its duration, `H_s` its end's distance
/// to `goal`.
fn converged(traj: PolyTraj, goal: &Vec3) -> Solution {
    Solution {
        costs: CostBreakdown {
            ht: traj.duration(),
            hs: (traj.position(traj.t_end()) - goal).norm(),
            ..CostBreakdown::default()
        },
        traj,
        stats: SolveStats {
            iteration_count: 0,
            evaluation_count: 1,
            elapsed: std::time::Duration::ZERO,
            status: SolveStatus::Converged,
        },
        violations: Vec::new(),
    }
}

/// A backend that ignores obstacles: it continues the start state for 4 s (constant
/// acceleration), so every trajectory drives into whatever is ahead.
struct Blind;

impl TrajectoryBackend for Blind {
    fn name(&self) -> &str {
        "blind"
    }

    fn optimize(&self, req: &TrajRequest<'_>, _scene: &Scene<'_>) -> Result<Solution, PlanError> {
        let s = req.start;
        let piece = [
            s.p,
            s.v,
            s.a * 0.5,
            Vec3::zeros(),
            Vec3::zeros(),
            Vec3::zeros(),
        ];
        let traj = PolyTraj::new(s.t, vec![4.0], vec![piece])?;
        Ok(converged(traj, &req.goal))
    }
}

/// A 100 × 20 × 10 m box without obstacles.
fn open_air() -> StaticMap {
    StaticMap::empty(Aabb::new(Vec3::new(0.0, -10.0, 0.0), Vec3::new(100.0, 10.0, 10.0)).unwrap())
        .unwrap()
}

/// One branch from the straight line, optimized by [`Blind`].
fn blind_single_branch() -> Manager<StraightLine, Blind, Tvd> {
    Manager::new(
        StraightLine,
        Blind,
        Tvd::default(),
        Limits::default(),
        reproducible(ManagerParams::single_branch()),
    )
    .unwrap()
}

/// At (5, 0, 5) at time 0, flying along x at `speed` m/s.
fn cruising(speed: f64) -> State {
    State {
        t: 0.0,
        p: Vec3::new(5.0, 0.0, 5.0),
        v: Vec3::new(speed, 0.0, 0.0),
        a: Vec3::zeros(),
    }
}

#[test]
fn a_trajectory_beyond_the_limits_is_dropped_with_the_values_reached() {
    // The blind backend keeps the measured 13 m/s, 30 % above `v_max`: its plan is clear of
    // everything but infeasible, and the drop says by how much.
    let map = open_air();
    let mut m = blind_single_branch();
    let start = cruising(13.0);
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let r = m
        .step(0.0, &start, &Vec3::new(95.0, 0.0, 5.0), &scene)
        .unwrap();
    let excess = r
        .events
        .iter()
        .find_map(|e| match e {
            Event::DroppedCollision {
                violation: None,
                over_limits,
                ..
            } => *over_limits,
            _ => None,
        })
        .expect("a drop on the limits alone");
    assert!((excess.max_speed_mps - 13.0).abs() < 1e-6, "{excess:?}");
    assert_eq!(excess.v_max, Limits::default().v_max);
    assert_eq!(excess.a_max, Limits::default().a_max);
    assert!(r.main.is_none() && r.fallback.is_some());
}

#[test]
fn braking_fallback_when_every_branch_collides() {
    let map = open_air();
    let mut m = blind_single_branch();
    // Flying at 8 m/s along x with a clear scene: the blind plan is fine.
    let start = cruising(8.0);
    let goal = Vec3::new(95.0, 0.0, 5.0);
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let r = m.step(0.0, &start, &goal, &scene).unwrap();
    assert!(r.main.is_some() && r.fallback.is_none());

    // A wall of obstacles appears 12 m ahead across the whole corridor.
    let t = 0.1;
    let wall: Vec<Forecast> = (-5..=5)
        .flat_map(|y| (0..=5).map(move |z| (y, z)))
        .map(|(y, z)| {
            Forecast::new(
                ObstacleShape::Sphere,
                Vec3::new(18.0, 2.0 * y as f64, 2.0 * z as f64),
                Vec3::zeros(),
                t,
                1.5,
                0.3,
                0.0,
            )
            .unwrap()
        })
        .collect();
    let scene = Scene::new(&map, &wall, t).unwrap();
    let state = m.plan().unwrap().state(t);
    let r = m.step(t, &state, &goal, &scene).unwrap();
    assert!(r.main.is_none());
    let fallback = r.fallback.as_ref().expect("fallback");
    assert!(fallback.collision_free, "{fallback:?}");
    assert_eq!(fallback.along, trust_manager::FallbackKind::Committed);
    assert!(r.events.iter().any(|e| matches!(e, Event::Fallback { .. })));
    let plan = m.plan().unwrap();
    let end = plan.state(plan.t_end());
    assert!(end.v.norm() < 1e-9 && end.p.x < 16.0, "{end:?}");
    // It keeps braking (and stays clear) in the next cycles.
    let state = plan.state(t + 0.1);
    let scene = Scene::new(&map, &wall, t + 0.1).unwrap();
    let r = m.step(t + 0.1, &state, &goal, &scene).unwrap();
    assert!(r.fallback.as_ref().is_some_and(|f| f.collision_free));
}

/// An obstacle walking toward the map's wall y = 10 (it turns there, at y = 9, at t = 0.5 s)
/// crosses the blind plan's line at x = 29 just when the vehicle gets there (t = 3 s), on its way
/// back; its constant-velocity forecast is at y = 19 by then. With the wall images
/// (`ManagerParams::wall_images`, the default) the plan is dropped; without, it is kept.
#[test]
fn an_obstacle_turning_at_a_wall_is_expected_back() {
    let walker = Forecast::new(
        ObstacleShape::Sphere,
        Vec3::new(29.0, 7.0, 5.0),
        Vec3::new(0.0, 4.0, 0.0),
        0.0,
        1.0,
        0.3,
        0.0,
    )
    .unwrap();
    let plan_kept = |wall_images: bool| {
        straight_plan_kept(
            ManagerParams {
                wall_images,
                ..ManagerParams::single_branch()
            },
            walker,
        )
    };
    assert!(ManagerParams::default().wall_images);
    assert!(plan_kept(false));
    assert!(!plan_kept(true));
}

/// An obstacle known to stay inside a region (`Forecast::walls`, a scenario's obstacle
/// region) turns at the region's wall y = 5 in open air, 5 m inside the map's wall: walking at
/// 5/3 m/s from y = 3 it turns at y = 4 (t = 0.6 s) and is back on the blind plan's line at
/// x = 29 when the vehicle gets there (t = 3 s); its constant-velocity forecast is at y = 8. The
/// manager mirrors it at its region's walls, not only at the map's.
#[test]
fn an_obstacle_turning_at_its_region_wall_is_expected_back() {
    let walker = Forecast::new(
        ObstacleShape::Sphere,
        Vec3::new(29.0, 3.0, 5.0),
        Vec3::new(0.0, 5.0 / 3.0, 0.0),
        0.0,
        1.0,
        0.3,
        0.0,
    )
    .unwrap();
    let region = Aabb::new(Vec3::new(20.0, -10.0, 0.0), Vec3::new(40.0, 5.0, 10.0)).unwrap();
    let params = ManagerParams::single_branch;
    assert!(straight_plan_kept(params(), walker));
    assert!(!straight_plan_kept(params(), walker.with_walls(region)));
    // Without wall images the region is not used either.
    let no_images = ManagerParams {
        wall_images: false,
        ..params()
    };
    assert!(straight_plan_kept(no_images, walker.with_walls(region)));
}

/// Whether a single-branch manager cruising at 8 m/s along y = 0 toward x = 95 past `obstacle`
/// (open air) keeps the straight branch in its first cycle.
fn straight_plan_kept(params: ManagerParams, obstacle: Forecast) -> bool {
    let map = open_air();
    let forecasts = [obstacle];
    let scene = Scene::new(&map, &forecasts, 0.0).unwrap();
    let mut m = Manager::new(
        StraightLine,
        Blind,
        Tvd::default(),
        Limits::default(),
        reproducible(params),
    )
    .unwrap();
    let r = m
        .step(0.0, &cruising(8.0), &Vec3::new(95.0, 0.0, 5.0), &scene)
        .unwrap();
    r.main.is_some()
}

/// A slow walker beside the line whose forecast grows fast: grown for the whole horizon it
/// reaches the line by the time the vehicle passes and the plan is dropped; with the growth
/// stopped after a sixteenth of the horizon (the default) the plan passes. The paper's model is
/// `forecast_growth_s = ∞`.
#[test]
fn forecast_growth_stops_after_a_sixteenth_of_the_horizon() {
    let walker = Forecast::new(
        ObstacleShape::Sphere,
        Vec3::new(30.0, 6.0, 5.0),
        Vec3::zeros(),
        0.0,
        1.0,
        0.3,
        2.0,
    )
    .unwrap();
    let plan_kept = |forecast_growth_s: Option<f64>| {
        straight_plan_kept(
            ManagerParams {
                forecast_growth_s,
                ..ManagerParams::single_branch()
            },
            walker,
        )
    };
    assert_eq!(ManagerParams::default().forecast_growth(), 0.25);
    assert!(plan_kept(None));
    assert!(!plan_kept(Some(f64::INFINITY)));
    let bad = ManagerParams {
        forecast_growth_s: Some(0.0),
        ..ManagerParams::default()
    };
    let Err(e) = Manager::new(StraightLine, Blind, Tvd::default(), Limits::default(), bad) else {
        panic!("forecast_growth_s = 0 accepted");
    };
    let e = e.to_string();
    assert!(e.contains("manager.forecast_growth_s"), "{e}");
}

/// A single-branch manager at a room's limits (1 m/s, 3 m/s²) with the [`Blind`] backend.
fn blind_single_branch_at_room_limits() -> Manager<StraightLine, Blind, Tvd> {
    let limits = Limits {
        v_max: 1.0,
        a_max: 3.0,
    };
    Manager::new(
        StraightLine,
        Blind,
        Tvd::default(),
        limits,
        reproducible(ManagerParams::single_branch()),
    )
    .unwrap()
}

/// The forecast of a ball 4 m before a vehicle at rest at (50, 0, 5), rolling at it at 2 m/s.
fn rolling_ball() -> Forecast {
    Forecast::new(
        ObstacleShape::Sphere,
        Vec3::new(46.0, 0.0, 5.0),
        Vec3::new(2.0, 0.0, 0.0),
        0.0,
        0.5,
        0.2,
        0.6,
    )
    .unwrap()
}

/// A ball rolling at a vehicle at rest, twice as fast as the vehicle can fly, its forecast growing
/// fast: the fallback steps out of its path rather than fleeing along it (judged against
/// forecasts that grow for ever, every option collided and fleeing, colliding latest, won).
#[test]
fn the_fallback_steps_out_of_a_faster_obstacles_path() {
    let map = open_air();
    let mut m = blind_single_branch_at_room_limits();
    let ball = [rolling_ball()];
    let scene = Scene::new(&map, &ball, 0.0).unwrap();
    let start = State::at_rest(0.0, Vec3::new(50.0, 0.0, 5.0));
    let r = m
        .step(0.0, &start, &Vec3::new(95.0, 0.0, 5.0), &scene)
        .unwrap();
    let fallback = r.fallback.expect("every branch collides");
    let plan = m.plan().unwrap();
    let moved = plan.position(plan.t_end()) - start.p;
    // Out of the ball's path: farther aside than its radius plus margin (0.7 m).
    assert!(
        moved.y.hypot(moved.z) > 0.7,
        "{} moved {moved:?}",
        fallback.along
    );
}

/// A person coming at 1.5 m/s from 3 m behind a vehicle at rest at (50, 0, 5), with 0.3 m of
/// body and 1.5 m of margin: every way out touches the forecast, and fleeing straight ahead of it
/// does so last.
fn person_with_no_way_round() -> Forecast {
    Forecast::new(
        ObstacleShape::Sphere,
        Vec3::new(47.0, 0.0, 5.0),
        Vec3::new(1.5, 0.0, 0.0),
        0.0,
        0.3,
        1.5,
        0.6,
    )
    .unwrap()
}

/// Issue 19 (a holdout room: a person pacing across it faster than the vehicle; 6 of 60
/// flights collided): a vehicle in a faster obstacle's lane whose forecast's margins leave no
/// way out of it in time. Every option touches the forecast, and "collides latest" fled along
/// the lane, where the obstacle catches up; the fallback now steps out of the obstacle's likely
/// path (its forecast without growth or margins), and says that it is not clear of the forecast.
#[test]
fn with_no_way_clear_of_the_forecasts_the_fallback_steps_out_of_the_likely_path() {
    let map = open_air();
    let mut m = blind_single_branch_at_room_limits();
    let person = [person_with_no_way_round()];
    let scene = Scene::new(&map, &person, 0.0).unwrap();
    let start = State::at_rest(0.0, Vec3::new(50.0, 0.0, 5.0));
    let r = m
        .step(0.0, &start, &Vec3::new(95.0, 0.0, 5.0), &scene)
        .unwrap();
    let fallback = r.fallback.expect("every branch collides");
    assert!(!fallback.collision_free, "{fallback:?}");
    let plan = m.plan().unwrap();
    // Out of the person's likely path (0.3 m of body) for as long as the plan lasts.
    let aside = (0..=100)
        .map(|k| {
            let t = plan.t_start() + (plan.t_end() - plan.t_start()) * f64::from(k) / 100.0;
            let p = plan.position(t);
            let centre = person[0].center(t);
            (p - centre).norm() - 0.3
        })
        .fold(f64::INFINITY, f64::min);
    assert!(aside > 0.0, "{} came within {aside:.3} m", fallback.along);
}

/// The fallback's hysteresis: with no way clear of the forecasts, the next cycle flies on the
/// manoeuvre the last one chose (from the state that manoeuvre predicted) while it stays clear
/// of the likely path and nearly as wide as the best new one, instead of choosing afresh (a room
/// with a pacing person: dash, evade and escape in turn, and the vehicle went nowhere).
#[test]
fn the_fallback_flies_on_the_manoeuvre_under_way() {
    let map = open_air();
    let mut m = blind_single_branch_at_room_limits();
    let person = [person_with_no_way_round()];
    let goal = Vec3::new(95.0, 0.0, 5.0);
    let scene = Scene::new(&map, &person, 0.0).unwrap();
    let start = State::at_rest(0.0, Vec3::new(50.0, 0.0, 5.0));
    let first = m.step(0.0, &start, &goal, &scene).unwrap();
    let first = first.fallback.expect("every branch collides");
    assert!(!first.collision_free, "{first:?}");
    let plan = m.plan().unwrap().clone();
    let t = 0.1;
    let on_plan = State { t, ..plan.state(t) };
    let scene = Scene::new(&map, &person, t).unwrap();
    let second = m.step(t, &on_plan, &goal, &scene).unwrap();
    let second = second.fallback.expect("still no branch");
    assert_eq!(second.along, first.along);
    let flown_on = m.plan().unwrap();
    for k in 0..=20 {
        let s = t + (plan.t_end() - t) * f64::from(k) / 20.0;
        let gap = (flown_on.position(s) - plan.position(s)).norm();
        assert!(gap < 1e-9, "{gap} m off the manoeuvre at t = {s}");
    }
}

/// A frontend that never finds a path.
struct Nothing;

impl PathFrontend for Nothing {
    fn name(&self) -> &str {
        "nothing"
    }

    fn search(
        &self,
        _q: &PathQuery,
        _scene: &Scene<'_>,
        _rng: &mut Rng,
    ) -> Result<SearchResult, PlanError> {
        Ok(SearchResult::default())
    }
}

#[test]
fn an_empty_frontend_result_holds_still_safely() {
    let map = two_gap_corridor();
    let mut m = Manager::new(
        Nothing,
        utf_minco(),
        Tvd::default(),
        Limits::default(),
        reproducible(ManagerParams {
            straight_guide_when_empty: false,
            ..ManagerParams::trust()
        }),
    )
    .unwrap();
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let r = m
        .step(0.0, &State::at_rest(0.0, START), &GOAL, &scene)
        .unwrap();
    assert!(r.main.is_none() && r.branches.is_empty());
    let f = r.fallback.expect("fallback");
    assert!(f.collision_free);
    assert_eq!(f.along, trust_manager::FallbackKind::Straight);
    let plan = m.plan().unwrap();
    assert!((plan.position(plan.t_end()) - START).norm() < 1e-9);
}

#[test]
fn an_empty_frontend_result_falls_back_on_the_straight_guide() {
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(40.0, 20.0, 10.0)).unwrap();
    let map = StaticMap::empty(bounds).unwrap();
    let mut m = Manager::new(
        Nothing,
        utf_minco(),
        Tvd::default(),
        Limits::default(),
        reproducible(ManagerParams::trust()),
    )
    .unwrap();
    let goal = Vec3::new(38.0, 10.0, 5.0);
    let reports = fly(
        &mut m,
        &map,
        goal,
        State::at_rest(0.0, Vec3::new(2.0, 10.0, 5.0)),
        5,
        |_| Vec::new(),
    );
    assert!(reports.iter().all(|r| r.straight_guide && r.main.is_some()));
    assert!(m.plan().unwrap().position(2.0).x > 2.5);
}

#[test]
fn start_on_the_goal_hovers() {
    let map = two_gap_corridor();
    let mut m = planner(ManagerParams::trust());
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let r = m
        .step(0.0, &State::at_rest(0.0, GOAL), &GOAL, &scene)
        .unwrap();
    let plan = m.plan().expect("a plan");
    for k in 0..=20 {
        let t = plan.t_start() + plan.duration() * k as f64 / 20.0;
        assert!((plan.position(t) - GOAL).norm() < 0.05, "drifts at {t}");
    }
    assert!(r.fallback.is_none() || r.fallback.unwrap().collision_free);
}

#[test]
fn without_obstacles_the_plan_heads_straight_for_the_goal() {
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(40.0, 20.0, 10.0)).unwrap();
    let map = StaticMap::empty(bounds).unwrap();
    let mut m = planner(ManagerParams::trust());
    let start = State::at_rest(0.0, Vec3::new(2.0, 10.0, 5.0));
    let goal = Vec3::new(38.0, 10.0, 5.0);
    let reports = fly(&mut m, &map, goal, start, 30, |_| Vec::new());
    assert!(reports.iter().all(|r| r.fallback.is_none()));
    let plan = m.plan().unwrap();
    for k in 0..=20 {
        let t = plan.t_start() + plan.duration() * k as f64 / 20.0;
        let p = plan.position(t);
        assert!((p.y - 10.0).abs() < 0.1 && (p.z - 5.0).abs() < 0.1, "{p:?}");
    }
    // It is on its way.
    assert!(plan.position(3.0).x > 8.0);
}

#[test]
fn a_goal_inside_a_wall_or_outside_the_bounds_is_unreachable_and_a_stop_is_held_short_of_it() {
    let map = two_gap_corridor();
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let start = State::at_rest(0.0, START);
    for (goal, cause) in [
        (Vec3::new(14.5, 0.0, 3.0), "inside"),
        (Vec3::new(50.0, 0.0, 3.0), "outside the map bounds"),
    ] {
        let mut m = planner(ManagerParams::trust());
        let mut state = start;
        let mut first_since = None;
        let mut held = state.p;
        for k in 0..60 {
            let t = 0.1 * f64::from(k);
            state.t = t;
            let r = m.step(t, &state, &goal, &scene).unwrap();
            let u = r.goal_unreachable.clone().expect("a verdict every cycle");
            assert!(u.cause.to_string().contains(cause), "{}", u.cause);
            let since = *first_since.get_or_insert(u.since_t);
            assert_eq!(u.since_t, since, "the verdict keeps its first time");
            let verdicts = r
                .events
                .iter()
                .filter(|e| matches!(e, Event::GoalUnreachable { .. }))
                .count();
            assert_eq!(
                verdicts,
                usize::from(k == 0),
                "the event once, at the verdict"
            );
            held = u.held_at.map(|p| Vec3::new(p[0], p[1], p[2])).unwrap();
            assert!(map.bounds().contains(&held));
            assert!(scene.static_clearance(&held) >= trust_manager::HOLD_CLEARANCE_M);
            if let Some(plan) = m.plan() {
                state = plan.state(t + 0.1);
            }
        }
        // The plan ends at rest at the held stop, short of the goal, clear of the walls.
        let plan = m.plan().expect("a plan");
        let end = plan.position(plan.t_start() + plan.duration());
        assert!((end - held).norm() < 1.0, "{end:?} vs {held:?}");
        assert!(held.x < 14.0 && (held - START).norm() > 5.0, "{held:?}");
        assert!(scene.static_clearance(&end) > 0.0);
    }
}

#[test]
fn bad_input_is_an_error_naming_the_field() {
    let map = two_gap_corridor();
    let mut m = planner(ManagerParams::trust());
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let mut nan = State::at_rest(0.0, START);
    nan.v.y = f64::NAN;
    let e = m.step(0.0, &nan, &GOAL, &scene).unwrap_err().to_string();
    assert!(e.contains("state.v"), "{e}");
    let e = m
        .step(f64::INFINITY, &State::at_rest(0.0, START), &GOAL, &scene)
        .unwrap_err()
        .to_string();
    assert!(e.contains("now"), "{e}");
    // Nothing was committed by the failed calls.
    assert!(m.plan().is_none());
    let e = Manager::new(
        dev_prm(),
        UtfMinco::default(),
        Tvd::default(),
        Limits::default(),
        ManagerParams {
            max_branches: 0,
            ..ManagerParams::trust()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("manager.max_branches"), "{e}");
}

#[test]
fn a_start_inside_a_static_obstacle_is_survived_not_fatal() {
    // The vehicle was pushed into a wall (a disturbance): the frontend refuses the start, the
    // cycle goes on and reports it instead of failing.
    let map = two_gap_corridor();
    let mut m = planner(ManagerParams::trust());
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let r = m
        .step(
            0.0,
            &State::at_rest(0.0, Vec3::new(14.5, 0.0, 3.0)),
            &GOAL,
            &scene,
        )
        .expect("not an input error");
    assert!(
        r.events
            .iter()
            .any(|e| matches!(e, Event::FrontendFailed { .. }))
    );
    assert!(m.plan().is_some());
    let _ = GuidePath::new(vec![START]).unwrap();
}

/// A frontend with one guide path: the straight line from the start to the goal.
struct Toward;

impl PathFrontend for Toward {
    fn name(&self) -> &str {
        "toward"
    }

    fn search(
        &self,
        q: &PathQuery,
        _scene: &Scene<'_>,
        _rng: &mut Rng,
    ) -> Result<SearchResult, PlanError> {
        Ok(SearchResult {
            paths: vec![GuidePath::new(vec![q.start.p, q.goal])?],
            ..SearchResult::default()
        })
    }
}

/// A checker for which every two curves are equivalent (one homotopy class, as in open air).
struct OneClass;

impl trust_core::HomotopyChecker for OneClass {
    fn name(&self) -> &str {
        "one-class"
    }

    fn equivalent(
        &self,
        _a: &dyn trust_core::Curve,
        _b: &dyn trust_core::Curve,
        _scene: &Scene<'_>,
    ) -> Result<bool, PlanError> {
        Ok(true)
    }
}

/// A backend reproducing E4 seed 7301's stall: its first cold solve (the cycle at `t = 0`, replanning from `t = 0.05`) stands still
/// (the branch stopped short), every later cold solve flies rest-to-rest to the goal within the
/// limits, and a warm re-solve keeps the branch's end (a stopped branch stays stopped). Every
/// trajectory is the quintic from the start state to rest at its end, so a re-solve of a flying
/// branch is the same curve.
struct StopsFirst;

impl StopsFirst {
    /// The quintic from `start` to rest at `end` over `duration`, with its `H_t` and `H_s`.
    fn to_rest(start: &State, end: Vec3, duration: f64, goal: &Vec3) -> Solution {
        let piece = trust_manager::hermite_quintic(
            [start.p, start.v, start.a],
            [end, Vec3::zeros(), Vec3::zeros()],
            duration,
        );
        Solution {
            traj: PolyTraj::new(start.t, vec![duration], vec![piece]).expect("valid"),
            costs: CostBreakdown {
                ht: duration,
                hs: (end - goal).norm(),
                ..CostBreakdown::default()
            },
            stats: SolveStats {
                iteration_count: 0,
                evaluation_count: 1,
                elapsed: std::time::Duration::ZERO,
                status: SolveStatus::Converged,
            },
            violations: Vec::new(),
        }
    }
}

impl TrajectoryBackend for StopsFirst {
    fn name(&self) -> &str {
        "stops-first"
    }

    fn optimize(&self, req: &TrajRequest<'_>, _scene: &Scene<'_>) -> Result<Solution, PlanError> {
        let s = &req.start;
        // The standing branch's duration: J = 0.3 s + d/v_max, as the kept branch's in the stall
        // (0.3 s: longer than a stub, `trust_manager::STUB_FRACTION` of the horizon, which is
        // dropped before it is ranked).
        const HOLD_S: f64 = 0.3;
        Ok(match req.initial {
            trust_core::InitialGuess::WarmStart(traj) => {
                let end = traj.position(traj.t_end());
                let duration = (traj.t_end() - s.t).max(HOLD_S);
                Self::to_rest(s, end, duration, &req.goal)
            }
            trust_core::InitialGuess::Guide(_) if s.t < 0.1 => {
                Self::to_rest(s, s.p, HOLD_S, &req.goal)
            }
            trust_core::InitialGuess::Guide(_) => {
                // Rest to rest over d: peak speed 1.875·d/T, peak acceleration 5.774·d/T².
                let d = (req.goal - s.p).norm();
                let (v, a) = (req.limits.v_max, req.limits.a_max);
                let duration = (1.1 * (1.875 * d / v).max((5.774 * d / a).sqrt())).max(HOLD_S);
                Self::to_rest(s, req.goal, duration, &req.goal)
            }
        })
    }
}

/// Regression (E4 seed 7301, issue 19): a branch standing still 10 m short of the goal has
/// `J ≈ d/v_max`, less than any branch that flies there (`H_t ≥ d/v_max` plus speeding up and
/// braking); ranked by `J` alone it kept the main branch and every explored branch reaching the
/// goal was `discarded_equivalent`, for ever. A branch that reaches the goal must win.
#[test]
fn a_branch_that_reaches_the_goal_outranks_one_that_stops_short() {
    let map = open_air();
    let mut m = Manager::new(
        Toward,
        StopsFirst,
        OneClass,
        Limits::default(),
        reproducible(ManagerParams::trust()),
    )
    .unwrap();
    let start = State::at_rest(0.0, Vec3::new(80.0, 0.0, 5.0));
    let goal = Vec3::new(90.0, 0.0, 5.0);
    let reports = fly(&mut m, &map, goal, start, 40, |_| Vec::new());
    // The first cycle has only the standing branch.
    assert_eq!(reports[0].branches.len(), 1);
    assert!(reports[0].branches[0].j < 1.4, "{:?}", reports[0].branches);
    // The reaching branch replaces it in its class although its J is larger, and leads.
    let r = &reports[1];
    let replaced = r.events.iter().find_map(|e| match e {
        Event::Replaced { j_old, j_new, .. } => Some((*j_old, *j_new)),
        _ => None,
    });
    let (j_old, j_new) = replaced.expect("the stopped branch is replaced");
    assert!(j_new > j_old, "J {j_old} → {j_new}");
    let plan = m.plan().unwrap();
    assert!((plan.position(plan.t_end()) - goal).norm() < 1e-9);
    // Flown perfectly, the vehicle arrives and stays.
    let last = reports.last().unwrap();
    let end = m.plan().unwrap().state(last.t + 0.1);
    assert!((end.p - goal).norm() < 0.05, "ends at {:?}", end.p);
    assert!(reports.iter().all(|r| r.fallback.is_none()));
}

/// A frontend with two guide paths to the goal: straight, and through a point beside the line.
struct TwoWays;

impl PathFrontend for TwoWays {
    fn name(&self) -> &str {
        "two-ways"
    }

    fn search(
        &self,
        q: &PathQuery,
        _scene: &Scene<'_>,
        _rng: &mut Rng,
    ) -> Result<SearchResult, PlanError> {
        let beside = (q.start.p + q.goal) * 0.5 + Vec3::new(0.0, 1.0, 0.0);
        Ok(SearchResult {
            paths: vec![
                GuidePath::new(vec![q.start.p, q.goal])?,
                GuidePath::new(vec![q.start.p, beside, q.goal])?,
            ],
            ..SearchResult::default()
        })
    }
}

/// A backend for which standing still is cheapest: the straight guide gives a branch standing
/// still (`J = 0.1 s + d/v_max`), the other guide a branch that flies 8 m toward the goal and
/// stops (`J` about 1 s more); a warm re-solve keeps the branch's end.
struct Hesitant;

impl TrajectoryBackend for Hesitant {
    fn name(&self) -> &str {
        "hesitant"
    }

    fn optimize(&self, req: &TrajRequest<'_>, _scene: &Scene<'_>) -> Result<Solution, PlanError> {
        let s = &req.start;
        Ok(match req.initial {
            trust_core::InitialGuess::WarmStart(traj) => {
                let duration = (traj.t_end() - s.t).max(0.3);
                StopsFirst::to_rest(s, traj.position(traj.t_end()), duration, &req.goal)
            }
            trust_core::InitialGuess::Guide(path) if path.points.len() == 2 => {
                StopsFirst::to_rest(s, s.p, 0.3, &req.goal)
            }
            trust_core::InitialGuess::Guide(_) => {
                let d = 8.0;
                let end = s.p + (req.goal - s.p).normalize() * d;
                let (v, a) = (req.limits.v_max, req.limits.a_max);
                let duration = 1.1 * (1.875 * d / v).max((5.774 * d / a).sqrt());
                StopsFirst::to_rest(s, end, duration, &req.goal)
            }
        })
    }
}

/// Issue 19, "progress, not hovering": a branch that stands still is the cheapest by `J`, so the
/// vehicle hovers 30 m from the goal; after one window (`T_h/2 = 2 s`) the monitor reports
/// `stalled`, the ranking by progress takes the branch that flies on, and once the vehicle has
/// progressed `5 % · v_max · 2 s = 1 m` the monitor reports `escaped`.
#[test]
fn a_stalled_flight_says_so_and_progresses_again() {
    let map = open_air();
    let mut m = Manager::new(
        TwoWays,
        Hesitant,
        OneClass,
        Limits::default(),
        reproducible(ManagerParams::trust()),
    )
    .unwrap();
    let start = State::at_rest(0.0, Vec3::new(60.0, 0.0, 5.0));
    let goal = Vec3::new(90.0, 0.0, 5.0);
    let reports = fly(&mut m, &map, goal, start, 50, |_| Vec::new());
    let first = |tag: &str| reports.iter().position(|r| r.event_tags().contains(&tag));
    let stalled = first("stalled").expect("a stall is reported");
    // Standing still until the stall: one window of 2 s (20 cycles).
    assert_eq!(stalled, 20);
    let x_at = |k: usize| reports[k].replan_start.p.x;
    assert!((x_at(stalled) - 60.0).abs() < 1e-6, "{}", x_at(stalled));
    let escaped = first("escaped").expect("the escape is reported");
    assert!(escaped > stalled);
    assert!(x_at(escaped) - 60.0 >= 1.0, "{}", x_at(escaped));
    let Some(Event::Stalled {
        progress_mps,
        distance_to_goal_m,
        ..
    }) = reports[stalled]
        .events
        .iter()
        .find(|e| matches!(e, Event::Stalled { .. }))
    else {
        unreachable!()
    };
    assert!(progress_mps.abs() < 1e-9 && (distance_to_goal_m - 30.0).abs() < 1e-6);
    // The vehicle ends nearer the goal than it stalled.
    let last = reports.last().unwrap();
    assert!(m.plan().unwrap().position(last.t).x > 65.0);
}

/// Issue 19, "a wide wall ahead": a full-height wall 30 m wide, 15 m from the start, across the
/// straight line to the goal. With the global route the branches aim at the route's local goal,
/// around the wall's end, and the vehicle (tracking perfectly) leaves the start and arrives.
#[test]
fn with_a_route_a_wide_wall_ahead_is_flown_around_to_the_goal() {
    let bounds = Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(60.0, 40.0, 10.0)).unwrap();
    let wall =
        Shape::AaBox(AaBox::new(Vec3::new(20.0, 5.0, 0.0), Vec3::new(21.0, 35.0, 10.0)).unwrap());
    let map = StaticMap::from_shapes(bounds, vec![wall]).unwrap();
    let (start, goal) = (Vec3::new(5.0, 20.0, 5.0), Vec3::new(50.0, 20.0, 5.0));
    let route = trust_route::RoutePlanner::new(trust_route::RouteParams::default())
        .unwrap()
        .plan(&map, &start, &goal, 0.3)
        .expect("a route around the wall");
    // Without the route (the paper's setting) it never leaves the start: every branch collides.
    let mut m = planner(ManagerParams::trust());
    let reports = fly(&mut m, &map, goal, State::at_rest(0.0, start), 30, |_| {
        Vec::new()
    });
    assert!(reports.iter().all(|r| r.main.is_none()));
    assert!((reports.last().unwrap().replan_start.p - start).norm() < 1e-6);
    let mut m = planner(ManagerParams::trust());
    m.set_route(Some(route));
    let reports = fly(&mut m, &map, goal, State::at_rest(0.0, start), 150, |_| {
        Vec::new()
    });
    let arrived = reports
        .iter()
        .position(|r| (r.replan_start.p - goal).norm() < 0.5)
        .expect("arrives");
    assert!(arrived < 150, "{arrived}");
    // It never touched the wall (the safety check passed every committed plan).
    assert!(reports.iter().all(|r| r.fallback.is_none()));

    // The same with the manager planning its own route (a router): the search starts on the
    // first cycle and gets a slice of work per cycle; the vehicle holds its place until the
    // route is found (`awaiting_route`), says so, and arrives as well.
    let mut m = planner(ManagerParams::trust());
    m.set_router(Some(
        trust_manager::Router::new(trust_route::RouteParams::default(), 0.3).unwrap(),
    ));
    let reports = fly(&mut m, &map, goal, State::at_rest(0.0, start), 150, |_| {
        Vec::new()
    });
    let routed = reports
        .iter()
        .position(|r| r.events.iter().any(|e| matches!(e, Event::Rerouted { .. })))
        .expect("a route");
    assert!(routed < 10, "the first route took {routed} cycles");
    assert!(
        matches!(
            reports[routed].events.iter().find(|e| matches!(e, Event::Rerouted { .. })),
            Some(Event::Rerouted { reason, vertex_count, .. }) if *reason == trust_manager::RouteReason::First && *vertex_count >= 3
        ),
        "{:?}",
        reports[routed].events
    );
    for r in &reports[..routed] {
        assert!(r.event_tags().contains(&"awaiting_route"), "{:?}", r.events);
        assert!(
            (r.replan_start.p - start).norm() < 1e-3,
            "it held its place"
        );
    }
    assert!(reports[..=routed].iter().all(|r| r.timing.route_ms > 0.0));
    assert!(
        reports[routed + 1..]
            .iter()
            .all(|r| !r.events.iter().any(|e| matches!(e, Event::Rerouted { .. }))),
        "no re-plan without a stall"
    );
    assert!(
        reports
            .iter()
            .any(|r| (r.replan_start.p - goal).norm() < 0.5),
        "arrives with its own route"
    );
    // A bad radius is a typed error naming the field.
    let e = trust_manager::Router::new(trust_route::RouteParams::default(), f64::NAN).unwrap_err();
    assert!(e.to_string().contains("route.radius_m"), "{e}");
}

/// A 40 × 20 × 10 m world with a closed box of 0.4 m walls around (24..28, 8..12, 2..5): a goal
/// at its centre is sealed off.
fn sealed_box_map() -> StaticMap {
    let bounds = Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(40.0, 20.0, 10.0)).unwrap();
    let (lo, hi, t) = (Vec3::new(24.0, 8.0, 2.0), Vec3::new(28.0, 12.0, 5.0), 0.4);
    let slab = |a: Vec3, b: Vec3| Shape::AaBox(AaBox::new(a, b).unwrap());
    let walls = vec![
        slab(
            Vec3::new(lo.x - t, lo.y - t, lo.z - t),
            Vec3::new(hi.x + t, hi.y + t, lo.z),
        ),
        slab(
            Vec3::new(lo.x - t, lo.y - t, hi.z),
            Vec3::new(hi.x + t, hi.y + t, hi.z + t),
        ),
        slab(
            Vec3::new(lo.x - t, lo.y - t, lo.z),
            Vec3::new(lo.x, hi.y + t, hi.z),
        ),
        slab(
            Vec3::new(hi.x, lo.y - t, lo.z),
            Vec3::new(hi.x + t, hi.y + t, hi.z),
        ),
        slab(Vec3::new(lo.x, lo.y - t, lo.z), Vec3::new(hi.x, lo.y, hi.z)),
        slab(Vec3::new(lo.x, hi.y, lo.z), Vec3::new(hi.x, hi.y + t, hi.z)),
    ];
    StaticMap::from_shapes(bounds, walls).unwrap()
}

/// Issue 31: with the map shared with the manager's threads, the route search goes on between
/// cycles on a thread of its own: a vehicle at rest does no slice itself (in flight the cycle
/// that starts a search does its first slice, `mission_classes`), the verdict
/// is the one the in-cycle slices reach (no later: every slice between cycles does more work;
/// one cycle of slack for taking it back), and two flights of
/// the same seed are the same flight (each cycle waits for the slice).
#[test]
fn with_a_shared_map_the_route_search_runs_between_cycles() {
    let map = std::sync::Arc::new(sealed_box_map());
    let (start, goal) = (Vec3::new(3.0, 10.0, 3.5), Vec3::new(26.0, 10.0, 3.5));
    // A first slice too small for the verdict, so that the search goes on between cycles.
    let router = || {
        trust_manager::Router::new(trust_route::RouteParams::default(), 0.3)
            .unwrap()
            .with_work_per_cycle(1000)
    };
    let run = |share: bool| {
        let mut m = planner(ManagerParams::trust());
        m.set_router(Some(router()));
        if share {
            m.share_map(std::sync::Arc::clone(&map));
        }
        fly(&mut m, &map, goal, State::at_rest(0.0, start), 30, |_| {
            Vec::new()
        })
    };
    let verdict = |reports: &[StepReport]| {
        let i = reports
            .iter()
            .position(|r| r.goal_unreachable().is_some())
            .expect("a verdict");
        (i, reports[i].goal_unreachable().unwrap().clone())
    };
    let here = run(false);
    let away = run(true);
    let (i_here, u_here) = verdict(&here);
    let (i_away, u_away) = verdict(&away);
    assert_eq!(u_here.cause, u_away.cause);
    assert_eq!(u_here.held_at, u_away.held_at);
    assert!(i_away <= i_here + 1, "{i_away} cycles away, {i_here} here");
    assert!(
        i_away >= 1,
        "the first slice found the verdict: nothing went away"
    );
    assert!(here[..=i_here].iter().all(|r| r.timing.route_ms > 0.0));
    // A vehicle at rest awaiting its first route does no route work in its cycles at all: even
    // the first slice goes away (the re-checks after the verdict start searches of their own).
    assert!(away[..=i_away].iter().all(|r| r.timing.route_ms == 0.0));
    assert!(
        away[1..=i_away]
            .iter()
            .all(|r| r.timing.route_worker_ms > 0.0)
    );
    assert!(away[..i_away].iter().all(|r| r.worker_started));
    let again = run(true);
    assert_eq!(verdict(&again).0, i_away);
    for (a, b) in away.iter().zip(&again) {
        assert_eq!(a.replan_start.p, b.replan_start.p, "t = {}", a.t);
    }

    // In real time on a computer a million times slower, a slice's answer is not due within
    // the flight: the cycles go on without it (and never wait for another slice).
    let mut m = planner(ManagerParams {
        real_time_scale: Some(1e6),
        ..ManagerParams::trust()
    });
    m.set_router(Some(router()));
    m.share_map(std::sync::Arc::clone(&map));
    let slow = fly(&mut m, &map, goal, State::at_rest(0.0, start), 30, |_| {
        Vec::new()
    });
    assert!(slow.iter().all(|r| r.goal_unreachable().is_none()));
    assert_eq!(
        slow.iter()
            .filter(|r| r.timing.route_worker_ms > 0.0)
            .count(),
        0,
        "no slice taken back"
    );
    let e = ManagerParams {
        real_time_scale: Some(0.0),
        ..ManagerParams::trust()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(e.contains("manager.real_time_scale"), "{e}");
}

/// Issue 31: a goal sealed inside a closed box. The route search proves it in a few cycles, the
/// manager reports the verdict with its cause, plans toward the reachable point nearest the goal
/// (outside the box) and keeps re-checking; the vehicle never enters the box's walls.
#[test]
fn a_sealed_goal_is_reported_unreachable_and_a_stop_is_held_outside() {
    let map = sealed_box_map();
    let (start, goal) = (Vec3::new(3.0, 10.0, 3.5), Vec3::new(26.0, 10.0, 3.5));
    let mut m = planner(ManagerParams::trust());
    m.set_router(Some(
        trust_manager::Router::new(trust_route::RouteParams::default(), 0.3).unwrap(),
    ));
    let reports = fly(&mut m, &map, goal, State::at_rest(0.0, start), 60, |_| {
        Vec::new()
    });
    let verdict = reports
        .iter()
        .position(|r| r.goal_unreachable().is_some())
        .expect("a verdict");
    assert!(verdict < 10, "the verdict took {verdict} cycles");
    let u = reports[verdict].goal_unreachable().unwrap();
    assert!(u.cause.to_string().contains("sealed"), "{}", u.cause);
    let held = u.held_at.expect("a reachable point nearest the goal");
    let held = Vec3::new(held[0], held[1], held[2]);
    assert!(map.signed_distance(&held) >= 0.3, "{held}");
    assert!((held - goal).norm() < 4.0, "held at {held}, goal {goal}");
    // The verdict stands (re-checked every 2 s, `since_t` kept) and the vehicle heads for the
    // held point, never into the walls.
    assert!(
        reports[verdict..]
            .iter()
            .all(|r| r.goal_unreachable().is_some())
    );
    let since = reports.last().unwrap().goal_unreachable().unwrap().since_t;
    assert_eq!(since, u.since_t);
    assert!(since <= reports[verdict].t);
    let end = reports.last().unwrap().replan_start.p;
    assert!((end - held).norm() < (start - held).norm() - 5.0, "{end}");
    let closest = reports
        .iter()
        .map(|r| map.signed_distance(&r.replan_start.p))
        .fold(f64::INFINITY, f64::min);
    // The library's default safety clearance is 0 (a point vehicle): never inside a wall.
    assert!(closest > 0.0, "{closest} m from the walls (held at {held})");
    assert!(
        reports
            .iter()
            .filter(|r| r
                .events
                .iter()
                .any(|e| matches!(e, Event::GoalUnreachable { .. })))
            .count()
            >= 2,
        "re-checked"
    );
}

/// A backend that always answers with a 0.04 s hover at the start: what UTF-MINCO returned when
/// every way toward the aim crossed a growing forecast.
struct Stub;

impl TrajectoryBackend for Stub {
    fn name(&self) -> &str {
        "stub"
    }

    fn optimize(&self, req: &TrajRequest<'_>, _scene: &Scene<'_>) -> Result<Solution, PlanError> {
        let s = req.start;
        Ok(converged(PolyTraj::hold(s.t, s.p, 0.04)?, &req.goal))
    }
}

#[test]
fn a_stub_far_from_the_goal_is_dropped_and_the_fallback_flies() {
    // Ranked by J the stub (0.04 s, terminal cost d / v_max) beat every real branch and the
    // vehicle hovered while a person walked into it: it is dropped as a stub instead.
    let map = open_air();
    let mut m = Manager::new(
        StraightLine,
        Stub,
        Tvd::default(),
        Limits::default(),
        reproducible(ManagerParams::single_branch()),
    )
    .unwrap();
    let start = State {
        t: 0.0,
        p: Vec3::new(5.0, 0.0, 5.0),
        v: Vec3::zeros(),
        a: Vec3::zeros(),
    };
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let r = m
        .step(0.0, &start, &Vec3::new(95.0, 0.0, 5.0), &scene)
        .unwrap();
    assert!(
        r.events.iter().any(|e| matches!(e, Event::DroppedStub { duration_s, .. } if (*duration_s - 0.04).abs() < 1e-9)),
        "{:?}",
        r.events
    );
    assert!(r.main.is_none() && r.fallback.is_some());
    // On the goal a short hover is no stub: it is the plan.
    let mut m = Manager::new(
        StraightLine,
        Stub,
        Tvd::default(),
        Limits::default(),
        reproducible(ManagerParams::single_branch()),
    )
    .unwrap();
    let r = m.step(0.0, &start, &start.p, &scene).unwrap();
    assert!(
        !r.events
            .iter()
            .any(|e| matches!(e, Event::DroppedStub { .. })),
        "{:?}",
        r.events
    );
}

/// A manager flying `sc` with its worker on (the map shared), `cycles` cycles of 0.1 s.
fn fly_with_worker(seed: u64, cycles: usize) -> (Vec<StepReport>, PolyTraj) {
    let params = SceneParams {
        size: Vec3::new(40.0, 20.0, 10.0),
        r_safe: 0.3,
        ..SceneParams::default()
    };
    let sc = random_dynamic_scene(8, &params, &mut Rng::seed_from_u64(seed)).unwrap();
    let map = std::sync::Arc::new(sc.map);
    let mut m = planner(ManagerParams {
        seed,
        ..ManagerParams::trust()
    });
    m.share_map(std::sync::Arc::clone(&map));
    let reports = fly(&mut m, &map, sc.query.goal, sc.query.start, cycles, |_| {
        sc.forecasts.clone()
    });
    (reports, m.plan().unwrap().clone())
}

#[test]
fn the_worker_takes_the_sub_branches_and_exploration_off_the_cycle_and_keeps_a_seed_one_flight() {
    for seed in [3u64, 11] {
        let (reports, plan) = fly_with_worker(seed, 12);
        // Every cycle starts a job (the first guesses the period: twice the cycle budget, 0.1 s),
        // and from the second on each merges one (the period is regular and the plan tracked
        // perfectly, so every job applies).
        assert!(reports.iter().all(|r| r.worker_started), "seed {seed}");
        assert_eq!(reports[0].timing.worker_ms, 0.0);
        for r in &reports[1..] {
            assert!(r.timing.worker_ms > 0.0, "seed {seed}, t {}", r.t);
        }
        // The same seed gives the same flight, whatever the worker's timing.
        let (again, plan_again) = fly_with_worker(seed, 12);
        assert_eq!(summary(&reports), summary(&again), "seed {seed}");
        assert_eq!(plan, plan_again, "seed {seed}");
    }
}

#[test]
fn a_cycle_off_the_predicted_period_solves_everything_itself() {
    let map = std::sync::Arc::new(two_gap_corridor());
    let mut m = planner(ManagerParams::trust());
    m.share_map(std::sync::Arc::clone(&map));
    let mut state = State::at_rest(0.0, START);
    let mut merged = Vec::new();
    // Cycles at 0, 0.1, 0.2, then 0.35 (a late tick: the job predicted 0.3), then 0.45.
    for t in [0.0, 0.1, 0.2, 0.35, 0.45] {
        let scene = Scene::new(&map, &[], t).unwrap();
        let r = m.step(t, &state, &GOAL, &scene).expect("valid input");
        assert!(r.main.is_some(), "t {t}: a plan");
        merged.push(r.timing.worker_ms > 0.0);
        state = m.plan().unwrap().state(t + 0.1);
    }
    // The late cycle dropped the job (its start was not the predicted one); the job that cycle
    // started for 0.5 s does not apply at 0.45 s either.
    assert_eq!(merged, vec![false, true, true, false, false]);
}

#[test]
fn without_a_shared_map_or_history_there_is_no_worker() {
    let map = two_gap_corridor();
    for params in [
        ManagerParams::trust(),
        ManagerParams::multi_branch_without_history(),
    ] {
        let mut m = planner(params);
        let reports = fly(
            &mut m,
            &map,
            GOAL,
            State::at_rest(0.0, START),
            4,
            |_| vec![],
        );
        assert!(reports.iter().all(|r| !r.worker_started));
        assert!(reports.iter().all(|r| r.timing.worker_ms == 0.0));
    }
    // With history and the map shared, but the scenes built on another copy of the map.
    let mut m = planner(ManagerParams::trust());
    m.share_map(std::sync::Arc::new(two_gap_corridor()));
    let reports = fly(
        &mut m,
        &map,
        GOAL,
        State::at_rest(0.0, START),
        4,
        |_| vec![],
    );
    assert!(reports.iter().all(|r| !r.worker_started));
}

/// Known free space for the commit check: the half-space where coordinate `axis` (0 = x,
/// 1 = y, 2 = z) is at most `max` (the rest unobserved).
struct KnownUpTo {
    axis: usize,
    max: f64,
    /// `CommitCheck::retreat_m`.
    retreat_m: Option<f64>,
}

impl KnownUpTo {
    fn x(max: f64) -> Self {
        Self {
            axis: 0,
            max,
            retreat_m: None,
        }
    }

    fn y(max: f64) -> Self {
        Self {
            axis: 1,
            max,
            retreat_m: None,
        }
    }
}

impl trust_manager::CommitCheck for KnownUpTo {
    fn name(&self) -> &str {
        "known up to a plane"
    }

    fn segment_free(&self, a: &Vec3, b: &Vec3) -> bool {
        a[self.axis] <= self.max && b[self.axis] <= self.max
    }

    fn retreat_m(&self) -> Option<f64> {
        self.retreat_m
    }
}

/// A vehicle that stalls before space its check refuses backs off along the way it came (to
/// let its sensor see that space), when the check names a retreat distance; never without.
#[test]
fn a_vehicle_stalled_before_unseen_space_backs_off_to_look() {
    let map = open_air();
    let start = State::at_rest(0.0, Vec3::new(5.0, 0.0, 5.0));
    let goal = Vec3::new(95.0, 0.0, 5.0);
    let flight = |retreat_m: Option<f64>| {
        let mut m = planner(ManagerParams::trust());
        m.set_commit_check(Some(std::sync::Arc::new(KnownUpTo {
            retreat_m,
            ..KnownUpTo::x(8.0)
        })));
        let reports = fly(&mut m, &map, goal, start, 80, |_| vec![]);
        let xs: Vec<f64> = reports.iter().map(|r| r.replan_start.p.x).collect();
        let retreats = reports
            .iter()
            .filter(|r| {
                r.fallback
                    .as_ref()
                    .is_some_and(|f| f.along == FallbackKind::Retreat)
            })
            .count();
        (xs, retreats)
    };
    let (xs, retreats) = flight(Some(2.0));
    let farthest = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    assert!(
        farthest <= 8.0 && farthest > 7.0,
        "stopped before x = 8: {farthest}"
    );
    assert!(retreats > 0);
    let after = xs.iter().position(|&x| x == farthest).unwrap();
    let back = xs[after..].iter().copied().fold(f64::INFINITY, f64::min);
    assert!(farthest - back >= 1.0, "backed off {} m", farthest - back);
    let (_, retreats) = flight(None);
    assert_eq!(retreats, 0);
}

#[test]
fn a_plan_whose_committed_part_enters_unknown_space_is_not_committed() {
    let map = two_gap_corridor();
    let state = State::at_rest(0.0, START);
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    // Everything ahead of the start's plane unobserved: the plan toward the goal (+x) leaves
    // known free space at once (from rest it moves only millimetres in its committed stretch,
    // so a margin ahead of the start would let it pass).
    let mut m = planner(ManagerParams::trust());
    m.set_commit_check(Some(std::sync::Arc::new(KnownUpTo::x(START.x))));
    let report = m.step(0.0, &state, &GOAL, &scene).unwrap();
    assert!(
        report
            .events
            .iter()
            .any(|e| matches!(e, Event::NotKnownFree { .. })),
        "{:?}",
        report.event_tags()
    );
    assert_eq!(m.main(), None, "a braking fallback is committed instead");
    assert!(!m.branches().is_empty(), "the branch itself is kept");
    // Observed free far enough: the same plan is committed.
    let mut m = planner(ManagerParams::trust());
    m.set_commit_check(Some(std::sync::Arc::new(KnownUpTo::x(100.0))));
    let report = m.step(0.0, &state, &GOAL, &scene).unwrap();
    assert!(m.main().is_some(), "{:?}", report.event_tags());
}

/// A sensed map's policy: everything committable, and a route map of its own (a wall across
/// the straight line that the planning map does not hold, as remembered beyond the window).
struct RoutesOnItsOwnMap {
    route_map: std::sync::Arc<StaticMap>,
}

impl trust_manager::CommitCheck for RoutesOnItsOwnMap {
    fn name(&self) -> &str {
        "routes on its own map"
    }

    fn segment_free(&self, _a: &Vec3, _b: &Vec3) -> bool {
        true
    }

    fn route_map(&self, _from: &Vec3, _goal: &Vec3) -> Option<std::sync::Arc<StaticMap>> {
        Some(std::sync::Arc::clone(&self.route_map))
    }
}

/// Issue 34: the route is searched on the commit check's own map when it gives one, and a route
/// that an obstacle seen since blocks (the planning map changed under it) is searched again
/// (`blocked`), no sooner than `BLOCKED_REROUTE_S` after the last search.
#[test]
fn a_sensed_route_uses_its_own_map_and_is_searched_again_when_blocked() {
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(60.0, 20.0, 8.0)).unwrap();
    let wall = |y0: f64, y1: f64| -> Shape {
        AaBox::new(Vec3::new(30.0, y0, 0.0), Vec3::new(31.0, y1, 8.0))
            .unwrap()
            .into()
    };
    let open = StaticMap::new(bounds).unwrap();
    let (start, goal) = (Vec3::new(3.0, 10.0, 3.5), Vec3::new(55.0, 10.0, 3.5));
    let route_map = StaticMap::from_shapes(bounds, vec![wall(0.0, 16.0)]).unwrap();
    let mut m = planner(ManagerParams::trust());
    m.set_router(Some(
        trust_manager::Router::new(trust_route::RouteParams::default(), 0.3).unwrap(),
    ));
    m.set_commit_check(Some(std::sync::Arc::new(RoutesOnItsOwnMap {
        route_map: std::sync::Arc::new(route_map),
    })));
    let scene = Scene::new(&open, &[], 0.0).unwrap();
    let mut state = State::at_rest(0.0, start);
    for i in 0..100 {
        state.t = 0.1 * i as f64;
        m.step(state.t, &state, &goal, &scene).unwrap();
        if m.route().is_some() {
            break;
        }
    }
    let route = m.route().expect("a route").clone();
    assert!(
        route.points().iter().any(|p| p.y > 16.0),
        "round the wall of the route's own map: {:?}",
        route.points()
    );
    // The planning map now holds a wall across that route (seen since): searched again.
    let seen = StaticMap::from_shapes(bounds, vec![wall(14.0, 20.0)]).unwrap();
    let scene = Scene::new(&seen, &[], 0.0).unwrap();
    let reasons: Vec<_> = (0..60)
        .flat_map(|i| {
            state.t += 0.1;
            let _ = i;
            m.step(state.t, &state, &goal, &scene)
                .unwrap()
                .events
                .into_iter()
                .filter_map(|e| match e {
                    Event::Rerouted { reason, .. } => Some((state.t, reason)),
                    _ => None,
                })
                .collect::<Vec<_>>()
        })
        .collect();
    assert!(
        matches!(
            reasons.first(),
            Some((_, trust_manager::RouteReason::Blocked))
        ),
        "{reasons:?}"
    );
}

/// Issue 34: on a sensed map the vehicle aims at what it can see on the route's own map. A
/// rolling window forgets the walls it has left; aimed past a corner through such a wall (a
/// sensed U-trap), the vehicle hovered against it for a minute.
#[test]
fn a_sensed_route_aims_at_its_corner_when_a_remembered_wall_hides_the_rest() {
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(60.0, 30.0, 8.0)).unwrap();
    let wall: Shape = AaBox::new(Vec3::new(30.0, 0.0, 0.0), Vec3::new(31.0, 16.0, 8.0))
        .unwrap()
        .into();
    // The planning map (the window) has forgotten the wall; the route's map remembers it.
    let open = StaticMap::new(bounds).unwrap();
    let route_map = std::sync::Arc::new(StaticMap::from_shapes(bounds, vec![wall]).unwrap());
    let (start, goal) = (Vec3::new(28.0, 10.0, 3.5), Vec3::new(55.0, 10.0, 3.5));
    let mut m = planner(ManagerParams::trust());
    m.set_router(Some(
        trust_manager::Router::new(trust_route::RouteParams::default(), 0.3).unwrap(),
    ));
    m.set_commit_check(Some(std::sync::Arc::new(RoutesOnItsOwnMap {
        route_map: std::sync::Arc::clone(&route_map),
    })));
    let scene = Scene::new(&open, &[], 0.0).unwrap();
    let mut state = State::at_rest(0.0, start);
    let mut aims = Vec::new();
    for i in 0..60 {
        state.t = 0.1 * i as f64;
        let report = m.step(state.t, &state, &goal, &scene).unwrap();
        if m.route().is_some() {
            aims.push(Vec3::from(report.aim));
        }
    }
    let route = m.route().expect("a route");
    assert!(
        route.points().iter().any(|p| p.y > 16.0),
        "round the wall: {:?}",
        route.points()
    );
    assert!(!aims.is_empty());
    for aim in aims {
        assert!(
            route_map.segment_clear(&start, &aim, 0.0),
            "aimed at {aim:?}, behind the remembered wall"
        );
    }
}

/// With a sensed map the fallback stays in known free space when it can: the ball rolling at
/// a vehicle at rest is dodged, but not into the unobserved side (+y), where a wall may stand.
#[test]
fn the_fallback_dodges_into_known_free_space() {
    let map = open_air();
    let ball = [rolling_ball()];
    let scene = Scene::new(&map, &ball, 0.0).unwrap();
    let start = State::at_rest(0.0, Vec3::new(50.0, 0.0, 5.0));
    let goal = Vec3::new(95.0, 0.0, 5.0);
    let widest_y = |max_y: Option<f64>| {
        let mut m = blind_single_branch_at_room_limits();
        if let Some(max_y) = max_y {
            m.set_commit_check(Some(std::sync::Arc::new(KnownUpTo::y(max_y))));
        }
        let r = m.step(0.0, &start, &goal, &scene).unwrap();
        assert!(r.fallback.is_some(), "every branch collides");
        let plan = m.plan().unwrap();
        let moved = plan.position(plan.t_end()) - start.p;
        assert!(moved.y.hypot(moved.z) > 0.7, "moved {moved:?}");
        (0..=100)
            .map(|k| {
                plan.position(plan.t_start() + plan.duration() * f64::from(k) / 100.0)
                    .y
            })
            .fold(f64::NEG_INFINITY, f64::max)
    };
    assert!(widest_y(Some(0.0)) <= 1e-9);
    // The check is what keeps it there: on the known map, the first dodge is to +y.
    assert!(widest_y(None) > 0.01);
}

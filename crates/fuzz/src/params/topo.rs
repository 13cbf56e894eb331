//! The params structs of trust-topo-prm at their edges, used by a search or a homotopy check on
//! valid scenes.

use trust_core::{GuidePath, HomotopyChecker, PathFrontend, PolyTraj, Scene, Vec3};
use trust_topo_prm::scenes::SceneParams;
use trust_topo_prm::{
    DevPrm, DevPrmParams, SparseAStar, SparseAStarParams, Tvd, TvdParams, Uvd, UvdParams, Vprm,
    VprmParams,
};

use super::{Field, Fields, judge, judge_use};
use crate::apis::{Api, Fixtures, Outcome};
use crate::inputs::Gen;

const DEVPRM: Fields<DevPrmParams> = Fields(&[
    Field::Float("devprm.inflate", |p, x| p.inflate.y = x),
    Field::Float("devprm.clearance", |p, x| p.clearance = x),
    Field::Float("devprm.resolution", |p, x| p.resolution = x),
    Field::Float("devprm.budget_ms", |p, x| p.budget_ms = x),
    Field::Count("devprm.max_samples", |p, x| p.max_samples = x),
    Field::Count("devprm.stall_samples", |p, x| p.stall_samples = x),
    Field::Count("devprm.beam_width", |p, x| p.beam_width = x),
    Field::Count("devprm.max_raw_paths", |p, x| p.max_raw_paths = x),
    Field::Count("devprm.keep_raw_paths", |p, x| p.keep_raw_paths = x),
    Field::Count("devprm.max_paths", |p, x| p.max_paths = x),
    Field::Float("devprm.length_ratio", |p, x| p.length_ratio = x),
    Field::Count("devprm.max_expansions", |p, x| p.max_expansions = x),
    Field::Float("devprm.pdc_horizon_s", |p, x| p.pdc_horizon_s = Some(x)),
    Field::Count("devprm.slices", |p, x| p.slices = x),
    Field::Count("devprm.samples_per_slice", |p, x| p.samples_per_slice = x),
    Field::Float("devprm.surface_offset", |p, x| p.surface_offset = x),
]);

const VPRM: Fields<VprmParams> = Fields(&[
    Field::Float("vprm.inflate", |p, x| p.inflate.x = x),
    Field::Float("vprm.clearance", |p, x| p.clearance = x),
    Field::Float("vprm.resolution", |p, x| p.resolution = x),
    Field::Float("vprm.budget_ms", |p, x| p.budget_ms = x),
    Field::Count("vprm.max_samples", |p, x| p.max_samples = x),
    Field::Count("vprm.max_raw_paths", |p, x| p.max_raw_paths = x),
    Field::Count("vprm.keep_raw_paths", |p, x| p.keep_raw_paths = x),
    Field::Count("vprm.max_paths", |p, x| p.max_paths = x),
    Field::Float("vprm.length_ratio", |p, x| p.length_ratio = x),
    Field::Count("vprm.max_expansions", |p, x| p.max_expansions = x),
]);

const ASTAR: Fields<SparseAStarParams> = Fields(&[
    Field::Float("sparse_astar.step", |p, x| p.step = x),
    Field::Float("sparse_astar.max_turn_deg", |p, x| p.max_turn_deg = x),
    Field::Count("sparse_astar.turn_branches", |p, x| p.turn_branches = x),
    Field::Float("sparse_astar.climb_deg", |p, x| p.climb_deg = x),
    Field::Float("sparse_astar.clearance", |p, x| p.clearance = x),
    Field::Float("sparse_astar.budget_ms", |p, x| p.budget_ms = x),
    Field::Count("sparse_astar.max_expansions", |p, x| p.max_expansions = x),
]);

const UVD: Fields<UvdParams> = Fields(&[
    Field::Float("uvd.resolution", |p, x| p.resolution = x),
    Field::Float("uvd.clearance", |p, x| p.clearance = x),
    Field::Float("uvd.pdc_horizon_s", |p, x| p.pdc_horizon_s = Some(x)),
]);

const TVD: Fields<TvdParams> = Fields(&[
    Field::Float("tvd.dt_s", |p, x| p.dt_s = x),
    Field::Float("tvd.clearance", |p, x| p.clearance = x),
]);

const SCENE: Fields<SceneParams> = Fields(&[
    Field::Float("scene.size", |p, x| p.size.x = x),
    Field::Float("scene.speed", |p, x| p.speed.1 = x),
    Field::Float("scene.radius", |p, x| p.radius.1 = x),
    Field::Float("scene.mu", |p, x| p.mu.1 = x),
    Field::Float("scene.r_safe", |p, x| p.r_safe = x),
    Field::Float("scene.cylinder_fraction", |p, x| p.cylinder_fraction = x),
    Field::Float("scene.margin", |p, x| p.margin = x),
    Field::Float("scene.endpoint_clearance", |p, x| p.endpoint_clearance = x),
    Field::Float("scene.horizon_s", |p, x| p.horizon_s = x),
]);

/// A valid query in `map` (start and goal at 5–95 % of the bounds, at rest): the params are the
/// only thing edited.
fn valid_query(g: &mut Gen, map: &trust_core::StaticMap) -> trust_core::PathQuery {
    let b = map.bounds();
    let mut p = || {
        let mut v = Vec3::zeros();
        for i in 0..3 {
            let f = (0.05 + 0.9 * g.num(0.0, 1.0).abs().fract()).clamp(0.05, 0.95);
            let f = if f.is_finite() { f } else { 0.5 };
            v[i] = b.min[i] + (b.max[i] - b.min[i]) * f;
        }
        v
    };
    let (mut s, mut goal) = (p(), p());
    // Start and goal in free space (the params are on trial, not the query).
    for _ in 0..50 {
        if map.signed_distance(&s) > 1.0 && map.signed_distance(&goal) > 1.0 {
            break;
        }
        (s, goal) = (p(), p());
    }
    trust_core::PathQuery {
        start: trust_core::State::at_rest(0.0, s),
        goal,
        limits: trust_core::Limits::default(),
        horizon_s: 3.0,
        exploration: 1.0,
    }
}

/// Budgets above a second are work the caller asked for, not accidents: validated, not run.
const RUN_BUDGET_MS: f64 = 1000.0;

fn frontends(g: &mut Gen, fx: &Fixtures) -> Outcome {
    let map = if g.chance(0.5) {
        &fx.shapes_map
    } else {
        &fx.cloud_map
    };
    let Ok(scene) = Scene::new(map, &fx.forecasts, 0.0) else {
        return Outcome::Err;
    };
    let q = valid_query(g, map);
    if scene.clearance(&q.start.p, 0.0) < 0.5 || scene.clearance(&q.goal, 0.0) < 0.5 {
        return Outcome::Err;
    }
    let mut rng = <trust_core::Rng as rand::SeedableRng>::seed_from_u64(7);
    let (result, edited) = match g.index(3) {
        0 => {
            let (p, edited) = DEVPRM.edit(g, DevPrmParams::default());
            if let Some(o) = judge(&p.validate(), &edited) {
                return o;
            }
            if p.budget_ms > RUN_BUDGET_MS {
                return Outcome::Ok;
            }
            let f = match DevPrm::new(p) {
                Ok(f) => f,
                Err(e) => return judge_use(&e, &edited),
            };
            (f.search(&q, &scene, &mut rng), edited)
        }
        1 => {
            let (p, edited) = VPRM.edit(g, VprmParams::default());
            if let Some(o) = judge(&p.validate(), &edited) {
                return o;
            }
            if p.budget_ms > RUN_BUDGET_MS {
                return Outcome::Ok;
            }
            let f = match Vprm::new(p) {
                Ok(f) => f,
                Err(e) => return judge_use(&e, &edited),
            };
            (f.search(&q, &scene, &mut rng), edited)
        }
        _ => {
            let (p, edited) = ASTAR.edit(g, SparseAStarParams::default());
            if let Some(o) = judge(&p.validate(), &edited) {
                return o;
            }
            if p.budget_ms > RUN_BUDGET_MS {
                return Outcome::Ok;
            }
            let f = match SparseAStar::new(p) {
                Ok(f) => f,
                Err(e) => return judge_use(&e, &edited),
            };
            (f.search(&q, &scene, &mut rng), edited)
        }
    };
    match result {
        Ok(r) => {
            for p in &r.paths {
                if !p.points.iter().all(|v| v.iter().all(|c| c.is_finite())) {
                    return Outcome::NonFinite(format!("path {p:?} with {edited:?}"));
                }
            }
            Outcome::Ok
        }
        Err(e) => judge_use(&e, &edited),
    }
}

fn checkers(g: &mut Gen, fx: &Fixtures) -> Outcome {
    let map = if g.chance(0.5) {
        &fx.shapes_map
    } else {
        &fx.cloud_map
    };
    let Ok(scene) = Scene::new(map, &fx.forecasts, 0.0) else {
        return Outcome::Err;
    };
    let q = valid_query(g, map);
    if g.chance(0.5) {
        let (p, edited) = UVD.edit(g, UvdParams::default());
        if let Some(o) = judge(&p.validate(), &edited) {
            return o;
        }
        let a = GuidePath {
            points: vec![q.start.p, q.goal],
        };
        let b = GuidePath {
            points: vec![
                q.start.p,
                (q.start.p + q.goal) * 0.5 + Vec3::new(0.0, 3.0, 0.0),
                q.goal,
            ],
        };
        let uvd = match Uvd::new(p) {
            Ok(u) => u,
            Err(e) => return judge_use(&e, &edited),
        };
        match uvd.equivalent(&a, &b, &scene) {
            Ok(_) => Outcome::Ok,
            Err(e) => judge_use(&e, &edited),
        }
    } else {
        let (p, edited) = TVD.edit(g, TvdParams::default());
        if let Some(o) = judge(&p.validate(), &edited) {
            return o;
        }
        let hold = if g.chance(0.2) { 1e5 } else { 2.0 };
        let (Ok(a), Ok(b)) = (
            PolyTraj::hold(0.0, q.start.p, hold),
            PolyTraj::hold(0.0, q.goal, hold),
        ) else {
            return Outcome::Err;
        };
        let tvd = match Tvd::new(p) {
            Ok(t) => t,
            Err(e) => return judge_use(&e, &edited),
        };
        match tvd.equivalent(&a, &b, &scene) {
            Ok(_) => Outcome::Ok,
            // A 1e5 s hold needs 2e6 samples at the default step: the error names the span.
            Err(e) if hold > 2.0 => {
                let mut culprits = edited.clone();
                culprits.push("common time span of the two trajectories");
                judge_use(&e, &culprits)
            }
            Err(e) => judge_use(&e, &edited),
        }
    }
}

fn scene_params(g: &mut Gen, _: &Fixtures) -> Outcome {
    let (p, edited) = SCENE.edit(g, SceneParams::default());
    if let Some(o) = judge(&p.validate(), &edited) {
        return o;
    }
    let mut rng = <trust_core::Rng as rand::SeedableRng>::seed_from_u64(3);
    match trust_topo_prm::scenes::random_dynamic_scene(g.count(5).min(16), &p, &mut rng) {
        Ok(s) => {
            if s.forecasts.iter().any(|f| f.validate().is_err()) {
                return Outcome::Wrong(format!("invalid forecast in a random scene ({edited:?})"));
            }
            Outcome::Ok
        }
        Err(e) => judge_use(&e, &edited),
    }
}

/// The APIs of this module.
pub fn apis() -> Vec<Api> {
    vec![
        Api {
            name: "params::topo::frontends",
            weight: 4,
            run: frontends,
        },
        Api {
            name: "params::topo::checkers",
            weight: 8,
            run: checkers,
        },
        Api {
            name: "params::topo::SceneParams",
            weight: 10,
            run: scene_params,
        },
    ]
}

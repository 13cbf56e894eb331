//! The scenario as flown: the world's scenario with the planner's `[planner]` section
//! ([`Scenario`] = `trust_world::Scenario<trust_planner::PlannerSpec>`), and what needs both.
//!
//! The world never names a planner type; this is where the two meet. A file read as
//! [`Scenario`] has its `[planner]` section parsed by serde with the rest of the file, so an
//! unknown key or kind in it is a [`WorldError::Parse`] with toml's line, column and snippet
//! like any other. The semantic checks then run in two halves: the world's
//! ([`trust_world::check`]: every other section, the layout, traffic, sensing, vehicle) and the
//! planner's ([`problems`]: the section's own values with field paths under `planner.`, the
//! delay owned by `sim.latency`, the budgets in real time, and — when everything else is valid
//! — the planner's assembly for the vehicle, [`check`]). `trust-sim validate` reports both.

use std::path::Path;

use trust_planner::{FrontendSpec, PlannerContext, PlannerSpec, ResolvedPlanner};
use trust_world::problem::{fmt_num, readable_value};
use trust_world::scenario::{Latency, MAX_CPU_SCALE, Problem};
use trust_world::{World, WorldError};

/// A scenario whose `[planner]` section is read as the planner's spec (module docs).
pub type Scenario = trust_world::Scenario<PlannerSpec>;

/// The planner of `s` with every part chosen ([`PlannerSpec::resolve`]). A fixed `sim.latency`
/// with `seconds` is the one owner of the delay: it becomes the manager's `latency_s`, so the
/// manager plans for the delay the loop applies ([`problems`] rejects a different
/// `[planner.manager] latency_s`), so the loop's `sim.latency.seconds` and the manager's
/// `latency()` are one value wherever both exist.
pub fn resolve_planner(s: &Scenario) -> ResolvedPlanner {
    let mut r = s.planner.resolve();
    if let Latency::Fixed {
        seconds: Some(seconds),
    } = s.sim.latency
    {
        r.manager.latency_s = Some(seconds);
    }
    r
}

/// What [`trust_planner::build`] needs of `world`: the vehicle's limits and radius, the planner
/// map's error bound and the trial's planner seed.
pub fn planner_context(world: &World) -> PlannerContext {
    PlannerContext {
        limits: world.limits(),
        vehicle_radius_m: world.vehicle_radius_m(),
        static_map_error_m: world.static_map_error_m().max(sensed_map_error_m(world)),
        seed: world.seeds().planner,
    }
}

/// The planner's tracking margin for `world` (m): `planner.tracking_margin_m`, else
/// `trust_planner::tracking_margin_for` the vehicle's `a_max`, as `trust_planner::effective`
/// sets it.
pub fn tracking_margin_m(world: &World, planner: &trust_planner::ResolvedPlanner) -> f64 {
    planner
        .tracking_margin_m
        .unwrap_or_else(|| trust_planner::tracking_margin_for(world.limits().a_max))
}

/// How much a sensed map (`[sensing.static]`) may overestimate the distance to a true static
/// obstacle (m): half a voxel's diagonal, `√3/2` times the voxel edge (a surface anywhere in an
/// occupied voxel, the field measured between voxel centres); 0 for a known map.
pub fn sensed_map_error_m(world: &World) -> f64 {
    world
        .scenario()
        .sensing
        .static_map
        .sensor()
        .map_or(0.0, |(_, map)| 0.5 * 3f64.sqrt() * map.resolution_m)
}

/// The planner's problems of `s` that the file alone shows: the `[planner]` section's own
/// ([`PlannerSpec::problems`], values made readable), a `[planner.manager] latency_s` that
/// disagrees with `sim.latency.seconds`, and budgets that leave their range in real time.
pub fn problems(s: &Scenario) -> Vec<Problem> {
    let mut p: Vec<Problem> = s
        .planner
        .problems()
        .into_iter()
        .map(|q| Problem {
            field: q.field,
            value: readable_value(&q.value),
            expected: q.expected,
        })
        .collect();
    match s.sim.latency {
        Latency::Fixed {
            seconds: Some(seconds),
        } => check_latency_owner(s, seconds, &mut p),
        Latency::Measured { cpu_scale } => {
            check_real_time_budgets(s, cpu_scale.unwrap_or(1.0), &mut p);
        }
        Latency::Fixed { seconds: None } => {}
    }
    p
}

/// Every problem of `s`, without building the maps: the world's ([`trust_world::check`]) and the
/// planner's ([`problems`]) and, when there is none, the planner's assembly for the vehicle
/// ([`trust_planner::build`] with `vehicle.limits`, `vehicle.radius_m` and the map's error
/// bound), reported on `planner`. Empty: the world builds and a flight of it starts.
pub fn check(s: &Scenario) -> Vec<Problem> {
    let mut p = trust_world::check(s);
    p.extend(problems(s));
    if p.is_empty() {
        let ctx = PlannerContext {
            limits: s.vehicle.limits,
            vehicle_radius_m: s.vehicle.radius_m,
            static_map_error_m: trust_world::static_map_error_for(s),
            seed: s.seeds().planner,
        };
        if let Err(e) = trust_planner::build(&resolve_planner(s), &ctx) {
            p.push(Problem::new(
                "planner",
                "(the file's values)",
                format!(
                    "values the planner assembly (with vehicle.limits and vehicle.radius_m) \
                     accepts; it reports: {e}"
                ),
            ));
        }
    }
    p
}

/// Reads, parses and checks a scenario file as [`Scenario::load`] does, with the planner's
/// [`problems`] added.
///
/// # Errors
/// [`WorldError::Read`], [`WorldError::Parse`] (a wrong planner key or kind too), or
/// [`WorldError::Invalid`] with every problem.
pub fn load(path: &Path) -> Result<Scenario, WorldError> {
    let s = Scenario::parse_file(path)?;
    let mut problems_found = s.validate();
    problems_found.extend(problems(&s));
    WorldError::unless_problems(s, path, problems_found)
}

/// Reads, parses and fully checks a scenario file ([`check`]): what `trust-sim validate`
/// reports, without building the maps.
///
/// # Errors
/// As [`load`].
pub fn load_checked(path: &Path) -> Result<Scenario, WorldError> {
    let s = Scenario::parse_file(path)?;
    let problems_found = check(&s);
    WorldError::unless_problems(s, path, problems_found)
}

/// One owner of the delay: the loop's and the one the manager plans for must agree.
fn check_latency_owner(s: &Scenario, seconds: f64, p: &mut Vec<Problem>) {
    if let Some(manager) = s
        .planner
        .manager
        .as_ref()
        .and_then(|m| m.latency_s)
        .filter(|m| *m != seconds)
    {
        p.push(Problem::new(
            "planner.manager.latency_s",
            fmt_num(manager),
            format!(
                "the same value as sim.latency.seconds ({}) or no value: the manager plans for \
                 the delay the loop applies; set it in one place",
                fmt_num(seconds)
            ),
        ));
    }
}

/// In real time the loop divides the planner's budgets by the CPU scale
/// ([`crate::real_time_planner`]: the cycle budget and the frontend's `budget_ms`); the divided
/// budgets must stay within the ranges the planning crates accept, or the flight's set-up would
/// refuse what validation accepted (found by `trust-fuzz`'s file groups: `budget_ms = 200` at
/// `cpu_scale = 1e-5` is 2e7 ms). Reported on the scale, with the budget it breaks.
fn check_real_time_budgets(s: &Scenario, scale: f64, p: &mut Vec<Problem>) {
    if !(scale > 0.0 && scale <= MAX_CPU_SCALE) {
        return;
    }
    let r = resolve_planner(s);
    let frontend_ms = match &r.frontend {
        FrontendSpec::DevPrm(x) => Some(x.budget_ms),
        FrontendSpec::VPrm(x) => Some(x.budget_ms),
        FrontendSpec::SparseAStar(x) => Some(x.budget_ms),
        FrontendSpec::StraightLine(_) => None,
    };
    let max = trust_topo_prm::ranges::MAX_BUDGET_MS;
    let min = trust_core::scale::MIN_POSITIVE;
    let budgets = [
        (
            "planner.manager.cycle_budget_ms",
            Some(r.manager.cycle_budget_ms),
            (f64::MIN_POSITIVE, f64::MAX),
            "finite and > 0".to_string(),
        ),
        (
            "planner.frontend.budget_ms",
            frontend_ms,
            (min, max),
            format!("in [{}, {}] ms", fmt_num(min), fmt_num(max)),
        ),
    ];
    for (field, budget, (lo, hi), range) in budgets {
        let Some(b) = budget.filter(|b| b.is_finite() && *b > 0.0) else {
            // A bad budget is its own field's problem.
            continue;
        };
        let scaled = b / scale;
        if !(scaled >= lo && scaled <= hi) {
            p.push(Problem::new(
                "sim.latency.cpu_scale",
                fmt_num(scale),
                format!(
                    "a CPU scale that keeps the planner's budgets in range in real time \
                     ({field} {} ms / {} = {} ms; expected {range})",
                    fmt_num(b),
                    fmt_num(scale),
                    fmt_num(scaled)
                ),
            ));
        }
    }
}

//! `LbfgsParams` and `Lbfgs::new`'s dimension at their edges.

use trust_lbfgs::{Lbfgs, LbfgsParams};

use super::{COUNT_EDGES, Field, Fields, judge, judge_use};
use crate::apis::{Api, Fixtures, Outcome};
use crate::inputs::Gen;

const FIELDS: Fields<LbfgsParams> = Fields(&[
    Field::Count("memory", |p, x| p.memory = x),
    Field::Count("past", |p, x| p.past = x),
    Field::Count("max_iterations", |p, x| p.max_iterations = x),
    Field::Count("max_evaluations", |p, x| p.max_evaluations = x),
    Field::Count("max_linesearch", |p, x| p.max_linesearch = x),
    Field::Float("g_epsilon", |p, x| p.g_epsilon = x),
    Field::Float("delta", |p, x| p.delta = x),
    Field::Float("min_step", |p, x| p.min_step = x),
    Field::Float("max_step", |p, x| p.max_step = x),
    Field::Float("f_dec_coeff", |p, x| p.f_dec_coeff = x),
    Field::Float("s_curv_coeff", |p, x| p.s_curv_coeff = x),
    Field::Float("cautious_factor", |p, x| p.cautious_factor = x),
]);

fn lbfgs_params(g: &mut Gen, _: &Fixtures) -> Outcome {
    let (params, edited) = FIELDS.edit(g, LbfgsParams::default());
    if let Some(o) = judge(&params.validate(), &edited) {
        return o;
    }
    // Accepted: a solve of a small problem ends with a finite point and cost. Budgets keep
    // "unlimited" settings from turning into long runs.
    let mut solver = match Lbfgs::new(3, params) {
        Ok(s) => s,
        Err(e) => return judge_use(&e, &edited),
    };
    let mut x = [-1.2, 1.0, 0.5];
    let deadline = std::time::Instant::now() + std::time::Duration::from_millis(200);
    let mut monitor = trust_lbfgs::Deadline::new(deadline);
    let r = match solver.minimize(
        &mut x,
        trust_lbfgs::test_functions::rosenbrock,
        &mut monitor,
    ) {
        Ok(r) => r,
        Err(e) => return judge_use(&e, &edited),
    };
    if !(r.cost.is_finite() && x.iter().all(|v| v.is_finite())) {
        return Outcome::NonFinite(format!("cost {} at {x:?} with {edited:?}", r.cost));
    }
    Outcome::Ok
}

fn lbfgs_dimension(g: &mut Gen, _: &Fixtures) -> Outcome {
    let dimension = COUNT_EDGES[g.index(COUNT_EDGES.len())];
    let (params, edited) = if g.chance(0.5) {
        FIELDS.edit(g, LbfgsParams::default())
    } else {
        (LbfgsParams::default(), Vec::new())
    };
    let mut culprits = edited.clone();
    culprits.push("dimension");
    match Lbfgs::new(dimension, params) {
        Ok(s) => {
            if s.dimension() != dimension {
                return Outcome::Wrong(format!("dimension {} != {dimension}", s.dimension()));
            }
            Outcome::Ok
        }
        Err(e) => judge_use(&e, &culprits),
    }
}

/// The APIs of this module.
pub fn apis() -> Vec<Api> {
    vec![
        Api {
            name: "params::lbfgs::LbfgsParams",
            weight: 10,
            run: lbfgs_params,
        },
        Api {
            name: "params::lbfgs::Lbfgs::new(dimension)",
            weight: 10,
            run: lbfgs_dimension,
        },
    ]
}

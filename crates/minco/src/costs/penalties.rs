//! All sampled penalties of the objective in one integrand: moving obstacles, static map, speed
//! and acceleration, with their weights and their separate (unweighted) integrals.

use trust_core::{Aabb, Forecast, Limits, StaticMap};

use super::dynamic::DynamicObstacleTerm;
use super::feasibility::FeasibilityTerm;
use super::integrate::{Integrand, SampleGrad, SampleState};
use super::static_map::StaticObstacleTerm;
use super::{CostWeights, PenaltyParams};

/// Unweighted integrals of the sampled penalties at the last integration.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PenaltyIntegrals {
    /// Moving obstacles (DDF), part of `I_o`.
    pub dynamic: f64,
    /// Static map, part of `I_o`.
    pub static_map: f64,
    /// Speed, part of `I_d`.
    pub speed: f64,
    /// Acceleration, part of `I_d`.
    pub acceleration: f64,
}

impl PenaltyIntegrals {
    /// `I_o` = moving obstacles + static map.
    pub fn obstacle(&self) -> f64 {
        self.dynamic + self.static_map
    }

    /// `I_d` = speed + acceleration.
    pub fn feasibility(&self) -> f64 {
        self.speed + self.acceleration
    }
}

/// The integrand `λ_o (L_o + L_s) + λ_d L_d` of paper eq. design-of-J, evaluated in one pass over
/// the samples (each node's derivatives are computed once for all terms). Records the unweighted
/// integral of each part ([`PenaltyIntegrand::integrals`]); call
/// [`PenaltyIntegrand::reset_integrals`] before each integration.
#[derive(Debug, Clone)]
pub struct PenaltyIntegrand<'a> {
    dynamic: DynamicObstacleTerm<'a>,
    static_map: StaticObstacleTerm<'a>,
    feasibility: FeasibilityTerm,
    obstacle_weight: f64,
    feasibility_weight: f64,
    dynamic_active: bool,
    static_active: bool,
    integrals: PenaltyIntegrals,
}

impl<'a> PenaltyIntegrand<'a> {
    /// The penalties against `forecasts` and `map` for `limits`, with weights `λ_o`, `λ_d` from
    /// `weights` and shapes from `params`.
    pub fn new(
        forecasts: &'a [Forecast],
        map: &'a StaticMap,
        limits: Limits,
        weights: &CostWeights,
        params: &PenaltyParams,
    ) -> Self {
        Self {
            dynamic: DynamicObstacleTerm::new(
                forecasts,
                params.dynamic_clearance_m,
                params.smoothing,
            ),
            static_map: StaticObstacleTerm::new(map, params.static_clearance_m, params.smoothing),
            feasibility: FeasibilityTerm::new(limits, params.smoothing),
            obstacle_weight: weights.obstacle,
            feasibility_weight: weights.feasibility,
            dynamic_active: false,
            static_active: false,
            integrals: PenaltyIntegrals::default(),
        }
    }

    /// Zeroes the recorded integrals.
    pub fn reset_integrals(&mut self) {
        self.integrals = PenaltyIntegrals::default();
    }

    /// Unweighted integrals accumulated since the last reset.
    pub fn integrals(&self) -> PenaltyIntegrals {
        self.integrals
    }
}

impl Integrand for PenaltyIntegrand<'_> {
    fn begin_trajectory(&mut self, t_begin: f64, t_end: f64, samples_box: &Aabb) {
        self.dynamic
            .begin_trajectory_impl(t_begin, t_end, samples_box);
    }

    fn begin_piece(&mut self, _piece: usize, t_begin: f64, t_end: f64, samples_box: &Aabb) -> bool {
        self.dynamic_active = self.dynamic.begin_piece_impl(t_begin, t_end, samples_box);
        self.static_active = self.static_map.begin_piece_impl(samples_box);
        true
    }

    #[inline]
    fn sample(&mut self, s: &SampleState, grad: &mut SampleGrad) -> f64 {
        let (wo, wd) = (self.obstacle_weight, self.feasibility_weight);
        let mut total = 0.0;
        if self.dynamic_active {
            let l = self.dynamic.sample_weighted(s, grad, wo);
            self.integrals.dynamic += s.weight * l;
            total += wo * l;
        }
        if self.static_active {
            let l = self.static_map.sample_weighted(s, grad, wo);
            self.integrals.static_map += s.weight * l;
            total += wo * l;
        }
        let (lv, la) = self.feasibility.sample_parts(s, grad, wd);
        self.integrals.speed += s.weight * lv;
        self.integrals.acceleration += s.weight * la;
        total + wd * (lv + la)
    }
}

//! The closed enums that make any combination of parts one type: [`AnyFrontend`],
//! [`AnyBackend`] and [`AnyChecker`] implement the `trust-core` traits by delegation, so a
//! planner of any combination is one [`AnyManager`] (style rule 4: the concrete types are chosen
//! once, at the top, from a serde enum; everything below stays generic).

use trust_core::{
    Curve, HomotopyChecker, PathFrontend, PathQuery, PlanError, Rng, Scene, SearchResult, Solution,
    TrajRequest, TrajectoryBackend,
};
use trust_manager::Manager;
use trust_minco::{Minco, UtfMinco};
use trust_topo_prm::{DevPrm, SparseAStar, StraightLine, Tvd, Uvd, Vprm};

/// A frontend of any supported kind, implementing [`PathFrontend`] by delegation.
#[derive(Debug, Clone)]
pub enum AnyFrontend {
    /// DEV-PRM (`"dev-prm"`).
    DevPrm(DevPrm),
    /// V-PRM (`"v-prm"`).
    Vprm(Vprm),
    /// The straight line of baseline 1 (`"straight-line"`).
    StraightLine(StraightLine),
    /// Sparse A* of baseline 2 (`"sparse-a-star"`).
    SparseAStar(SparseAStar),
}

impl PathFrontend for AnyFrontend {
    fn name(&self) -> &str {
        match self {
            AnyFrontend::DevPrm(f) => f.name(),
            AnyFrontend::Vprm(f) => f.name(),
            AnyFrontend::StraightLine(f) => f.name(),
            AnyFrontend::SparseAStar(f) => f.name(),
        }
    }

    fn search(
        &self,
        query: &PathQuery,
        scene: &Scene<'_>,
        rng: &mut Rng,
    ) -> Result<SearchResult, PlanError> {
        match self {
            AnyFrontend::DevPrm(f) => f.search(query, scene, rng),
            AnyFrontend::Vprm(f) => f.search(query, scene, rng),
            AnyFrontend::StraightLine(f) => f.search(query, scene, rng),
            AnyFrontend::SparseAStar(f) => f.search(query, scene, rng),
        }
    }
}

/// A backend of any supported kind, implementing [`TrajectoryBackend`] by delegation.
#[derive(Debug, Clone)]
pub enum AnyBackend {
    /// UTF-MINCO (`"utf-minco"`).
    UtfMinco(UtfMinco),
    /// The original fixed-terminal MINCO (`"minco"`).
    Minco(Minco),
}

impl TrajectoryBackend for AnyBackend {
    fn name(&self) -> &str {
        match self {
            AnyBackend::UtfMinco(b) => b.name(),
            AnyBackend::Minco(b) => b.name(),
        }
    }

    fn optimize(&self, req: &TrajRequest<'_>, scene: &Scene<'_>) -> Result<Solution, PlanError> {
        match self {
            AnyBackend::UtfMinco(b) => b.optimize(req, scene),
            AnyBackend::Minco(b) => b.optimize(req, scene),
        }
    }
}

/// A homotopy checker of any supported kind, implementing [`HomotopyChecker`] by delegation.
#[derive(Debug, Clone)]
pub enum AnyChecker {
    /// Temporal visibility deformation (`"tvd"`).
    Tvd(Tvd),
    /// Uniform visibility deformation (`"uvd"`).
    Uvd(Uvd),
}

impl HomotopyChecker for AnyChecker {
    fn name(&self) -> &str {
        match self {
            AnyChecker::Tvd(c) => c.name(),
            AnyChecker::Uvd(c) => c.name(),
        }
    }

    fn equivalent(
        &self,
        a: &dyn Curve,
        b: &dyn Curve,
        scene: &Scene<'_>,
    ) -> Result<bool, PlanError> {
        match self {
            AnyChecker::Tvd(c) => c.equivalent(a, b, scene),
            AnyChecker::Uvd(c) => c.equivalent(a, b, scene),
        }
    }
}

/// The manager of any planner this module assembles.
pub type AnyManager = Manager<AnyFrontend, AnyBackend, AnyChecker>;

//! [`Vprm`]: a faithful visibility PRM (Fast-Planner's topological planner, Zhou et al. 2020), the
//! paper's comparison point in experiment E1 (Fig. Sim-A-1-1(c)).
//!
//! Guards and connectors over samples from a box between start and goal, UVD-redundant connectors,
//! dead-end pruning, bounded depth-first search, shortcutting, equivalence pruning and K-shortest
//! selection with a length ratio — against the static map, with moving obstacles (optionally) frozen
//! where they are at the query time, as an occupancy map would show them. It never uses their motion.

use serde::{Deserialize, Serialize};

use trust_core::{PathFrontend, PathQuery, PlanError, Rng, Scene, SearchResult, Vec3};

use crate::prm::{ConeMode, PrmSetup, run};

/// Parameters of [`Vprm`]. Defaults are Fast-Planner's (its `topo_prm` launch parameters) unless
/// stated otherwise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct VprmParams {
    /// Sampling-box inflation (m): along start→goal (added to half the distance), horizontal,
    /// vertical. Fast-Planner: (1.0, 3.5, 1.0).
    /// Accepted: each component in `[0, 1e6]` m.
    pub inflate: Vec3,
    /// Samples closer than this to an obstacle are rejected (m). Fast-Planner: 0.3.
    /// Accepted: `[0, 1e6]` m.
    pub clearance: f64,
    /// Map resolution (m): roadmap edges keep this distance from obstacles, and UVD and shortcutting
    /// step by it. Fast-Planner: 0.1.
    /// Accepted: `[1e-3, 1e6]` m ([`crate::ranges::MIN_RESOLUTION_M`]).
    pub resolution: f64,
    /// Budget of the roadmap construction and shortcutting (ms): a work count
    /// ([`VprmParams::work_per_ms`]) and the monotonic clock ([`VprmParams::wall_clock_budget`]).
    /// Fast-Planner: 5 ms
    /// (experiment E1 uses 20 ms).
    /// Accepted: `(0, 6e5]` ms ([`crate::ranges::MAX_BUDGET_MS`]).
    pub budget_ms: f64,
    /// Work units per ms of `budget_ms`: the search stops after `budget_ms · work_per_ms`
    /// units — 80 % for the roadmap, the rest for shortcutting the raw paths — and returns the
    /// paths found so far with `SearchStats::budget_exhausted` set. A unit is an estimated
    /// nanosecond of the development machine ([`crate::QueryWork`]: map queries, ESDF samples,
    /// shape and cone tests, samples, each with a fitted weight), so the default `1e6` makes the
    /// budget about `budget_ms` of that machine whatever the map. Unlike the clock, the count
    /// gives the same paths for the same seed on any machine.
    /// Accepted: `(0, 1e12]` ([`crate::ranges::MAX_WORK_PER_MS`]).
    pub work_per_ms: f64,
    /// Also stop on the monotonic clock at `budget_ms` (the wall-clock guard of real-time runs).
    /// Default `true`; `false` leaves only the work budget and the counts, so a run depends on its
    /// seed alone (`trust-world`'s reproducible mode).
    pub wall_clock_budget: bool,
    /// Sample budget of the roadmap construction. Fast-Planner: 2000. V-PRM samples until this or
    /// `budget_ms` binds, as Fast-Planner does (no stop when the roadmap stalls, unlike
    /// [`crate::DevPrmParams::stall_samples`]).
    /// Accepted: `[0, 1e6]` (`scale::MAX_SAMPLE_COUNT`).
    pub max_samples: usize,
    /// The depth-first search stops after this many raw paths. Fast-Planner: 300.
    /// Accepted: `[1, 1e5]` ([`crate::ranges::MAX_PATH_COUNT`]).
    pub max_raw_paths: usize,
    /// Raw paths kept (fewest nodes first) for shortcutting. Fast-Planner: 25.
    /// Accepted: `[1, 1e5]` ([`crate::ranges::MAX_PATH_COUNT`]).
    pub keep_raw_paths: usize,
    /// At most this many paths are returned. Fast-Planner: 6 (`reserve_num`).
    /// Accepted: `[1, 1e5]` ([`crate::ranges::MAX_PATH_COUNT`]).
    pub max_paths: usize,
    /// Paths longer than this times the shortest are dropped. Fast-Planner: 5.5.
    /// Accepted: `[1, 1e6]` ([`crate::ranges::MAX_LENGTH_RATIO`]).
    pub length_ratio: f64,
    /// The search stops after this many node expansions. Ours (the anchor has no bound): 100 000, far
    /// above what the 300-path bound needs on a pruned roadmap.
    /// Accepted: `[1, 1e6]` ([`crate::ranges::MAX_EXPANSIONS`]).
    pub max_expansions: usize,
    /// See moving obstacles as static obstacles where they are at the query time (their shape with
    /// radius `radius(t)`), as Fast-Planner sees them in its occupancy map. Ours: `true`; `false`
    /// plans against the static map alone.
    pub freeze_forecasts: bool,
}

impl Default for VprmParams {
    fn default() -> Self {
        VprmParams {
            inflate: Vec3::new(1.0, 3.5, 1.0),
            clearance: 0.3,
            resolution: 0.1,
            budget_ms: 5.0,
            work_per_ms: 1.0e6,
            wall_clock_budget: true,
            max_samples: 2000,
            max_raw_paths: 300,
            keep_raw_paths: 25,
            max_paths: 6,
            length_ratio: 5.5,
            max_expansions: 100_000,
            freeze_forecasts: true,
        }
    }
}

crate::prm::impl_shared_setup!(VprmParams);

impl VprmParams {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), PlanError> {
        self.setup().map(|_| ())
    }

    fn setup(&self) -> Result<PrmSetup, PlanError> {
        let setup = PrmSetup {
            cones: if self.freeze_forecasts {
                ConeMode::Frozen
            } else {
                ConeMode::Ignore
            },
            ..self.shared_setup()
        };
        setup.check_shared("vprm")?;
        Ok(setup)
    }
}

/// The visibility PRM of Fast-Planner as a [`PathFrontend`] (`"v-prm"`). Paths end at the goal.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Vprm {
    params: VprmParams,
}

impl Vprm {
    /// A planner with validated parameters.
    pub fn new(params: VprmParams) -> Result<Self, PlanError> {
        params.validate()?;
        Ok(Vprm { params })
    }

    /// The parameters.
    pub fn params(&self) -> &VprmParams {
        &self.params
    }
}

impl PathFrontend for Vprm {
    fn name(&self) -> &str {
        "v-prm"
    }

    fn search(
        &self,
        query: &PathQuery,
        scene: &Scene<'_>,
        rng: &mut Rng,
    ) -> Result<SearchResult, PlanError> {
        run(&self.params.setup()?, query, scene, rng)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_values_are_named() {
        assert!(VprmParams::default().validate().is_ok());
        let bad = VprmParams {
            length_ratio: 0.5,
            ..VprmParams::default()
        };
        let e = bad.validate().unwrap_err().to_string();
        assert!(e.contains("vprm.length_ratio") && e.contains("0.5"), "{e}");
        let bad = VprmParams {
            budget_ms: 1e300,
            ..VprmParams::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .contains("vprm.budget_ms")
        );
        let bad = VprmParams {
            inflate: Vec3::new(1.0, -1.0, 0.0),
            ..VprmParams::default()
        };
        assert!(Vprm::new(bad).is_err());
        let bad = VprmParams {
            max_paths: 0,
            ..VprmParams::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .contains("vprm.max_paths")
        );
    }

    #[test]
    fn params_deserialize_strictly() {
        let p: VprmParams = serde_json::from_str(r#"{"budget_ms": 20.0}"#).unwrap();
        assert_eq!(p.budget_ms, 20.0);
        assert_eq!(p.max_samples, 2000);
        assert!(serde_json::from_str::<VprmParams>(r#"{"budget": 20.0}"#).is_err());
    }
}

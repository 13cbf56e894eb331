//! [`DevPrm`]: the Dynamic Enhanced Visible PRM of TRUST-Planner (paper Sec. III-B, Algorithm 2).
//!
//! V-PRM plus three enhancements:
//! 1. visibility against the predictive directional cones (PDCs, eq. PDC) of all forecasts over the
//!    query horizon `T_h`, so paths avoid where moving obstacles may be;
//! 2. obstacle-aware samples on the PDC surfaces, on slices along the predicted velocity, inserted
//!    before the random samples (`ConstructRoadMap(G, P_PDC)`);
//! 3. the goal guidance surface (GGS): paths end on the sphere of radius
//!    `r_des = ‖p_s − p_g‖ − T_h·v_max` around the goal, or at the goal when `r_des <= 0`.
//!
//! The roadmap is searched by a beam search (bounded-width best-first expansion of partial paths by
//! estimated length) and then `TopoPathSelect` (shortcut, UVD-against-PDC pruning, K-shortest with a
//! length ratio). Each enhancement can be switched off for ablations.
//!
//! Details the paper leaves open, as implemented here:
//! * the cones span `[query.start.t, query.start.t + query.horizon_s]`;
//! * a cone that contains the start (or the goal, when paths end there) cannot be avoided in space
//!   and is ignored by the roadmap — the trajectory backend handles it in time;
//! * the budget `t_max` (`budget_ms`) covers the roadmap construction (obstacle-aware and random
//!   samples) and the shortcutting of the raw paths, as a deterministic work count
//!   (`budget_ms · work_per_ms` units, [`crate::QueryWork`]) and, unless
//!   `wall_clock_budget` is off, the monotonic clock; the graph search is bounded by
//!   `max_expansions`, and the selection tests only the paths it could keep;
//! * besides `t_max` and `N_max`, random sampling stops when the roadmap stalls
//!   ([`DevPrmParams::stall_samples`]): the coverage rule of the original visibility PRM (Siméon et
//!   al. 2000), which Fast-Planner replaced by a fixed budget;
//! * obstacle-aware samples lie on slices of each PDC and, for a moving obstacle, on its axis beyond
//!   the first and last slice ([`trust_predict::Pdc::surface_samples`]); they are inserted first, when
//!   only the start and the terminal are guards, so one that sees a single guard is kept and retried
//!   against the guards added later ([`crate::roadmap::RoadmapBuilder::add_persistent_sample`])
//!   instead of being discarded;
//! * the sampling box spans the start and the point of the GGS nearest to it, and samples inside the
//!   GGS ball are rejected.

use serde::{Deserialize, Serialize};

use trust_core::{PathFrontend, PathQuery, PlanError, Rng, Scene, SearchResult, Vec3};

use crate::prm::{ConeMode, GraphSearch, PrmSetup, SurfaceSampling, run};
use crate::ranges;
use trust_core::scale::{self, Quantity};

/// Parameters of [`DevPrm`]. The V-PRM part defaults to Fast-Planner's values (see
/// [`crate::VprmParams`]); the paper gives no values for the rest, so they are ours, as stated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DevPrmParams {
    /// Sampling-box inflation (m) along, across and above the start→terminal line, as in V-PRM.
    /// Ours: (1, 10, 5). Fast-Planner's (1, 3.5, 1) box is walled off by the PDCs in the
    /// paper's scenes: on E3 (`scenarios/e3.toml`, seeds 0–7) it gave 0–1 paths per query, on E4
    /// seeds 0–2 the closed loop fell back to braking 1–18 times per flight and took 32–35 s;
    /// with (1, 10, 5) and [`DevPrmParams::pdc_horizon_s`] = 2 s, E3 gives 3–6 paths and E4 flies
    /// in 29–31 s without a fallback, at about 3× the frontend time.
    /// Accepted: each component in `[0, 1e6]` m.
    pub inflate: Vec3,
    /// Samples closer than this to an obstacle (static or PDC) are rejected (m). Fast-Planner: 0.3.
    /// Accepted: `[0, 1e6]` m.
    pub clearance: f64,
    /// Resolution (m): edge threshold and UVD/shortcut step. Fast-Planner: 0.1.
    /// Accepted: `[1e-3, 1e6]` m ([`crate::ranges::MIN_RESOLUTION_M`]).
    pub resolution: f64,
    /// Budget `t_max` of the roadmap construction and shortcutting (ms): a work count
    /// ([`DevPrmParams::work_per_ms`]) and the monotonic clock ([`DevPrmParams::wall_clock_budget`]).
    /// Fast-Planner's 5 ms (E1 uses 20 ms).
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
    /// Random-sample budget `N_max`. Fast-Planner's 2000.
    /// Accepted: `[0, 1e6]` (`scale::MAX_SAMPLE_COUNT`).
    pub max_samples: usize,
    /// Random sampling stops early after this many consecutive samples in free space that added
    /// neither a guard nor a connector; `0` switches the stop off (only `budget_ms` and `max_samples`
    /// bind, as in Fast-Planner). This is the termination rule of the original visibility PRM
    /// (Siméon, Laumond & Nissoux 2000: stop after `M` consecutive failures to add a guard, `1/M`
    /// estimating the part of the free space no guard sees), extended to connectors because the
    /// homotopy classes live in them. Ours: 200 (the guards see an estimated 99.5 % of the sampling
    /// region, and the last 200 samples brought no new connector, i.e. no candidate class).
    /// Accepted: `[0, 1e6]` (`scale::MAX_SAMPLE_COUNT`).
    pub stall_samples: usize,
    /// Width of the beam search (partial paths kept per level). Ours: 16.
    /// Accepted: `[1, 1024]` ([`crate::ranges::MAX_BEAM_WIDTH`]).
    pub beam_width: usize,
    /// The search stops after this many raw paths. Fast-Planner: 300.
    /// Accepted: `[1, 1e5]` ([`crate::ranges::MAX_PATH_COUNT`]).
    pub max_raw_paths: usize,
    /// Raw paths kept (shortest first) for shortcutting. Fast-Planner: 25.
    /// Accepted: `[1, 1e5]` ([`crate::ranges::MAX_PATH_COUNT`]).
    pub keep_raw_paths: usize,
    /// At most this many paths are returned. Fast-Planner: 6.
    /// Accepted: `[1, 1e5]` ([`crate::ranges::MAX_PATH_COUNT`]).
    pub max_paths: usize,
    /// Paths longer than this times the shortest are dropped. Fast-Planner: 5.5.
    /// Accepted: `[1, 1e6]` ([`crate::ranges::MAX_LENGTH_RATIO`]).
    pub length_ratio: f64,
    /// The search stops after this many partial-path expansions. Ours: 100 000.
    /// Accepted: `[1, 1e6]` ([`crate::ranges::MAX_EXPANSIONS`]).
    pub max_expansions: usize,
    /// Test visibility against the PDCs of all forecasts (enhancement 1). Default `true`.
    pub pdc: bool,
    /// The PDCs span `min(query.horizon_s, pdc_horizon_s)` (s); `None` spans the query horizon.
    /// The paper builds the PDC "over a short time horizon" without a value. Ours: 2 s (E1's
    /// horizon): over the manager's 4 s horizon the cones of E3's EKF forecasts (growing at
    /// 0.56 m/s) fill the corridor; the backend still avoids the obstacles over the whole horizon.
    /// Accepted: `[0, 1e7]` s, or `None`.
    pub pdc_horizon_s: Option<f64>,
    /// Insert obstacle-aware samples on PDC surfaces before random sampling (enhancement 2; needs
    /// `pdc`). Default `true`.
    pub obstacle_aware_samples: bool,
    /// Slices along each PDC's predicted velocity. Ours: 3 (start, middle and end of the horizon).
    /// Accepted: `≥ 1` with `slices · samples_per_slice ≤ 1e4` ([`crate::ranges::MAX_SURFACE_SAMPLES`]).
    pub slices: usize,
    /// Samples on each slice. Ours: 8 (every 45°).
    /// Accepted: `≥ 1` with `slices · samples_per_slice ≤ 1e4`.
    pub samples_per_slice: usize,
    /// Signed distance of the obstacle-aware samples from the PDC surface (m); must be at least
    /// `clearance`. Ours: 0.5 (the 0.3 m clearance plus two resolutions).
    /// Accepted: `[clearance, 1e6]` m.
    pub surface_offset: f64,
    /// End paths on the goal guidance surface (enhancement 3). Default `true`.
    pub goal_guidance_surface: bool,
}

impl Default for DevPrmParams {
    fn default() -> Self {
        DevPrmParams {
            inflate: Vec3::new(1.0, 10.0, 5.0),
            clearance: 0.3,
            resolution: 0.1,
            budget_ms: 5.0,
            work_per_ms: 1.0e6,
            wall_clock_budget: true,
            max_samples: 2000,
            stall_samples: 200,
            beam_width: 16,
            max_raw_paths: 300,
            keep_raw_paths: 25,
            max_paths: 6,
            length_ratio: 5.5,
            max_expansions: 100_000,
            pdc: true,
            pdc_horizon_s: Some(2.0),
            obstacle_aware_samples: true,
            slices: 3,
            samples_per_slice: 8,
            surface_offset: 0.5,
            goal_guidance_surface: true,
        }
    }
}

crate::prm::impl_shared_setup!(DevPrmParams);

impl DevPrmParams {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), PlanError> {
        self.setup().map(|_| ())
    }

    fn setup(&self) -> Result<PrmSetup, PlanError> {
        let shared = self.shared_setup();
        shared.check_shared("devprm")?;
        ranges::count(
            "devprm.stall_samples",
            self.stall_samples,
            0,
            trust_core::scale::MAX_SAMPLE_COUNT,
        )?;
        ranges::count(
            "devprm.beam_width",
            self.beam_width,
            1,
            ranges::MAX_BEAM_WIDTH,
        )?;
        if self.obstacle_aware_samples {
            ranges::count("devprm.slices", self.slices, 1, ranges::MAX_SURFACE_SAMPLES)?;
            ranges::count(
                "devprm.samples_per_slice",
                self.samples_per_slice,
                1,
                ranges::MAX_SURFACE_SAMPLES,
            )?;
            scale::check_count(
                "devprm.slices * devprm.samples_per_slice",
                self.slices as u128 * self.samples_per_slice as u128,
                ranges::MAX_SURFACE_SAMPLES,
            )?;
            // At least the sample clearance (a surface sample must be a valid sample), at most a
            // length of the scale policy.
            ranges::range(
                "devprm.surface_offset",
                self.surface_offset,
                self.clearance,
                scale::MAX_LENGTH_M,
                "m (lower end: devprm.clearance)",
            )?;
        }
        if let Some(h) = self.pdc_horizon_s {
            ranges::quantity("devprm.pdc_horizon_s", h, Quantity::Duration)?;
        }
        Ok(PrmSetup {
            stall_samples: self.stall_samples,
            search: GraphSearch::Beam {
                width: self.beam_width,
            },
            cones: if self.pdc {
                ConeMode::Predictive {
                    pdc_horizon_s: self.pdc_horizon_s.unwrap_or(f64::INFINITY),
                }
            } else {
                ConeMode::Ignore
            },
            surface_sampling: (self.pdc && self.obstacle_aware_samples).then_some(
                SurfaceSampling {
                    slices: self.slices,
                    per_slice: self.samples_per_slice,
                    offset: self.surface_offset,
                },
            ),
            goal_surface: self.goal_guidance_surface,
            ..shared
        })
    }
}

/// DEV-PRM as a [`PathFrontend`] (`"dev-prm"`). Paths end on the GGS, or at the goal when it is
/// within reach (`r_des <= 0`) or the GGS is switched off.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DevPrm {
    params: DevPrmParams,
}

impl DevPrm {
    /// A planner with validated parameters.
    pub fn new(params: DevPrmParams) -> Result<Self, PlanError> {
        params.validate()?;
        Ok(DevPrm { params })
    }

    /// The parameters.
    pub fn params(&self) -> &DevPrmParams {
        &self.params
    }
}

impl PathFrontend for DevPrm {
    fn name(&self) -> &str {
        "dev-prm"
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
        assert!(DevPrmParams::default().validate().is_ok());
        let e = DevPrmParams {
            surface_offset: 0.1,
            ..DevPrmParams::default()
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(e.contains("devprm.surface_offset"), "{e}");
        assert!(
            DevPrm::new(DevPrmParams {
                beam_width: 0,
                ..DevPrmParams::default()
            })
            .is_err()
        );
        // Switched-off enhancements do not need their parameters.
        assert!(
            DevPrmParams {
                obstacle_aware_samples: false,
                slices: 0,
                ..DevPrmParams::default()
            }
            .validate()
            .is_ok()
        );
    }

    #[test]
    fn params_deserialize_strictly() {
        let p: DevPrmParams = serde_json::from_str(r#"{"beam_width": 4, "pdc": false}"#).unwrap();
        assert_eq!(p.beam_width, 4);
        assert!(!p.pdc);
        assert!(serde_json::from_str::<DevPrmParams>(r#"{"beam": 4}"#).is_err());
    }
}

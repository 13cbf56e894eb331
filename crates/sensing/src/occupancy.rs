//! Log-odds occupancy: the per-voxel update and its parameters.

use serde::{Deserialize, Serialize};

use crate::error::{SensingError, check_range};

/// What is known about a voxel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VoxelState {
    /// Never observed, or outside the map's window.
    Unknown,
    /// Observed, occupancy probability at or below the threshold.
    Free,
    /// Observed, occupancy probability above the threshold.
    Occupied,
}

/// The log-odds sensor model of an occupancy voxel (Hornung et al., "OctoMap: an efficient
/// probabilistic 3D mapping framework based on octrees", Autonomous Robots 34(3), 2013, Sec. 3.1
/// and 4.1). Defaults: OctoMap's (`OccupancyOcTreeBase`: hit 0.7, miss 0.4, clamping 0.1192 and
/// 0.971, threshold 0.5), in log-odds `ln(p / (1 − p))`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LogOddsParams {
    /// Added when a ray ends in the voxel (OctoMap: `logit(0.7)` = 0.847), `> 0`.
    pub hit: f64,
    /// Added when a ray passes the voxel (OctoMap: `logit(0.4)` = −0.405), `< 0`.
    pub miss: f64,
    /// Lower clamp (OctoMap: `logit(0.1192)` = −1.992), `<= miss`.
    pub clamp_min: f64,
    /// Upper clamp (OctoMap: `logit(0.971)` = 3.511), `>= hit`.
    pub clamp_max: f64,
    /// A voxel is occupied above this (OctoMap: `logit(0.5)` = 0), in `(clamp_min, clamp_max)`.
    pub occupied_above: f64,
}

/// `ln(p / (1 − p))`.
pub fn logit(p: f64) -> f64 {
    (p / (1.0 - p)).ln()
}

impl Default for LogOddsParams {
    fn default() -> Self {
        Self {
            hit: logit(0.7),
            miss: logit(0.4),
            clamp_min: logit(0.1192),
            clamp_max: logit(0.971),
            occupied_above: 0.0,
        }
    }
}

impl LogOddsParams {
    /// Checks every field (named `map.log_odds.<field>` in the error).
    pub fn validate(&self) -> Result<(), SensingError> {
        check_range("map.log_odds.hit", self.hit, 0.0, 20.0, true, "in (0, 20]")?;
        check_range(
            "map.log_odds.miss",
            self.miss,
            -20.0,
            0.0,
            false,
            "in [-20, 0)",
        )?;
        if self.miss >= 0.0 {
            return Err(SensingError::OutOfRange {
                field: "map.log_odds.miss".into(),
                value: self.miss,
                expected: "in [-20, 0)",
            });
        }
        check_range(
            "map.log_odds.clamp_min",
            self.clamp_min,
            -40.0,
            self.miss,
            false,
            "in [-40, miss]",
        )?;
        check_range(
            "map.log_odds.clamp_max",
            self.clamp_max,
            self.hit,
            40.0,
            false,
            "in [hit, 40]",
        )?;
        check_range(
            "map.log_odds.occupied_above",
            self.occupied_above,
            self.clamp_min,
            self.clamp_max,
            true,
            "in (clamp_min, clamp_max]",
        )?;
        if self.occupied_above >= self.clamp_max {
            return Err(SensingError::OutOfRange {
                field: "map.log_odds.occupied_above".into(),
                value: self.occupied_above,
                expected: "in (clamp_min, clamp_max)",
            });
        }
        Ok(())
    }

    /// The log-odds after one observation (`hit` or a miss), clamped (OctoMap's update rule,
    /// eq. 3 of Hornung et al. with clamping, Sec. 4.1).
    pub fn update(&self, log_odds: f64, hit: bool) -> f64 {
        let step = if hit { self.hit } else { self.miss };
        (log_odds + step).clamp(self.clamp_min, self.clamp_max)
    }

    /// Whether a value counts as occupied.
    pub fn is_occupied(&self, log_odds: f64) -> bool {
        log_odds > self.occupied_above
    }
}

//! Weights and shape parameters of the cost terms (paper eq. design-of-J).

use serde::{Deserialize, Serialize};
use trust_core::{PlanError, Vec3, check_finite_vec, check_non_negative, check_positive};

/// The weight vector `λ` of paper eq. design-of-J: `J = λ · [H_t, H_s, I_o, I_d, I_e]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CostWeights {
    /// `λ_t`, weight of the flight duration `H_t = T_Σ`.
    pub time: f64,
    /// `λ_s`, weight of the heuristic terminal cost `H_s` (UTF-MINCO only; MINCO's terminal is
    /// fixed so `H_s` is a constant there).
    pub terminal: f64,
    /// `λ_o`, weight of the obstacle penalty `I_o` (moving obstacles and static map).
    pub obstacle: f64,
    /// `λ_d`, weight of the feasibility penalty `I_d` (speed and acceleration).
    pub feasibility: f64,
    /// `λ_e`, weight of the jerk energy `I_e`.
    pub energy: f64,
}

impl Default for CostWeights {
    /// - `time = 20`, `obstacle = feasibility = 1e4`, `energy = 1`: GCOPTER's defaults (time weight
    ///   20, penalty weights 1e4, unit energy weight).
    /// - `terminal = 50`: ours (the paper gives no value). Ending 1 m short of the goal saves about
    ///   `1 m / v` of flight, worth `λ_t / v ≈ 2–3` at the paper's speeds; `λ_s` must exceed that
    ///   by a margin for the free terminal to reach a reachable goal, and stay far below the
    ///   obstacle slope (`λ_o · 2r · T_i/κ ≈ 10³` per metre of penetration at one sample) so that
    ///   a blocked goal does not drag the terminal into an obstacle.
    fn default() -> Self {
        Self {
            time: 20.0,
            terminal: 50.0,
            obstacle: 1e4,
            feasibility: 1e4,
            energy: 1.0,
        }
    }
}

impl CostWeights {
    /// Every weight finite and `≥ 0`; the error names `{prefix}.{field}`.
    pub fn validate(&self, prefix: &str) -> Result<(), PlanError> {
        check_non_negative(&format!("{prefix}.time"), self.time)?;
        check_non_negative(&format!("{prefix}.terminal"), self.terminal)?;
        check_non_negative(&format!("{prefix}.obstacle"), self.obstacle)?;
        check_non_negative(&format!("{prefix}.feasibility"), self.feasibility)?;
        check_non_negative(&format!("{prefix}.energy"), self.energy)?;
        Ok(())
    }

    /// The weighted objective `λ · [ht, hs, io, id, ie]`.
    pub fn combine(&self, ht: f64, hs: f64, io: f64, id: f64, ie: f64) -> f64 {
        self.time * ht
            + self.terminal * hs
            + self.obstacle * io
            + self.feasibility * id
            + self.energy * ie
    }
}

/// Shapes of the cost terms: integration, smoothing, clearances and the terminal cost.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PenaltyParams {
    /// `κ`, trapezoidal intervals per piece (`κ + 1` samples; paper eq. trapezoidal-integration).
    pub samples_per_piece: usize,
    /// `μ`, width of the C² smoothed max (eq. design-of-Io's `f_max`).
    pub smoothing: f64,
    /// Extra clearance (m) kept from every moving obstacle beyond its forecast radius
    /// `r_o + r_safe + μ_o (t − t0)` (which already holds the paper's `r_safe`).
    pub dynamic_clearance_m: f64,
    /// Clearance (m) kept from the static map.
    pub static_clearance_m: f64,
    /// `d_ε` (m): within this distance of the goal the terminal-velocity weight `α` of eq.
    /// design-of-Hs rises linearly from 0 (at `d_ε`) to 1 (on the goal).
    pub goal_radius_m: f64,
    /// Diagonal of `K_f^p`, the terminal position weights of eq. design-of-Hs.
    pub terminal_position_gains: Vec3,
    /// Diagonal of `K_f^ṗ`, the terminal velocity weights of eq. design-of-Hs.
    pub terminal_velocity_gains: Vec3,
    /// `ε` of the smoothed norm `√(xᵀKx + ε²) − ε` that replaces `‖x‖_K` in `H_s` (the plain
    /// norm is not differentiable at 0, where L-BFGS would stall on the goal).
    pub terminal_norm_epsilon: f64,
    /// Width (m) of the smoothed max that measures how far the free terminal lies outside the
    /// goal guidance surface when the request has a planning horizon
    /// ([`crate::costs::TerminalCost::eval_objective`]).
    pub guidance_smoothing_m: f64,
    /// Samples of the obstacle penalty along the straight braking manoeuvre that
    /// follows a free terminal reached in motion (UTF-MINCO only; 0 switches it off): the
    /// manager's safety check requires that manoeuvre to be clear
    /// (`trust_manager::SafetyParams::braking_tail`), and an optimizer that does not see it
    /// ends trajectories at speed just in front of obstacles. Ours: 8 (see
    /// [`crate::costs::PenaltyIntegrand::braking_tail`]).
    pub braking_tail_samples: usize,
    /// The braking tail's model: the vehicle keeps its terminal velocity for
    /// `braking_tail_delay_s`, then decelerates at `braking_tail_decel_fraction · a_max` to rest.
    /// Defaults 0.9 and 0.1 s: the manager's braking manoeuvre
    /// (`trust_manager::brake_straight`) aims for 0.9 `a_max` and ramps the deceleration in over
    /// 0.2 s, which loses the distance of 0.1 s at full deceleration; it stops after 0.34 / 1.42 /
    /// 4.70 m from 2 / 5 / 10 m/s, this model after 0.35 / 1.43 / 4.70 m (the manager's test
    /// `the_backends_braking_tail_model_matches_the_braking_manoeuvre` keeps them together). With
    /// a straight stop at `a_max` (3.33 m from 10 m/s) the check found the tail of E3's and E4's
    /// candidates blocked 1.4 m beyond what the penalty had cleared.
    pub braking_tail_decel_fraction: f64,
    /// See [`PenaltyParams::braking_tail_decel_fraction`].
    pub braking_tail_delay_s: f64,
}

impl Default for PenaltyParams {
    /// - `samples_per_piece = 16`, `smoothing = 1e-2`: GCOPTER's defaults (`κ = 16`, `μ = 1e−2`).
    /// - `dynamic_clearance_m = static_clearance_m = 0.1`: ours. The penalty admits violations of
    ///   the order of `μ` at the optimum and is only evaluated at the samples; 0.1 m covers both at
    ///   the paper's speeds (sample spacing ≤ 0.3 m at 10 m/s with pieces of ≤ 0.5 s).
    /// - `goal_radius_m = 10`: ours (the paper names `d_ε` without a value): three braking
    ///   distances `v²/(2a) = 3.3 m` at the paper's limits (10 m/s, 15 m/s²).
    /// - `K_p = K_ṗ = I`: the paper gives no values; the weight `λ_s` scales both.
    /// - `terminal_norm_epsilon = 1e-2`: ours (1 cm / 1 cm/s of smoothing).
    /// - `guidance_smoothing_m = 1`: ours. The terminal settles where the surface term's slope
    ///   balances the time cost, a few centimetres outside the surface at the default weights; a
    ///   width of the order of the piece spacing keeps the term's curvature moderate for L-BFGS.
    fn default() -> Self {
        Self {
            samples_per_piece: 16,
            smoothing: 1e-2,
            dynamic_clearance_m: 0.1,
            static_clearance_m: 0.1,
            goal_radius_m: 10.0,
            terminal_position_gains: Vec3::new(1.0, 1.0, 1.0),
            terminal_velocity_gains: Vec3::new(1.0, 1.0, 1.0),
            terminal_norm_epsilon: 1e-2,
            guidance_smoothing_m: 1.0,
            braking_tail_samples: 8,
            braking_tail_decel_fraction: 0.9,
            braking_tail_delay_s: 0.1,
        }
    }
}

impl PenaltyParams {
    /// Checks every field; the error names `{prefix}.{field}`.
    pub fn validate(&self, prefix: &str) -> Result<(), PlanError> {
        if self.samples_per_piece == 0 || self.samples_per_piece > 1024 {
            return Err(PlanError::invalid(
                format!("{prefix}.samples_per_piece"),
                self.samples_per_piece,
                "an integer in [1, 1024] (node tables are allocated per piece)",
            ));
        }
        check_positive(&format!("{prefix}.smoothing"), self.smoothing)?;
        check_non_negative(
            &format!("{prefix}.dynamic_clearance_m"),
            self.dynamic_clearance_m,
        )?;
        check_non_negative(
            &format!("{prefix}.static_clearance_m"),
            self.static_clearance_m,
        )?;
        check_positive(&format!("{prefix}.goal_radius_m"), self.goal_radius_m)?;
        check_gains(
            &format!("{prefix}.terminal_position_gains"),
            &self.terminal_position_gains,
        )?;
        check_gains(
            &format!("{prefix}.terminal_velocity_gains"),
            &self.terminal_velocity_gains,
        )?;
        check_positive(
            &format!("{prefix}.terminal_norm_epsilon"),
            self.terminal_norm_epsilon,
        )?;
        check_positive(
            &format!("{prefix}.guidance_smoothing_m"),
            self.guidance_smoothing_m,
        )?;
        let fraction = self.braking_tail_decel_fraction;
        if !(fraction > 0.0 && fraction <= 1.0) {
            return Err(PlanError::invalid(
                format!("{prefix}.braking_tail_decel_fraction"),
                fraction,
                "a fraction of a_max in (0, 1]",
            ));
        }
        check_non_negative(
            &format!("{prefix}.braking_tail_delay_s"),
            self.braking_tail_delay_s,
        )?;
        Ok(())
    }
}

fn check_gains(field: &str, gains: &Vec3) -> Result<(), PlanError> {
    check_finite_vec(field, gains)?;
    if gains.iter().any(|g| *g < 0.0) {
        return Err(PlanError::invalid(
            field,
            [gains.x, gains.y, gains.z],
            "gains >= 0",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_serde_is_strict() {
        CostWeights::default().validate("w").unwrap();
        PenaltyParams::default().validate("p").unwrap();
        let p: PenaltyParams = serde_json::from_str(r#"{"samples_per_piece": 8}"#).unwrap();
        assert_eq!(p.samples_per_piece, 8);
        assert_eq!(p.smoothing, 1e-2);
        assert!(serde_json::from_str::<PenaltyParams>(r#"{"kappa": 8}"#).is_err());
        assert!(serde_json::from_str::<CostWeights>(r#"{"lambda": 8}"#).is_err());
    }

    #[test]
    fn errors_name_the_field() {
        let w = CostWeights {
            obstacle: -1.0,
            ..CostWeights::default()
        };
        let e = w.validate("params.weights").unwrap_err().to_string();
        assert!(
            e.contains("params.weights.obstacle") && e.contains("-1"),
            "{e}"
        );
        let p = PenaltyParams {
            samples_per_piece: 0,
            ..PenaltyParams::default()
        };
        assert!(
            p.validate("x")
                .unwrap_err()
                .to_string()
                .contains("x.samples_per_piece")
        );
        let p = PenaltyParams {
            terminal_velocity_gains: Vec3::new(1.0, -1.0, 0.0),
            ..PenaltyParams::default()
        };
        assert!(
            p.validate("x")
                .unwrap_err()
                .to_string()
                .contains("x.terminal_velocity_gains")
        );
    }
}

//! Weights and shape parameters of the cost terms (paper eq. design-of-J).

use serde::{Deserialize, Serialize};
use trust_core::scale::{MAX_LENGTH_M, MIN_POSITIVE, Quantity};
use trust_core::{PlanError, Vec3, check_range, check_scaled};

/// Largest accepted weight `λ` and terminal gain. The penalty weights' defaults are 1e4
/// (GCOPTER); up to 1e6 every term of `J` stays finite and L-BFGS's relative tests stay
/// meaningful on every accepted scene (probed on the E2 scenes: 1e8 and above still solve but
/// `λ_t = 1e8` already squashes the trajectory to 0.16 s through the obstacles).
pub const MAX_WEIGHT: f64 = 1.0e6;

/// Largest accepted smoothing width `μ` of the penalties' smoothed max (m for the obstacle
/// terms, a fraction of the squared limit for the feasibility term). The smoothed max grows like
/// `x³/μ²` below `μ`: at `μ = 10` the E2 solves already ignored the obstacles (a 5.4 s
/// trajectory straight through them with `I_o ≈ 1e-4`), so widths above 1 are rejected.
pub const MAX_SMOOTHING: f64 = 1.0;

/// Accepted range of the terminal norm's `ε` (m and m/s): below 1e-6 its square loses the
/// difference that keeps the smoothed norm's gradient finite at the goal (probed: `1e-300`
/// gave a NaN gradient at the start point), above [`MAX_LENGTH_M`] the norm overflows.
pub const TERMINAL_NORM_EPSILON_RANGE: (f64, f64) = (1.0e-6, MAX_LENGTH_M);

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

/// Smallest time weight `λ_t` a backend accepts ([`crate::backend::UtfMincoParams::validate`];
/// the objectives alone accept 0): with `λ_t = 0` nothing bounds the durations (the jerk energy
/// alone falls like `1/T⁵`), and a solve with `λ_e = 1e20` ended with a 7e7 s piece, outside the
/// scale policy. With `λ_t ≥ 1e-6` and `λ_e ≤ 1e6` the optimal duration of a 1e6 m path stays
/// near `(5·λ_e·L²/λ_t)^(1/6) ≈ 1e4` s.
pub const MIN_TIME_WEIGHT: f64 = 1.0e-6;

impl CostWeights {
    /// Every weight in `[0, 1e6]` ([`MAX_WEIGHT`]); the error names `{prefix}.{field}`. (A
    /// backend also needs `time ≥ 1e-6`, [`MIN_TIME_WEIGHT`].)
    pub fn validate(&self, prefix: &str) -> Result<(), PlanError> {
        for (name, w) in [
            ("time", self.time),
            ("terminal", self.terminal),
            ("obstacle", self.obstacle),
            ("feasibility", self.feasibility),
            ("energy", self.energy),
        ] {
            check_range(&format!("{prefix}.{name}"), w, 0.0, MAX_WEIGHT, "")?;
        }
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
    /// Settling distance `d_s` (m) of the final approach: near the goal (weighted by `α`) the
    /// terminal pull is raised so that the free terminal settles within `d_s` of the goal, and
    /// a vehicle at rest farther than `d_s` from it moves onto it, instead of stopping where
    /// the time of the last rest-to-rest move outweighs the pull
    /// ([`crate::costs::final_approach_gain`]; UTF-MINCO only). Ours, beyond the paper: 0.02 m,
    /// under half the manager's 0.05 m "reaches the goal" threshold
    /// (`trust_manager::ManagerParams::goal_reached_m`) and far below every goal tolerance, at
    /// any scale — the gain it implies scales with the limits (with `λ_t = λ_s` and the
    /// presets' jerk limit `a_max/0.3 s`: 14.9 at E4's planning 13.5 m/s², 25.5 at 2.7 m/s²;
    /// without a jerk limit 4.6 and 10.3). Accepted: `[1e-6, 1e6]` m.
    pub goal_settle_m: f64,
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
    /// Jerk limit as a ramp time (s): the feasibility penalty `I_d` also penalizes jerk above
    /// `a_max / jerk_ramp_s` ([`PenaltyParams::jerk_limit`]); 0 (the default, the paper's
    /// `I_d`) switches it off. Beyond the paper: a quadrotor's attitude lags a reference whose
    /// acceleration swings faster than that, and its true acceleration overshoots the plan's
    /// (`trust_planner::closed_loop_backend` sets 0.3 s).
    pub jerk_ramp_s: f64,
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
            goal_settle_m: 0.02,
            terminal_position_gains: Vec3::new(1.0, 1.0, 1.0),
            terminal_velocity_gains: Vec3::new(1.0, 1.0, 1.0),
            terminal_norm_epsilon: 1e-2,
            guidance_smoothing_m: 1.0,
            braking_tail_samples: 8,
            braking_tail_decel_fraction: 0.9,
            braking_tail_delay_s: 0.1,
            jerk_ramp_s: 0.0,
        }
    }
}

impl PenaltyParams {
    /// The jerk limit (m/s³) for `a_max`: `a_max / jerk_ramp_s`, or `None` when
    /// `jerk_ramp_s` is 0.
    pub fn jerk_limit(&self, a_max: f64) -> Option<f64> {
        (self.jerk_ramp_s > 0.0).then(|| a_max / self.jerk_ramp_s)
    }

    /// Checks every field; the error names `{prefix}.{field}`. Accepted ranges (derived from the
    /// scale policy, [`trust_core::scale`], and probed on the E2 scenes):
    ///
    /// | field | accepted |
    /// |---|---|
    /// | `samples_per_piece`, `braking_tail_samples` | `[1, 1024]`, `[0, 1024]` |
    /// | `smoothing` | `[1e-9, 1]` ([`MAX_SMOOTHING`]) |
    /// | `dynamic_clearance_m`, `static_clearance_m` | `[0, 1e6]` m (a length) |
    /// | `goal_radius_m`, `guidance_smoothing_m` | `[1e-9, 1e6]` m (a positive length) |
    /// | `goal_settle_m` | `[1e-6, 1e6]` m |
    /// | `terminal_position_gains`, `terminal_velocity_gains` | each component `[0, 1e6]` |
    /// | `terminal_norm_epsilon` | `[1e-6, 1e6]` ([`TERMINAL_NORM_EPSILON_RANGE`]) |
    /// | `braking_tail_decel_fraction` | `(0, 1]` |
    /// | `braking_tail_delay_s`, `jerk_ramp_s` | `[0, 1e7]` s (a duration) |
    pub fn validate(&self, prefix: &str) -> Result<(), PlanError> {
        let field = |name: &str| format!("{prefix}.{name}");
        check_count(
            &field("samples_per_piece"),
            self.samples_per_piece,
            1,
            MAX_SAMPLES_PER_PIECE,
        )?;
        check_range(
            &field("smoothing"),
            self.smoothing,
            MIN_POSITIVE,
            MAX_SMOOTHING,
            "",
        )?;
        check_scaled(
            &field("dynamic_clearance_m"),
            self.dynamic_clearance_m,
            Quantity::Length,
        )?;
        check_scaled(
            &field("static_clearance_m"),
            self.static_clearance_m,
            Quantity::Length,
        )?;
        check_scaled(
            &field("goal_radius_m"),
            self.goal_radius_m,
            Quantity::PositiveLength,
        )?;
        check_range(&field("goal_settle_m"), self.goal_settle_m, 1e-6, 1e6, "m")?;
        check_gains(
            &field("terminal_position_gains"),
            &self.terminal_position_gains,
        )?;
        check_gains(
            &field("terminal_velocity_gains"),
            &self.terminal_velocity_gains,
        )?;
        let (lo, hi) = TERMINAL_NORM_EPSILON_RANGE;
        check_range(
            &field("terminal_norm_epsilon"),
            self.terminal_norm_epsilon,
            lo,
            hi,
            "m",
        )?;
        check_scaled(
            &field("guidance_smoothing_m"),
            self.guidance_smoothing_m,
            Quantity::PositiveLength,
        )?;
        check_count(
            &field("braking_tail_samples"),
            self.braking_tail_samples,
            0,
            MAX_SAMPLES_PER_PIECE,
        )?;
        let fraction = self.braking_tail_decel_fraction;
        if !(fraction > 0.0 && fraction <= 1.0) {
            return Err(PlanError::invalid(
                field("braking_tail_decel_fraction"),
                fraction,
                "a fraction of a_max in (0, 1]",
            ));
        }
        check_scaled(
            &field("braking_tail_delay_s"),
            self.braking_tail_delay_s,
            Quantity::Duration,
        )?;
        check_scaled(&field("jerk_ramp_s"), self.jerk_ramp_s, Quantity::Duration)?;
        Ok(())
    }
}

/// Most samples per piece (`samples_per_piece`, `braking_tail_samples`): node tables are
/// allocated per piece.
pub const MAX_SAMPLES_PER_PIECE: usize = 1024;

fn check_count(field: &str, n: usize, lo: usize, hi: usize) -> Result<(), PlanError> {
    if (lo..=hi).contains(&n) {
        Ok(())
    } else {
        Err(PlanError::invalid(
            field,
            n,
            format!("an integer in [{lo}, {hi}]"),
        ))
    }
}

fn check_gains(field: &str, gains: &Vec3) -> Result<(), PlanError> {
    for (axis, g) in ['x', 'y', 'z'].into_iter().zip(gains.iter()) {
        check_range(&format!("{field}.{axis}"), *g, 0.0, MAX_WEIGHT, "")?;
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

    #[test]
    fn extreme_values_are_rejected_with_the_field_and_a_readable_number() {
        // Issue 18: these were accepted and then broke the solve with an error about something
        // else ("cost at the start point = inf", "g[0] = NaN") or silently turned the
        // obstacle penalty off (`smoothing = 1e300`).
        type Edit = fn(&mut PenaltyParams);
        let cases: [(&str, Edit); 6] = [
            ("p.smoothing", |p| p.smoothing = 1e300),
            ("p.terminal_norm_epsilon", |p| {
                p.terminal_norm_epsilon = 1e-300
            }),
            ("p.terminal_norm_epsilon", |p| {
                p.terminal_norm_epsilon = 1e300
            }),
            ("p.dynamic_clearance_m", |p| p.dynamic_clearance_m = 1e300),
            ("p.terminal_position_gains.y", |p| {
                p.terminal_position_gains.y = f64::MAX
            }),
            ("p.braking_tail_samples", |p| {
                p.braking_tail_samples = usize::MAX
            }),
        ];
        for (field, edit) in cases {
            let mut p = PenaltyParams::default();
            edit(&mut p);
            let e = p.validate("p").unwrap_err().to_string();
            assert!(e.contains(field), "{field}: {e}");
            assert!(e.len() < 200, "{e}");
        }
        let w = CostWeights {
            time: 1e300,
            ..CostWeights::default()
        };
        let e = w.validate("w").unwrap_err().to_string();
        assert!(e.contains("w.time") && e.contains("1.0e300"), "{e}");
    }
}

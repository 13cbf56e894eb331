//! Parameters of the two backends.

use serde::{Deserialize, Serialize};
use trust_core::scale::{MAX_TIME_S, MIN_POSITIVE, Quantity};
use trust_core::{PlanError, check_range, check_scaled};
use trust_lbfgs::LbfgsParams;

use crate::costs::{CostWeights, MAX_WEIGHT, MIN_TIME_WEIGHT, PenaltyParams};

/// How many pieces a trajectory gets and how short a piece may become.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PieceParams {
    /// Target length of one piece along the initial guess (m); the piece count is
    /// `ceil(length / target)` clamped to `[min_pieces, max_pieces]`.
    pub target_piece_length_m: f64,
    /// Fewest pieces (≥ 1).
    pub min_pieces: usize,
    /// Most pieces (≥ `min_pieces`).
    pub max_pieces: usize,
    /// Lower bound of every piece duration (s): durations are `T_min + T(τ)` with the positive
    /// map [`crate::backend::positive_time`]. Accepted: `[1e-9, 10]` s
    /// ([`MAX_MIN_PIECE_DURATION_S`]).
    pub min_piece_duration_s: f64,
}

impl Default for PieceParams {
    /// Ours (the paper gives no values):
    /// - `target_piece_length_m = 7`: the E2 path (about 50 m) gets 7–8 pieces of about 0.7 s at
    ///   10 m/s. Measured (release, 60 random E2-like scenes of each kind plus the two E2 scenes,
    ///   `examples/e2_compare.rs` limits): against 3 m (16–18 pieces), 7 m needs about half the
    ///   evaluations to converge (static 407 vs 936 on average, dynamic 561 vs 993 with the
    ///   1000-evaluation cap), each evaluation costs about half as much, and the optimizer finds
    ///   better local minima among moving obstacles (mean `J` 165 vs 216, mean duration 7.5 vs
    ///   7.8 s; on E2 dynamic 7.7 s to the goal instead of 8.3 s stopping 4 m short). 6 m and 8 m
    ///   give the same quality; 12 m starts to cut corners between samples;
    /// - `min_pieces = 2`, `max_pieces = 32`: at least one free waypoint; the cost stays linear in
    ///   the number of pieces;
    /// - `min_piece_duration_s = 0.02`: keeps MINCO's `T⁵` pivot above 3e-9 and gives a hover
    ///   (start on the goal) a non-degenerate duration when `H_t` pushes every duration down.
    fn default() -> Self {
        Self {
            target_piece_length_m: 7.0,
            min_pieces: 2,
            max_pieces: 32,
            min_piece_duration_s: 0.02,
        }
    }
}

/// Largest accepted [`PieceParams::min_piece_duration_s`] (s): with at most
/// [`crate::minco::MAX_PIECES`] = 1e5 pieces the floors add up to at most a tenth of the scale
/// policy's longest duration (`MAX_TIME_S` = 1e7 s), so the trajectory's length is driven by
/// the path and the limits, not by the floor. (Before issue 18 a floor of 1e6 s was accepted
/// and the solve then failed with an error blaming `limits.v_max`.)
pub const MAX_MIN_PIECE_DURATION_S: f64 = MAX_TIME_S / 10.0 / crate::minco::MAX_PIECES as f64;

impl PieceParams {
    /// Checks every field; errors name `{prefix}.{field}`. Accepted: `target_piece_length_m` a
    /// positive length (`[1e-9, 1e6]` m), `1 ≤ min_pieces ≤ max_pieces ≤ MAX_PIECES`,
    /// `min_piece_duration_s` in `[1e-9, 10]` s.
    pub fn validate(&self, prefix: &str) -> Result<(), PlanError> {
        check_scaled(
            &format!("{prefix}.target_piece_length_m"),
            self.target_piece_length_m,
            Quantity::PositiveLength,
        )?;
        if self.min_pieces == 0 {
            return Err(PlanError::invalid(
                format!("{prefix}.min_pieces"),
                self.min_pieces,
                "an integer >= 1",
            ));
        }
        if self.max_pieces > crate::minco::MAX_PIECES {
            return Err(PlanError::invalid(
                format!("{prefix}.max_pieces"),
                self.max_pieces,
                format!(
                    "an integer <= {} (minco::MAX_PIECES)",
                    crate::minco::MAX_PIECES
                ),
            ));
        }
        if self.max_pieces < self.min_pieces {
            return Err(PlanError::invalid(
                format!("{prefix}.max_pieces"),
                self.max_pieces,
                format!(
                    "an integer >= {prefix}.min_pieces ({}); lower {prefix}.min_pieces or raise \
                     {prefix}.max_pieces",
                    self.min_pieces
                ),
            ));
        }
        check_range(
            &format!("{prefix}.min_piece_duration_s"),
            self.min_piece_duration_s,
            MIN_POSITIVE,
            MAX_MIN_PIECE_DURATION_S,
            "s",
        )?;
        Ok(())
    }

    /// The piece count for a path of `length` metres: `ceil(length / target)` clamped to
    /// `[min_pieces, max_pieces]` (`min_pieces` for a zero or non-finite length).
    pub fn piece_count(&self, length: f64) -> usize {
        let raw = if length.is_finite() && length > 0.0 {
            (length / self.target_piece_length_m)
                .ceil()
                .min(self.max_pieces as f64) as usize
        } else {
            0
        };
        raw.clamp(self.min_pieces, self.max_pieces).max(1)
    }
}

/// Budget and settings of the L-BFGS solve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverParams {
    /// Most cost evaluations per solve (0: only `lbfgs.max_evaluations` limits). The
    /// smaller non-zero of the two applies.
    pub max_evaluations: usize,
    /// The L-BFGS settings.
    pub lbfgs: LbfgsParams,
}

impl Default for SolverParams {
    /// - `max_evaluations = 1000`: ours, a hard cap (about 3 ms at the E2 problem size on this
    ///   machine); converged solves stop well before it (E2: 356 dynamic, 722 static; random
    ///   E2-like scenes: about 400–560 on average).
    /// - `lbfgs`: LBFGS-Lite's defaults (`g_epsilon = 1e-5`, `past = 3`, …; see [`LbfgsParams`])
    ///   except:
    ///   - `memory = 32` (LBFGS-Lite: 8; GCOPTER's own setting: 256). Measured to full convergence
    ///     on 30 random E2-like scenes of each kind (7 m pieces): the median number of
    ///     evaluations to come within 1 % of the final `J` is 465 / 872 (static / dynamic) with
    ///     memory 8, 366 / 580 with 16, 309 / 399 with 32 and 293 / 363 with 64; 32 is within
    ///     10 % of 64 at half the work per iteration.
    ///   - `delta = 1e-5` (LBFGS-Lite: 1e-6): on the same 30 + 30 scenes it saves 10–15 % of the
    ///     evaluations (static 412 vs 465, dynamic 531 vs 628 on average) for mean durations
    ///     within 0.4 % (7.065 vs 7.047 s, 7.302 vs 7.277 s) and a mean `J` within 0.3 %. Looser
    ///     tests stop on a plateau (the cost stalls for many iterations while the optimizer
    ///     slides the trajectory along an obstacle): `1e-4` (or `1e-3` with `past = 10`) ends the
    ///     dynamic solves about 6.5 % longer in duration, `1e-3` with `past = 3` 21 % longer.
    fn default() -> Self {
        Self {
            max_evaluations: 1000,
            lbfgs: LbfgsParams {
                memory: 32,
                delta: 1e-5,
                ..LbfgsParams::default()
            },
        }
    }
}

impl SolverParams {
    /// Checks the L-BFGS settings.
    pub fn validate(&self, prefix: &str) -> Result<(), PlanError> {
        self.lbfgs.validate().map_err(|e| PlanError::InvalidInput {
            field: format!("{prefix}.lbfgs"),
            value: e.to_string(),
            expected: "valid L-BFGS parameters".into(),
        })
    }

    /// These settings with the evaluation budget lowered to `cap` if that is smaller (a request's
    /// own budget, [`trust_core::TrajRequest::max_evaluations`]).
    pub fn capped(&self, cap: Option<usize>) -> SolverParams {
        let mut s = self.clone();
        if let Some(c) = cap {
            s.max_evaluations = match s.max_evaluations {
                0 => c,
                m => m.min(c),
            };
        }
        s
    }

    /// The L-BFGS parameters with the effective evaluation budget.
    pub fn effective_lbfgs(&self) -> LbfgsParams {
        let mut p = self.lbfgs.clone();
        p.max_evaluations = match (self.max_evaluations, p.max_evaluations) {
            (0, m) | (m, 0) => m,
            (a, b) => a.min(b),
        };
        p
    }
}

/// Parameters of [`crate::backend::UtfMinco`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct UtfMincoParams {
    /// `λ` of eq. design-of-J.
    pub weights: CostWeights,
    /// Shapes of the cost terms.
    pub penalty: PenaltyParams,
    /// Piece count and minimum duration.
    pub pieces: PieceParams,
    /// L-BFGS budget and settings.
    pub solver: SolverParams,
}

impl UtfMincoParams {
    /// Checks every field; errors name `{prefix}.{field}` (e.g. `params.weights.time`). The
    /// ranges are documented on [`CostWeights::validate`], [`PenaltyParams::validate`] and
    /// [`PieceParams::validate`]; a backend also needs `weights.time ≥ 1e-6`
    /// ([`crate::costs::MIN_TIME_WEIGHT`]).
    pub fn validate(&self, prefix: &str) -> Result<(), PlanError> {
        self.validate_objective(prefix)?;
        check_range(
            &format!("{prefix}.weights.time"),
            self.weights.time,
            MIN_TIME_WEIGHT,
            MAX_WEIGHT,
            "",
        )?;
        self.solver.validate(&format!("{prefix}.solver"))
    }

    /// The checks an objective needs (weights, penalty, pieces; `λ_t = 0` allowed).
    pub(crate) fn validate_objective(&self, prefix: &str) -> Result<(), PlanError> {
        self.weights.validate(&format!("{prefix}.weights"))?;
        self.penalty.validate(&format!("{prefix}.penalty"))?;
        self.pieces.validate(&format!("{prefix}.pieces"))
    }
}

/// Parameters of [`crate::backend::Minco`]. The same fields as [`UtfMincoParams`]; the terminal
/// weight `λ_s` only scales a constant there (the terminal is fixed).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct MincoParams {
    /// `λ` of eq. design-of-J.
    pub weights: CostWeights,
    /// Shapes of the cost terms.
    pub penalty: PenaltyParams,
    /// Piece count and minimum duration.
    pub pieces: PieceParams,
    /// L-BFGS budget and settings.
    pub solver: SolverParams,
}

impl MincoParams {
    /// Checks every field; errors name `{prefix}.{field}` (e.g. `params.weights.time`). The
    /// ranges are documented on [`CostWeights::validate`], [`PenaltyParams::validate`] and
    /// [`PieceParams::validate`]; a backend also needs `weights.time ≥ 1e-6`
    /// ([`crate::costs::MIN_TIME_WEIGHT`]).
    pub fn validate(&self, prefix: &str) -> Result<(), PlanError> {
        self.validate_objective(prefix)?;
        check_range(
            &format!("{prefix}.weights.time"),
            self.weights.time,
            MIN_TIME_WEIGHT,
            MAX_WEIGHT,
            "",
        )?;
        self.solver.validate(&format!("{prefix}.solver"))
    }

    /// The checks an objective needs (weights, penalty, pieces; `λ_t = 0` allowed).
    pub(crate) fn validate_objective(&self, prefix: &str) -> Result<(), PlanError> {
        self.weights.validate(&format!("{prefix}.weights"))?;
        self.penalty.validate(&format!("{prefix}.penalty"))?;
        self.pieces.validate(&format!("{prefix}.pieces"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn piece_count_is_clamped() {
        let p = PieceParams::default();
        assert_eq!(p.piece_count(0.0), 2);
        assert_eq!(p.piece_count(f64::NAN), 2);
        assert_eq!(p.piece_count(50.0), 8);
        assert_eq!(p.piece_count(1e9), 32);
    }

    #[test]
    fn budget_takes_the_smaller_limit() {
        let mut s = SolverParams::default();
        assert_eq!(s.effective_lbfgs().max_evaluations, 1000);
        s.lbfgs.max_evaluations = 50;
        assert_eq!(s.effective_lbfgs().max_evaluations, 50);
        s.max_evaluations = 0;
        assert_eq!(s.effective_lbfgs().max_evaluations, 50);
    }

    #[test]
    fn a_request_cap_only_lowers_the_budget() {
        let s = SolverParams::default();
        assert_eq!(s.capped(None).max_evaluations, 1000);
        assert_eq!(s.capped(Some(50)).max_evaluations, 50);
        assert_eq!(s.capped(Some(5000)).max_evaluations, 1000);
        let unlimited = SolverParams {
            max_evaluations: 0,
            ..SolverParams::default()
        };
        assert_eq!(unlimited.capped(Some(70)).max_evaluations, 70);
    }

    #[test]
    fn validation_names_nested_fields() {
        let mut p = UtfMincoParams::default();
        p.validate("params").unwrap();
        p.pieces.max_pieces = 1;
        let e = p.validate("params").unwrap_err().to_string();
        assert!(e.contains("params.pieces.max_pieces"), "{e}");
        let mut p = MincoParams::default();
        p.solver.lbfgs.memory = 0;
        let e = p.validate("params").unwrap_err().to_string();
        assert!(
            e.contains("params.solver.lbfgs") && e.contains("memory"),
            "{e}"
        );
        let json = r#"{"weights": {"time": 5.0}, "pieces": {"max_pieces": 8}}"#;
        let p: UtfMincoParams = serde_json::from_str(json).unwrap();
        assert_eq!(p.weights.time, 5.0);
        assert_eq!(p.weights.obstacle, 1e4);
        assert_eq!(p.pieces.max_pieces, 8);
        assert!(serde_json::from_str::<UtfMincoParams>(r#"{"kappa": 3}"#).is_err());
    }
}

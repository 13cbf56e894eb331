//! Solver parameters and their validation.

use serde::{Deserialize, Serialize};

use crate::LbfgsError;

/// Parameters of the L-BFGS solver.
///
/// The defaults are those of LBFGS-Lite (Zhepei Wang, `lbfgs.hpp`, `lbfgs_parameter_t` and its
/// default initializer); `max_evaluations` is our addition (LBFGS-Lite has no evaluation budget) and defaults to
/// "unlimited" so that the defaults behave exactly as LBFGS-Lite's.
///
/// Call [`LbfgsParams::validate`] (done by [`crate::Lbfgs::new`]) to check the ranges.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LbfgsParams {
    /// Number of correction pairs (s, y) kept in memory (`mem_size`). Must be >= 1.
    /// Accepted: `[1, 1024]` ([`MAX_MEMORY`]); with the dimension, the workspace is capped by [`MAX_WORKSPACE_FLOATS`].
    pub memory: usize,
    /// Gradient tolerance: stop with [`crate::Termination::Converged`] when
    /// `‖g‖∞ / max(1, ‖x‖∞) <= g_epsilon`. Finite and >= 0; 0 stops only on an exactly zero gradient.
    pub g_epsilon: f64,
    /// Distance, in iterations, of the cost-decrease test (`past`); 0 disables that test.
    /// Accepted: `[0, 65536]` ([`MAX_PAST`]).
    pub past: usize,
    /// Cost-decrease tolerance: stop with [`crate::Termination::CostStalled`] when
    /// `|f_{k−past} − f_k| / max(1, |f_k|) <= delta`. Finite and >= 0.
    pub delta: f64,
    /// Maximum number of iterations (accepted steps); 0 means unlimited.
    /// Accepted: any.
    pub max_iterations: usize,
    /// Maximum number of cost evaluations, the one at the start point included; 0 means unlimited.
    /// Accepted: any.
    pub max_evaluations: usize,
    /// Maximum number of trial points in one line search. Must be >= 1.
    /// Accepted: `≥ 1`.
    pub max_linesearch: usize,
    /// Smallest step the line search may try. Finite and >= 0.
    pub min_step: f64,
    /// Largest step the line search may try. Finite and > `min_step`.
    pub max_step: f64,
    /// Armijo (sufficient decrease) coefficient c₁. In (0, `s_curv_coeff`).
    pub f_dec_coeff: f64,
    /// Weak-Wolfe curvature coefficient c₂. In (`f_dec_coeff`, 1).
    pub s_curv_coeff: f64,
    /// Cautious-update factor ε: a pair is stored only if `yᵀs > ε·‖s‖₂²·‖g_prev‖₂`
    /// (Li and Fukushima, 2001). Finite and >= 0.
    pub cautious_factor: f64,
}

impl Default for LbfgsParams {
    /// LBFGS-Lite's defaults (`lbfgs.hpp`, `lbfgs_parameter_t`):
    /// `mem_size = 8`, `g_epsilon = 1e-5`, `past = 3`, `delta = 1e-6`, `max_iterations = 0`,
    /// `max_linesearch = 64`, `min_step = 1e-20`, `max_step = 1e20`, `f_dec_coeff = 1e-4`,
    /// `s_curv_coeff = 0.9`, `cautious_factor = 1e-6`; plus our `max_evaluations = 0` (unlimited).
    fn default() -> Self {
        Self {
            memory: 8,
            g_epsilon: 1e-5,
            past: 3,
            delta: 1e-6,
            max_iterations: 0,
            max_evaluations: 0,
            max_linesearch: 64,
            min_step: 1e-20,
            max_step: 1e20,
            f_dec_coeff: 1e-4,
            s_curv_coeff: 0.9,
            cautious_factor: 1e-6,
        }
    }
}

/// Largest accepted [`LbfgsParams::memory`]: the correction pairs are allocated up front.
pub const MAX_MEMORY: usize = 1024;

/// Largest accepted [`LbfgsParams::past`]: the past costs are allocated up front.
pub const MAX_PAST: usize = 65_536;

/// Largest number of variables of one solver ([`crate::Lbfgs::new`]): 10⁶. The largest problem of
/// the planner, a MINCO trajectory with `trust_geometry::scale::MAX_VERTEX_COUNT` = 10⁵ pieces, has
/// `3·(10⁵ − 1) + 10⁵ ≈ 4·10⁵` variables; above the cap a request is a typed error, not a
/// "capacity overflow" panic or a multi-terabyte allocation.
pub const MAX_DIMENSION: usize = 1_000_000;

/// Largest workspace of one solver in floats, `(2·memory + 6)·dimension + 3·memory + past`:
/// 5·10⁷ floats (400 MB), enough for [`MAX_DIMENSION`] variables with the default 8 pairs
/// (2.2·10⁷ floats) and for 1024 pairs up to 24 000 variables.
pub const MAX_WORKSPACE_FLOATS: usize = 50_000_000;

impl LbfgsParams {
    /// Checks every field's range; the error names the first offending field and its value.
    pub fn validate(&self) -> Result<(), LbfgsError> {
        if self.memory == 0 || self.memory > MAX_MEMORY {
            return Err(invalid(
                "memory",
                self.memory as f64,
                "an integer in [1, 1024] (MAX_MEMORY)",
            ));
        }
        if self.past > MAX_PAST {
            return Err(invalid(
                "past",
                self.past as f64,
                "an integer in [0, 65536] (MAX_PAST)",
            ));
        }
        if self.max_linesearch == 0 {
            return Err(invalid("max_linesearch", 0.0, "an integer >= 1"));
        }
        check_non_negative("g_epsilon", self.g_epsilon)?;
        check_non_negative("delta", self.delta)?;
        check_non_negative("cautious_factor", self.cautious_factor)?;
        check_non_negative("min_step", self.min_step)?;
        if !(self.max_step.is_finite() && self.max_step > self.min_step) {
            return Err(invalid(
                "max_step",
                self.max_step,
                "a finite number > min_step",
            ));
        }
        if !(self.f_dec_coeff > 0.0 && self.f_dec_coeff < 1.0) {
            return Err(invalid(
                "f_dec_coeff",
                self.f_dec_coeff,
                "a number in (0, 1)",
            ));
        }
        if !(self.s_curv_coeff > self.f_dec_coeff && self.s_curv_coeff < 1.0) {
            return Err(invalid(
                "s_curv_coeff",
                self.s_curv_coeff,
                "a number in (f_dec_coeff, 1)",
            ));
        }
        Ok(())
    }
}

fn invalid(field: &'static str, value: f64, expected: &'static str) -> LbfgsError {
    LbfgsError::InvalidParam {
        field,
        value,
        expected,
    }
}

fn check_non_negative(field: &'static str, value: f64) -> Result<(), LbfgsError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(invalid(field, value, "a finite number >= 0"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field_of(params: &LbfgsParams) -> &'static str {
        match params.validate() {
            Err(LbfgsError::InvalidParam { field, .. }) => field,
            other => panic!("expected InvalidParam, got {other:?}"),
        }
    }

    #[test]
    fn defaults_are_valid() {
        assert_eq!(LbfgsParams::default().validate(), Ok(()));
    }

    #[test]
    fn each_bad_field_is_named() {
        let base = LbfgsParams::default();
        let cases: Vec<(LbfgsParams, &str)> = vec![
            (
                LbfgsParams {
                    memory: 0,
                    ..base.clone()
                },
                "memory",
            ),
            (
                LbfgsParams {
                    max_linesearch: 0,
                    ..base.clone()
                },
                "max_linesearch",
            ),
            (
                LbfgsParams {
                    g_epsilon: -1e-3,
                    ..base.clone()
                },
                "g_epsilon",
            ),
            (
                LbfgsParams {
                    g_epsilon: f64::NAN,
                    ..base.clone()
                },
                "g_epsilon",
            ),
            (
                LbfgsParams {
                    delta: f64::INFINITY,
                    ..base.clone()
                },
                "delta",
            ),
            (
                LbfgsParams {
                    cautious_factor: -1.0,
                    ..base.clone()
                },
                "cautious_factor",
            ),
            (
                LbfgsParams {
                    min_step: -1.0,
                    ..base.clone()
                },
                "min_step",
            ),
            (
                LbfgsParams {
                    min_step: 1.0,
                    max_step: 1.0,
                    ..base.clone()
                },
                "max_step",
            ),
            (
                LbfgsParams {
                    max_step: f64::INFINITY,
                    ..base.clone()
                },
                "max_step",
            ),
            (
                LbfgsParams {
                    f_dec_coeff: 0.0,
                    ..base.clone()
                },
                "f_dec_coeff",
            ),
            (
                LbfgsParams {
                    f_dec_coeff: f64::NAN,
                    ..base.clone()
                },
                "f_dec_coeff",
            ),
            (
                LbfgsParams {
                    f_dec_coeff: 0.95,
                    ..base.clone()
                },
                "s_curv_coeff",
            ),
            (
                LbfgsParams {
                    s_curv_coeff: 1.0,
                    ..base.clone()
                },
                "s_curv_coeff",
            ),
        ];
        for (params, field) in cases {
            assert_eq!(field_of(&params), field, "{params:?}");
        }
    }

    #[test]
    fn message_names_field_value_and_expectation() {
        let params = LbfgsParams {
            memory: 0,
            ..LbfgsParams::default()
        };
        let message = params.validate().unwrap_err().to_string();
        assert_eq!(
            message,
            "invalid LbfgsParams: memory = 0, expected an integer in [1, 1024] (MAX_MEMORY)"
        );
    }

    #[test]
    fn zero_tolerances_are_allowed() {
        let params = LbfgsParams {
            g_epsilon: 0.0,
            delta: 0.0,
            past: 0,
            min_step: 0.0,
            ..LbfgsParams::default()
        };
        assert_eq!(params.validate(), Ok(()));
    }

    #[test]
    fn serde_fills_defaults_and_rejects_unknown_fields() {
        let params: LbfgsParams = serde_json::from_str(r#"{"memory": 16}"#).unwrap();
        assert_eq!(
            params,
            LbfgsParams {
                memory: 16,
                ..LbfgsParams::default()
            }
        );
        let unknown = serde_json::from_str::<LbfgsParams>(r#"{"mem_size": 16}"#);
        assert!(
            unknown
                .unwrap_err()
                .to_string()
                .contains("unknown field `mem_size`")
        );
    }
}

//! JSON front door for cross-checking MINCO against other implementations (used by the
//! `minco_eval` example): one problem in, coefficients, energy and energy gradients out.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::error::MincoError;
use crate::minco::{MincoGrad, MincoS3};

/// One MINCO problem: `{"head": [p, v, a], "tail": [p, v, a], "waypoints": [[x, y, z], …],
/// "durations": [T_1, …, T_n]}` with `n − 1` waypoints.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EvalInput {
    /// Head `[position, velocity, acceleration]`.
    pub head: [[f64; 3]; 3],
    /// Tail `[position, velocity, acceleration]`.
    pub tail: [[f64; 3]; 3],
    /// Inner waypoints `q_1 ..= q_{n−1}`.
    pub waypoints: Vec<[f64; 3]>,
    /// Piece durations (s), one per piece.
    pub durations: Vec<f64>,
}

/// The answer to an [`EvalInput`]: coefficients and the jerk energy with its total gradients.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EvalOutput {
    /// Per piece, `[c0, …, c5]` (ascending powers), each `[x, y, z]`.
    pub coeffs: Vec<[[f64; 3]; 6]>,
    /// Jerk energy `Σ ∫ ‖jerk‖²` (no ½).
    pub energy: f64,
    /// `∂E/∂q_i` per inner waypoint.
    pub grad_waypoints: Vec<[f64; 3]>,
    /// Total `∂E/∂T_i` per piece.
    pub grad_durations: Vec<f64>,
    /// `∂E/∂(tail position, velocity, acceleration)`.
    pub grad_tail: [[f64; 3]; 3],
}

fn vec3(a: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

fn arr(v: &Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}

impl EvalInput {
    /// Solves the problem and computes the energy and its gradients.
    ///
    /// # Errors
    /// [`MincoError::NoPieces`] for empty `durations`, [`MincoError::TooManyPieces`] for more than
    /// [`crate::minco::MAX_PIECES`], otherwise as [`MincoS3::solve`] and
    /// [`MincoS3::energy_and_grad`].
    pub fn evaluate(&self) -> Result<EvalOutput, MincoError> {
        let n = self.durations.len();
        let mut minco = MincoS3::new(n)?;
        let head = [
            vec3(&self.head[0]),
            vec3(&self.head[1]),
            vec3(&self.head[2]),
        ];
        let tail = [
            vec3(&self.tail[0]),
            vec3(&self.tail[1]),
            vec3(&self.tail[2]),
        ];
        let waypoints: Vec<Vector3<f64>> = self.waypoints.iter().map(vec3).collect();
        minco.solve(&head, &tail, &waypoints, &self.durations)?;
        let mut grad = MincoGrad::new(n);
        let energy = minco.energy_and_grad(&mut grad)?;
        Ok(EvalOutput {
            coeffs: minco
                .coeffs()
                .chunks_exact(6)
                .map(|c| std::array::from_fn(|k| arr(&c[k])))
                .collect(),
            energy,
            grad_waypoints: grad.waypoints.iter().map(arr).collect(),
            grad_durations: grad.durations.clone(),
            grad_tail: [arr(&grad.tail[0]), arr(&grad.tail[1]), arr(&grad.tail[2])],
        })
    }
}

/// Parses one [`EvalInput`] JSON object, evaluates it and returns one [`EvalOutput`] JSON object
/// (single line). This is the whole logic of `examples/minco_eval.rs`.
///
/// # Errors
/// [`MincoError::Json`] for malformed JSON, unknown fields or wrong array lengths inside the
/// head/tail/waypoint triples; otherwise as [`EvalInput::evaluate`].
pub fn eval_json(input: &str) -> Result<String, MincoError> {
    let parsed: EvalInput = serde_json::from_str(input).map_err(|e| MincoError::Json {
        message: e.to_string(),
    })?;
    let output = parsed.evaluate()?;
    serde_json::to_string(&output).map_err(|e| MincoError::Json {
        message: e.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn malformed_json_is_a_json_error() {
        assert!(matches!(eval_json("{"), Err(MincoError::Json { .. })));
        assert!(matches!(
            eval_json(
                r#"{"head": [[0,0,0],[0,0,0]], "tail": [[1,0,0],[0,0,0],[0,0,0]], "waypoints": [], "durations": [1]}"#
            ),
            Err(MincoError::Json { .. })
        ));
        assert!(matches!(
            eval_json(
                r#"{"head": [[0,0,0],[0,0,0],[0,0,0]], "tail": [[1,0,0],[0,0,0],[0,0,0]], "waypoints": [], "durations": [1], "extra": 1}"#
            ),
            Err(MincoError::Json { .. })
        ));
    }

    #[test]
    fn semantic_errors_name_the_field() {
        let base = r#""head": [[0,0,0],[0,0,0],[0,0,0]], "tail": [[1,0,0],[0,0,0],[0,0,0]]"#;
        assert_eq!(
            eval_json(&format!(r#"{{{base}, "waypoints": [], "durations": []}}"#)),
            Err(MincoError::NoPieces { got: 0 })
        );
        assert_eq!(
            eval_json(&format!(
                r#"{{{base}, "waypoints": [[0,0,0]], "durations": [1]}}"#
            )),
            Err(MincoError::LengthMismatch {
                field: "waypoints",
                expected: 0,
                got: 1
            })
        );
        assert_eq!(
            eval_json(&format!(r#"{{{base}, "waypoints": [], "durations": [0]}}"#)),
            Err(MincoError::InvalidDuration {
                index: 0,
                value: 0.0
            })
        );
    }

    #[test]
    fn single_piece_round_trip() {
        let out = eval_json(
            r#"{"head": [[0,0,0],[0,0,0],[0,0,0]], "tail": [[1,0,0],[0,0,0],[0,0,0]], "waypoints": [], "durations": [1]}"#,
        )
        .unwrap();
        let parsed: EvalOutput = serde_json::from_str(&out).unwrap();
        assert_eq!(parsed.coeffs.len(), 1);
        assert!(parsed.grad_waypoints.is_empty());
        // Rest-to-rest unit move in unit time: p = 10t³ − 15t⁴ + 6t⁵, E = 720.
        assert!((parsed.coeffs[0][3][0] - 10.0).abs() < 1e-9);
        assert!((parsed.energy - 720.0).abs() < 1e-9);
    }
}

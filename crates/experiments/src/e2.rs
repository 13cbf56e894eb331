//! E2 (paper Table Sim-A-2): UTF-MINCO vs MINCO on the static and dynamic 50×20×10 m scenes.
//!
//! `cargo xtask experiment e2` runs the `trust-minco` example `e2_compare --repeats N`, which
//! prints one [`E2Results`] as JSON, parsed by [`parse`]; [`report`] writes `report.md`.

use serde::{Deserialize, Serialize};
use trust_core::CostBreakdown;

use crate::ExperimentError;

/// The example that prints [`E2Results`] (package `trust-minco`).
pub const EXAMPLE: &str = "e2_compare";

/// The output of `e2_compare --repeats N` (the example's JSON, field for field).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct E2Results {
    /// The dynamic scene.
    pub dynamic: E2Case,
    /// Repetitions per backend and case (the timings are their medians).
    pub repeats: usize,
    /// The static scene.
    #[serde(rename = "static")]
    pub static_scene: E2Case,
}

/// Both backends on one scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct E2Case {
    /// MINCO (the baseline).
    pub minco: E2Run,
    /// UTF-MINCO.
    #[serde(rename = "utf-minco")]
    pub utf_minco: E2Run,
}

/// One backend's cold solve from the guide on one scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct E2Run {
    /// Median solve time over the repetitions (ms).
    pub cpu_ms: f64,
    /// Fastest solve time (ms).
    pub cpu_ms_min: f64,
    /// Duration of the trajectory (s).
    pub duration_s: f64,
    /// Whether the trajectory keeps clear of every obstacle.
    pub collision_free: bool,
    /// Smallest clearance along the trajectory (m); `None` (JSON `null`) when the scene has no
    /// obstacle to measure against.
    #[serde(deserialize_with = "nullable")]
    pub min_clearance_m: Option<f64>,
    /// The solver's status (`Debug` form).
    pub status: String,
    /// Solver iterations.
    pub iterations: usize,
    /// Cost and gradient evaluations.
    pub evaluations: usize,
    /// Polynomial pieces of the trajectory.
    pub pieces: usize,
    /// Largest speed along the trajectory (m/s).
    pub max_speed: f64,
    /// Largest acceleration along the trajectory (m/s²).
    pub max_acceleration: f64,
    /// Distance from the trajectory's end to the goal (m).
    pub end_to_goal_m: f64,
    /// The cost terms of the solution.
    pub costs: CostBreakdown,
    /// A re-solve one replanning period later, warm-started from this solution.
    pub warm_resolve: E2WarmResolve,
}

/// The warm-started re-solve of an [`E2Run`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct E2WarmResolve {
    /// Median solve time (ms).
    pub cpu_ms: f64,
    /// Duration of the trajectory (s).
    pub duration_s: f64,
    /// Whether the trajectory keeps clear of every obstacle.
    pub collision_free: bool,
    /// Smallest clearance along the trajectory (m); `None` when there is no obstacle.
    #[serde(deserialize_with = "nullable")]
    pub min_clearance_m: Option<f64>,
    /// The solver's status (`Debug` form).
    pub status: String,
    /// Cost and gradient evaluations.
    pub evaluations: usize,
}

/// A field that must be present but may be `null` (serde's default would accept it missing).
fn nullable<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    Option::<f64>::deserialize(d)
}

/// Parses `e2_compare`'s output; an error names the example and the missing, unknown or mistyped
/// field.
pub fn parse(json: &str) -> Result<E2Results, ExperimentError> {
    serde_json::from_str(json).map_err(|source| ExperimentError::ExampleOutput {
        example: EXAMPLE,
        source,
    })
}

/// `report.md` of E2: the results as pretty JSON (keys sorted, as the example's own output), then
/// the paper's figures.
pub fn report(results: &E2Results) -> String {
    format!(
        "# E2 — UTF-MINCO vs MINCO (paper Table Sim-A-2)\n\n```json\n{:#}\n```\n\n\
         Paper: UTF-MINCO 8.98 ms / 7.08 s (static), 9.71 ms / 6.47 s (dynamic); \
         MINCO 7.77 ms / 7.09 s, 8.52 ms / 6.72 s (collides in the dynamic case).\n",
        sorted_json(results)
    )
}

/// `results` as a JSON value with its keys sorted, as serde_json's map keeps them (the workspace
/// does not enable `preserve_order`), so the report lists the fields in the example's order.
fn sorted_json(results: &E2Results) -> serde_json::Value {
    // `json!` converts with `to_value`, which cannot fail here: every map key is a string.
    serde_json::json!(results)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(cpu_ms: f64, clearance: Option<f64>) -> serde_json::Value {
        serde_json::json!({
            "cpu_ms": cpu_ms,
            "cpu_ms_min": cpu_ms - 0.5,
            "duration_s": 7.08,
            "collision_free": clearance.is_none_or(|c| c >= 0.0),
            "min_clearance_m": clearance,
            "status": "Converged",
            "iterations": 41,
            "evaluations": 57,
            "pieces": 6,
            "max_speed": 2.9,
            "max_acceleration": 3.1,
            "end_to_goal_m": 0.01,
            "costs": CostBreakdown::default(),
            "warm_resolve": {
                "cpu_ms": 1.5,
                "duration_s": 6.9,
                "collision_free": true,
                "min_clearance_m": clearance,
                "status": "Converged",
                "evaluations": 12,
            },
        })
    }

    fn fixture() -> serde_json::Value {
        let case = |a, b| serde_json::json!({ "utf-minco": a, "minco": b });
        serde_json::json!({
            "static": case(run(8.98, Some(0.4)), run(7.77, Some(0.3))),
            "dynamic": case(run(9.71, None), run(8.52, Some(-0.2))),
            "repeats": 3,
        })
    }

    #[test]
    fn report_shows_the_results_as_sorted_pretty_json() {
        let json = fixture();
        let results = parse(&serde_json::to_string_pretty(&json).unwrap()).unwrap();
        assert_eq!(results.static_scene.utf_minco.cpu_ms, 8.98);
        assert_eq!(results.dynamic.utf_minco.min_clearance_m, None);
        let md = report(&results);
        // The example's own `Value` (keys sorted) printed pretty is what the report embeds.
        let pretty = serde_json::to_string_pretty(&json).unwrap();
        assert!(md.contains(&format!("```json\n{pretty}\n```\n")), "{md}");
        assert!(
            md.contains("    \"utf-minco\": {\n      \"collision_free\": true,"),
            "{md}"
        );
        assert!(md.contains("\"min_clearance_m\": null"), "{md}");
    }

    #[test]
    fn a_missing_field_is_an_error_naming_the_example_and_the_field() {
        let mut json = fixture();
        json["static"]["minco"]
            .as_object_mut()
            .unwrap()
            .remove("min_clearance_m");
        let e = parse(&json.to_string()).unwrap_err().to_string();
        assert!(e.contains(EXAMPLE), "{e}");
        assert!(e.contains("missing field `min_clearance_m`"), "{e}");
        let mut json = fixture();
        json.as_object_mut().unwrap().remove("dynamic");
        let e = parse(&json.to_string()).unwrap_err().to_string();
        assert!(e.contains("missing field `dynamic`"), "{e}");
    }
}

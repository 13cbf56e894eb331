//! E1 (paper Fig. Sim-A-1-1(c)): DEV-PRM vs V-PRM, distinct paths per CPU ms over the number of
//! dynamic obstacles.
//!
//! `cargo xtask experiment e1` runs the `trust-topo-prm` example `prm_efficiency` once per obstacle
//! count; each run prints one [`E1Row`] as JSON, parsed by [`parse_row`]; [`report`] turns the rows
//! into `report.md`.

use serde::{Deserialize, Serialize};
use trust_topo_prm::DevPrmParams;

use crate::ExperimentError;

/// The example that prints one [`E1Row`] (package `trust-topo-prm`).
pub const EXAMPLE: &str = "prm_efficiency";

/// One run of `prm_efficiency`: both planners over `trials` random scenes with `obstacles` moving
/// obstacles (the example's JSON output, field for field).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct E1Row {
    /// Number of moving obstacles `k`.
    pub obstacles: usize,
    /// Number of random scenes.
    pub trials: usize,
    /// Master seed of the scenes and planners.
    pub seed: u64,
    /// Roadmap time budget of both planners (ms).
    pub budget_ms: f64,
    /// Planning horizon of the query, the PDCs and the common checker (s).
    pub horizon_s: f64,
    /// Random-sample cap of V-PRM.
    pub vprm_max_samples: usize,
    /// Random-sample cap of DEV-PRM.
    pub devprm_max_samples: usize,
    /// The DEV-PRM parameters used.
    pub devprm_params: DevPrmParams,
    /// Name of the common homotopy checker of the headline counts.
    pub checker: String,
    /// Name of the checker of the `st_*` counts.
    pub st_checker: String,
    /// The example's definition of the metrics.
    pub metric: String,
    /// V-PRM's counts and timing.
    pub vprm: PlannerSummary,
    /// DEV-PRM's counts and timing.
    pub devprm: PlannerSummary,
    /// DEV-PRM paths/ms over V-PRM paths/ms (headline); `None` (JSON `null`) when V-PRM found none.
    #[serde(deserialize_with = "nullable")]
    pub ratio: Option<f64>,
    /// The same ratio over all returned paths; `None` when V-PRM returned none.
    #[serde(deserialize_with = "nullable")]
    pub raw_ratio: Option<f64>,
    /// The same ratio over the paths flown at v_max; `None` when none of V-PRM's stayed clear.
    #[serde(deserialize_with = "nullable")]
    pub st_ratio: Option<f64>,
}

/// One planner's means over the trials of an [`E1Row`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlannerSummary {
    /// Distinct valid paths per scene (headline count).
    pub distinct_paths_mean: f64,
    /// The planner's own CPU time per scene (ms).
    pub cpu_ms_mean: f64,
    /// Sum of distinct valid paths over the sum of CPU ms.
    pub paths_per_ms: f64,
    /// Valid paths per scene.
    pub valid_paths_mean: f64,
    /// Returned paths per scene.
    pub returned_paths_mean: f64,
    /// Distinct returned paths per scene.
    pub raw_distinct_paths_mean: f64,
    /// Sum of distinct returned paths over the sum of CPU ms.
    pub raw_paths_per_ms: f64,
    /// Paths per scene that stay clear when flown at v_max.
    pub st_valid_paths_mean: f64,
    /// Distinct such paths per scene (TVD classes).
    pub st_distinct_paths_mean: f64,
    /// Sum of distinct such paths over the sum of CPU ms.
    pub st_paths_per_ms: f64,
    /// Roadmap samples per scene.
    pub samples_mean: f64,
}

/// A field that must be present but may be `null`: unlike serde's default for `Option`, a missing
/// field is an error.
fn nullable<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    Option::<f64>::deserialize(d)
}

/// Parses one line of `prm_efficiency`'s output; an error names the example and the missing,
/// unknown or mistyped field.
pub fn parse_row(json: &str) -> Result<E1Row, ExperimentError> {
    serde_json::from_str(json).map_err(|source| ExperimentError::ExampleOutput {
        example: EXAMPLE,
        source,
    })
}

/// `report.md` of E1: one table row per obstacle count, the paper's figures, and the metric
/// definitions of the first row.
pub fn report(rows: &[E1Row]) -> String {
    let mut md = String::from(
        "# E1 — DEV-PRM vs V-PRM (paper Fig. Sim-A-1-1(c))\n\n\
         20×20×10 m scenes with k random dynamic obstacles, 20 ms budget per planner. Headline: \
         distinct *valid* paths (clear of the static map and of every moving obstacle's predictive \
         cone) per CPU ms, judged by one common checker for both planners. `raw` counts every \
         returned path; `st` flies each path at v_max and counts TVD classes of those that stay clear \
         of the moving obstacles at every instant.\n\n\
         | k | V-PRM paths | V-PRM ms | V-PRM paths/ms | DEV-PRM paths | DEV-PRM ms | DEV-PRM paths/ms | ratio | raw ratio | st ratio |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let cells = [
            r.vprm.distinct_paths_mean,
            r.vprm.cpu_ms_mean,
            r.vprm.paths_per_ms,
            r.devprm.distinct_paths_mean,
            r.devprm.cpu_ms_mean,
            r.devprm.paths_per_ms,
        ]
        .map(|x| cell(Some(x)));
        md.push_str(&format!(
            "| {} | {} | {} | {} | {} |\n",
            r.obstacles,
            cells.join(" | "),
            cell(r.ratio),
            cell(r.raw_ratio),
            cell(r.st_ratio),
        ));
    }
    md.push_str("\nPaper, k = 10: V-PRM 0.186, DEV-PRM 0.338 paths/ms (ratio 1.82).\n");
    if let Some(first) = rows.first() {
        // Quoted and escaped as a JSON string, as the report has always shown it.
        let metric = serde_json::Value::from(first.metric.as_str());
        md.push_str(&format!(
            "\nMetric definitions (from the example): {metric}\n"
        ));
    }
    md
}

/// A table cell: three decimals, or a dash for a value the example could not compute (`null`).
fn cell(x: Option<f64>) -> String {
    x.filter(|x| x.is_finite())
        .map_or_else(|| "—".to_string(), |x| format!("{x:.3}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn summary(distinct: f64, cpu_ms: f64) -> serde_json::Value {
        serde_json::json!({
            "distinct_paths_mean": distinct,
            "cpu_ms_mean": cpu_ms,
            "paths_per_ms": distinct / cpu_ms,
            "valid_paths_mean": 3.0,
            "returned_paths_mean": 4.0,
            "raw_distinct_paths_mean": 3.5,
            "raw_paths_per_ms": 0.2,
            "st_valid_paths_mean": 1.0,
            "st_distinct_paths_mean": 1.0,
            "st_paths_per_ms": 0.05,
            "samples_mean": 812.5,
        })
    }

    fn fixture() -> serde_json::Value {
        serde_json::json!({
            "obstacles": 10,
            "trials": 2,
            "seed": 1,
            "budget_ms": 20.0,
            "horizon_s": 2.0,
            "vprm_max_samples": 2000,
            "devprm_max_samples": 2000,
            "devprm_params": DevPrmParams::default(),
            "checker": "uvd+pdc",
            "st_checker": "tvd",
            "metric": "counts \"per\" ms",
            "vprm": summary(2.0, 16.0),
            "devprm": summary(3.0, 8.0),
            "ratio": 3.0,
            "raw_ratio": 1.25,
            "st_ratio": null,
        })
    }

    #[test]
    fn report_has_one_row_per_run_with_three_decimals_and_a_dash_for_null() {
        let row = parse_row(&fixture().to_string()).unwrap();
        assert_eq!(row.st_ratio, None);
        let md = report(&[row]);
        assert!(
            md.contains(
                "| 10 | 2.000 | 16.000 | 0.125 | 3.000 | 8.000 | 0.375 | 3.000 | 1.250 | — |\n"
            ),
            "{md}"
        );
        assert!(
            md.ends_with("(from the example): \"counts \\\"per\\\" ms\"\n"),
            "{md}"
        );
    }

    #[test]
    fn a_missing_field_is_an_error_naming_the_example_and_the_field() {
        for field in ["ratio", "st_ratio", "obstacles"] {
            let mut json = fixture();
            json.as_object_mut().unwrap().remove(field);
            let e = parse_row(&json.to_string()).unwrap_err().to_string();
            assert!(e.contains(EXAMPLE), "{e}");
            assert!(e.contains(&format!("missing field `{field}`")), "{e}");
        }
        let mut json = fixture();
        json["vprm"].as_object_mut().unwrap().remove("cpu_ms_mean");
        let e = parse_row(&json.to_string()).unwrap_err().to_string();
        assert!(e.contains("missing field `cpu_ms_mean`"), "{e}");
    }

    #[test]
    fn an_unknown_or_mistyped_field_is_an_error() {
        let mut json = fixture();
        json["speedup"] = 2.0.into();
        let e = parse_row(&json.to_string()).unwrap_err().to_string();
        assert!(e.contains("unknown field `speedup`"), "{e}");
        let mut json = fixture();
        json["obstacles"] = "ten".into();
        let e = parse_row(&json.to_string()).unwrap_err().to_string();
        assert!(e.contains("invalid type"), "{e}");
    }
}

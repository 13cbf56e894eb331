//! Cross-check of the JSON front door (`trust_minco::eval_json`, the logic of
//! `examples/minco_eval.rs`) against GCOPTER's numbers for the n = 8 reference problem
//! (`shared/reference/minco-lbfgs.md`, "Cross-check numbers").

use trust_minco::MincoError;
use trust_minco::minco::{EvalOutput, eval_json};

fn reference_json(n: usize) -> String {
    let waypoints: Vec<String> = (1..n)
        .map(|i| {
            let x = i as f64;
            format!(
                "[{:?}, {:?}, {:?}]",
                2.0 * x,
                3.0 * x.sin(),
                1.0 + 0.5 * x.cos()
            )
        })
        .collect();
    let durations = vec!["0.5"; n].join(", ");
    format!(
        r#"{{"head": [[0, 0, 1], [0, 0, 0], [0, 0, 0]],
            "tail": [[{}, 0, 1], [0, 0, 0], [0, 0, 0]],
            "waypoints": [{}],
            "durations": [{}]}}"#,
        2 * n,
        waypoints.join(", "),
        durations
    )
}

fn assert_rel(got: f64, want: f64, rel: f64, what: &str) {
    let err = (got - want).abs() / want.abs().max(1e-300);
    assert!(
        err <= rel,
        "{what}: got {got}, want {want} (relative error {err:e})"
    );
}

fn assert_vec_rel(got: &[f64; 3], want: [f64; 3], rel: f64, what: &str) {
    for d in 0..3 {
        assert_rel(got[d], want[d], rel, &format!("{what}[{d}]"));
    }
}

/// `|got - want| <= abs` per component.
fn assert_vec_abs(got: &[f64; 3], want: [f64; 3], abs: f64, what: &str) {
    for d in 0..3 {
        let err = (got[d] - want[d]).abs();
        assert!(
            err <= abs,
            "{what}[{d}]: got {}, want {} (error {err:e})",
            got[d],
            want[d]
        );
    }
}

/// Numbers printed with 6 decimals in the reference: the true value lies within half a unit of the
/// last digit of the printed one, so allow that rounding plus 1e-9 relative.
fn assert_vec_rounded6(got: &[f64; 3], want: [f64; 3], what: &str) {
    for d in 0..3 {
        let err = (got[d] - want[d]).abs();
        let tol = 5e-7 + 1e-9 * want[d].abs();
        assert!(
            err <= tol,
            "{what}[{d}]: got {}, want {} (error {err:e})",
            got[d],
            want[d]
        );
    }
}

#[test]
fn n8_reference_numbers_through_json() {
    let out: EvalOutput = serde_json::from_str(&eval_json(&reference_json(8)).unwrap()).unwrap();
    let rel = 1e-9;
    assert_eq!(out.coeffs.len(), 8);
    let p0 = &out.coeffs[0];
    assert_vec_abs(&p0[0], [0.0, 0.0, 1.0], 1e-12, "piece 0 c0");
    assert_vec_abs(&p0[1], [0.0, 0.0, 0.0], 1e-12, "piece 0 c1");
    assert_vec_abs(&p0[2], [0.0, 0.0, 0.0], 1e-12, "piece 0 c2");
    assert_vec_rel(
        &p0[3],
        [51.661746187506, 73.91335550047262, 11.277727922639443],
        rel,
        "piece 0 c3",
    );
    assert_vec_rel(
        &p0[4],
        [-97.16319285049453, -147.0446036982494, -25.660770932299613],
        rel,
        "piece 0 c4",
    );
    assert_vec_rel(
        &p0[5],
        [51.67940095096501, 79.21699993616649, 14.855467067931684],
        rel,
        "piece 0 c5",
    );
    let p7 = &out.coeffs[7];
    assert_vec_rel(
        &p7[0],
        [14.0, 1.9709597961563672, 1.3769511271716521],
        rel,
        "piece 7 c0",
    );
    assert_vec_rel(
        &p7[5],
        [51.67940095096507, -99.71034927553082, -10.900861065974901],
        rel,
        "piece 7 c5",
    );

    assert_rel(out.energy, 75650.62106350838, 1e-12, "energy");

    let dt = [
        -297335.0623528314,
        -18344.10394590532,
        5694.725190099412,
        -13929.646126010648,
        3836.8095812196025,
        -414.395163037203,
        -118582.10128239135,
        -317432.4365362276,
    ];
    for (i, (got, want)) in out.grad_durations.iter().zip(dt).enumerate() {
        assert_rel(*got, want, rel, &format!("dE/dT[{i}]"));
    }
    let uniform = out.grad_durations.iter().sum::<f64>() / 8.0;
    assert_rel(uniform, -94563.27632938555, rel, "uniform dE/dT_total");

    assert_vec_rounded6(
        &out.grad_tail[0],
        [12403.056228, -23930.483826, -2616.206656],
        "dE/dtail p",
    );
    assert_vec_rounded6(
        &out.grad_tail[1],
        [-4663.833257, 8338.616008, 984.623465],
        "dE/dtail v",
    );
    assert_vec_rounded6(
        &out.grad_tail[2],
        [619.940954, -932.408094, -126.562658],
        "dE/dtail a",
    );

    assert_eq!(out.grad_waypoints.len(), 7);
    assert_vec_rel(
        &out.grad_waypoints[0],
        [16726.68893165938, 25788.360636768997, 5226.220619866257],
        rel,
        "dE/dq_1",
    );
}

#[test]
fn larger_reference_energies_through_json() {
    for (n, want) in [
        (16, 53038.69151739622),
        (32, 48586.05013620369),
        (64, 60820.76320632773),
    ] {
        let out: EvalOutput =
            serde_json::from_str(&eval_json(&reference_json(n)).unwrap()).unwrap();
        assert_rel(out.energy, want, 1e-9, &format!("energy n = {n}"));
        assert_eq!(out.grad_durations.len(), n);
        assert_eq!(out.grad_waypoints.len(), n - 1);
    }
}

#[test]
fn bad_input_gives_errors_with_readable_messages() {
    let err = eval_json("not json").unwrap_err();
    assert!(matches!(err, MincoError::Json { .. }));
    assert!(err.to_string().contains("line 1"), "{err}");

    let wrong_count = reference_json(8).replace(r#""durations": [0.5, "#, r#""durations": ["#);
    let err = eval_json(&wrong_count).unwrap_err();
    assert_eq!(
        err,
        MincoError::LengthMismatch {
            field: "waypoints",
            expected: 6,
            got: 7
        }
    );
    assert!(err.to_string().contains("waypoints"), "{err}");

    let negative = reference_json(2).replace("[0.5, 0.5]", "[0.5, -1.0]");
    let err = eval_json(&negative).unwrap_err();
    assert_eq!(
        err,
        MincoError::InvalidDuration {
            index: 1,
            value: -1.0
        }
    );
    assert!(err.to_string().contains("durations[1] = -1"), "{err}");
}

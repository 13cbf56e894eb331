//! Fits the work-unit weights of the DEV-PRM / V-PRM work budget ([`trust_topo_prm::QueryWork`],
//! `RoadmapWork::SAMPLE_UNITS`) to measured search times.
//!
//! 1. Fly scenes with the trace on and a budget that does not bind, e.g. for each scenario
//!    `frontend = { kind = "dev-prm", budget_ms = 15.0, work_per_ms = 1e8 }` and
//!    `TRUST_PRM_WORK_TRACE=/tmp/trace.txt trust-sim run FILE --time-limit 8` (every search
//!    appends `elapsed_ns queries esdf_samples shape_tests cone_boxes cone_tests samples
//!    visibility_tests uvd_tests`).
//! 2. `cargo run --release -p trust-topo-prm --example prm_work_fit -- /tmp/trace.txt`
//!
//! Prints the non-negative least-squares weights (ns per operation, relative error, searches
//! under 20 µs left out) and the spread of measured over predicted time, and the same ratio with
//! the weights the crate uses.

use trust_topo_prm::QueryWork;
use trust_topo_prm::roadmap::RoadmapWork;

const NAMES: [&str; 6] = [
    "query",
    "esdf_sample",
    "shape_test",
    "cone_box",
    "cone_test",
    "sample",
];

fn main() {
    let path = std::env::args()
        .nth(1)
        .expect("usage: prm_work_fit TRACE_FILE");
    let text = std::fs::read_to_string(&path).expect("readable trace file");
    let rows: Vec<(f64, [f64; 6])> = text
        .lines()
        .filter_map(|l| {
            let v: Vec<f64> = l
                .split_whitespace()
                .filter_map(|x| x.parse().ok())
                .collect();
            (v.len() == 9 && v[0] > 20_000.0).then(|| (v[0], [v[1], v[2], v[3], v[4], v[5], v[6]]))
        })
        .collect();
    assert!(!rows.is_empty(), "no searches of 20 µs or more in {path}");
    let fitted = nnls_relative(&rows);
    println!("searches: {}", rows.len());
    for (name, w) in NAMES.iter().zip(fitted) {
        println!("  {name:<12} {w:8.1} ns");
    }
    report("fitted", &rows, &fitted);
    let used = [
        QueryWork::QUERY_UNITS,
        QueryWork::ESDF_SAMPLE_UNITS,
        QueryWork::SHAPE_TEST_UNITS,
        QueryWork::CONE_BOX_UNITS,
        QueryWork::CONE_TEST_UNITS,
        RoadmapWork::SAMPLE_UNITS,
    ]
    .map(|w| w as f64);
    report("crate's", &rows, &used);
}

/// Prints the 10th, 50th and 90th percentiles of measured over predicted time.
fn report(label: &str, rows: &[(f64, [f64; 6])], w: &[f64; 6]) {
    let mut ratios: Vec<f64> = rows
        .iter()
        .map(|(t, x)| t / x.iter().zip(w).map(|(a, b)| a * b).sum::<f64>().max(1.0))
        .collect();
    ratios.sort_by(f64::total_cmp);
    let q = |p: f64| ratios[((ratios.len() - 1) as f64 * p) as usize];
    println!(
        "{label} weights, measured/predicted: p10 {:.2}, median {:.2}, p90 {:.2}",
        q(0.1),
        q(0.5),
        q(0.9)
    );
}

/// Minimizes Σ ((x·w − t)/t)² over w ≥ 0 by dropping negative coefficients and refitting.
fn nnls_relative(rows: &[(f64, [f64; 6])]) -> [f64; 6] {
    let mut active: Vec<usize> = (0..6).collect();
    loop {
        let n = active.len();
        let mut a = vec![vec![0.0; n + 1]; n];
        for (t, x) in rows {
            let s = 1.0 / (t * t);
            for (i, &ci) in active.iter().enumerate() {
                a[i][n] += s * x[ci] * t;
                for (j, &cj) in active.iter().enumerate() {
                    a[i][j] += s * x[ci] * x[cj];
                }
            }
        }
        let sol = gauss(a);
        if sol.iter().all(|&v| v >= 0.0) {
            let mut w = [0.0; 6];
            for (i, &ci) in active.iter().enumerate() {
                w[ci] = sol[i];
            }
            return w;
        }
        active = active
            .iter()
            .zip(&sol)
            .filter(|(_, v)| **v >= 0.0)
            .map(|(c, _)| *c)
            .collect();
    }
}

/// Solves the augmented system `a` (n × n+1) by Gauss–Jordan elimination with partial pivoting;
/// a singular column gives 0.
fn gauss(mut a: Vec<Vec<f64>>) -> Vec<f64> {
    let n = a.len();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap_or(c);
        a.swap(c, p);
        if a[c][c].abs() < 1e-300 {
            continue;
        }
        let pivot = a[c].clone();
        for (r, row) in a.iter_mut().enumerate() {
            if r != c {
                let f = row[c] / pivot[c];
                for (x, p) in row[c..].iter_mut().zip(&pivot[c..]) {
                    *x -= f * p;
                }
            }
        }
    }
    (0..n)
        .map(|i| {
            if a[i][i].abs() < 1e-300 {
                0.0
            } else {
                a[i][n] / a[i][i]
            }
        })
        .collect()
}

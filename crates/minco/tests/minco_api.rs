//! Public-API tests of MINCO s = 3: GCOPTER cross-check numbers, constraint satisfaction,
//! finite-difference checks of every analytic gradient, and degenerate input.

use nalgebra::Vector3;
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trust_minco::minco::{BoundaryState, MincoGrad, MincoS3, eval_piece};
use trust_minco::{MincoError, jerk_energy};

// ---------------------------------------------------------------------------------------------
// Problems
// ---------------------------------------------------------------------------------------------

#[derive(Debug, Clone)]
struct Problem {
    head: BoundaryState,
    tail: BoundaryState,
    waypoints: Vec<Vector3<f64>>,
    durations: Vec<f64>,
}

impl Problem {
    fn pieces(&self) -> usize {
        self.durations.len()
    }

    fn solved(&self) -> MincoS3 {
        let mut minco = MincoS3::new(self.pieces()).unwrap();
        minco
            .solve(&self.head, &self.tail, &self.waypoints, &self.durations)
            .unwrap();
        minco
    }

    fn energy(&self) -> f64 {
        self.solved().energy()
    }
}

fn rest(p: Vector3<f64>) -> BoundaryState {
    [p, Vector3::zeros(), Vector3::zeros()]
}

/// The reference family: head (0,0,1) and tail (2n,0,1) at rest, q_i = (2i, 3 sin i, 1 + 0.5 cos i),
/// all T_i = 0.5.
fn reference_problem(n: usize) -> Problem {
    Problem {
        head: rest(Vector3::new(0.0, 0.0, 1.0)),
        tail: rest(Vector3::new(2.0 * n as f64, 0.0, 1.0)),
        waypoints: (1..n)
            .map(|i| {
                let x = i as f64;
                Vector3::new(2.0 * x, 3.0 * x.sin(), 1.0 + 0.5 * x.cos())
            })
            .collect(),
        durations: vec![0.5; n],
    }
}

fn vec3_in(r: f64) -> impl Strategy<Value = Vector3<f64>> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vector3::new(x, y, z))
}

prop_compose! {
    /// Bounded random problems with 1..=6 pieces.
    fn problem()(n in 1usize..=6)(
        head in [vec3_in(3.0), vec3_in(2.0), vec3_in(2.0)],
        tail in [vec3_in(3.0), vec3_in(2.0), vec3_in(2.0)],
        waypoints in proptest::collection::vec(vec3_in(5.0), n - 1),
        durations in proptest::collection::vec(0.3f64..2.0, n),
    ) -> Problem {
        Problem { head, tail, waypoints, durations }
    }
}

// ---------------------------------------------------------------------------------------------
// Comparison helpers
// ---------------------------------------------------------------------------------------------

fn assert_rel(got: f64, want: f64, rel: f64, what: &str) {
    let err = (got - want).abs() / want.abs().max(1e-300);
    assert!(
        err <= rel,
        "{what}: got {got}, want {want} (relative error {err:e})"
    );
}

fn assert_vec_rel(got: &Vector3<f64>, want: [f64; 3], rel: f64, what: &str) {
    for d in 0..3 {
        assert_rel(got[d], want[d], rel, &format!("{what}[{d}]"));
    }
}

/// Central finite-difference check: `|fd − analytic| ≤ 1e-5 · max(|analytic|, floor) + noise`,
/// where the floor (a fraction of the largest gradient entry of the same problem) keeps near-zero
/// entries from demanding impossible relative accuracy, and `noise = 100 ε |f(0)| / h` bounds the
/// rounding error of the difference quotient itself.
fn check_fd(
    what: &str,
    analytic: f64,
    floor: f64,
    h: f64,
    f: impl Fn(f64) -> f64,
) -> Result<(), TestCaseError> {
    let fd = trust_numdiff::central_difference(&f, 0.0, h);
    let noise = 100.0 * f64::EPSILON * f(0.0).abs() / h;
    let tol = 1e-5 * analytic.abs().max(floor) + noise;
    prop_assert!(
        (fd - analytic).abs() <= tol,
        "{what}: analytic {analytic}, finite difference {fd}, tolerance {tol:e}"
    );
    Ok(())
}

fn max_abs(grad: &MincoGrad) -> f64 {
    grad.waypoints
        .iter()
        .chain(&grad.head)
        .chain(&grad.tail)
        .map(|v| v.amax())
        .chain(grad.durations.iter().map(|g| g.abs()))
        .fold(0.0, f64::max)
}

/// Finite-difference checks of every entry of `grad` for the scalar `cost(problem)`.
fn check_all_gradients(
    p: &Problem,
    grad: &MincoGrad,
    cost: impl Fn(&Problem) -> f64,
) -> Result<(), TestCaseError> {
    let floor = 1e-3 * max_abs(grad) + 1e-6;
    let h = 1e-6;
    for (i, g) in grad.waypoints.iter().enumerate() {
        for d in 0..3 {
            check_fd(&format!("dK/dq[{i}][{d}]"), g[d], floor, h, |e| {
                let mut q = p.clone();
                q.waypoints[i][d] += e;
                cost(&q)
            })?;
        }
    }
    for (i, g) in grad.durations.iter().enumerate() {
        let ht = h * p.durations[i];
        check_fd(&format!("dK/dT[{i}]"), *g, floor, ht, |e| {
            let mut q = p.clone();
            q.durations[i] += e;
            cost(&q)
        })?;
    }
    for s in 0..3 {
        for d in 0..3 {
            check_fd(
                &format!("dK/dtail[{s}][{d}]"),
                grad.tail[s][d],
                floor,
                h,
                |e| {
                    let mut q = p.clone();
                    q.tail[s][d] += e;
                    cost(&q)
                },
            )?;
            check_fd(
                &format!("dK/dhead[{s}][{d}]"),
                grad.head[s][d],
                floor,
                h,
                |e| {
                    let mut q = p.clone();
                    q.head[s][d] += e;
                    cost(&q)
                },
            )?;
        }
    }
    Ok(())
}

/// An arbitrary smooth test cost of the coefficients and durations:
/// `K = Σ_r w_r ⊙ c_r ⊙ c_r + Σ_r u_r · c_r + Σ_i α_i T_i²`, with weights drawn from `seed`.
struct TestCost {
    w: Vec<Vector3<f64>>,
    u: Vec<Vector3<f64>>,
    alpha: Vec<f64>,
}

impl TestCost {
    fn new(n: usize, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut v = |r: f64| {
            Vector3::new(
                rng.random_range(-r..r),
                rng.random_range(-r..r),
                rng.random_range(-r..r),
            )
        };
        let w = (0..6 * n).map(|_| v(1.0)).collect();
        let u = (0..6 * n).map(|_| v(5.0)).collect();
        let alpha = (0..n).map(|_| rng.random_range(-10.0..10.0)).collect();
        Self { w, u, alpha }
    }

    fn value(&self, coeffs: &[Vector3<f64>], durations: &[f64]) -> f64 {
        let c_part: f64 = coeffs
            .iter()
            .zip(&self.w)
            .zip(&self.u)
            .map(|((c, w), u)| w.dot(&c.component_mul(c)) + u.dot(c))
            .sum();
        let t_part: f64 = durations
            .iter()
            .zip(&self.alpha)
            .map(|(t, a)| a * t * t)
            .sum();
        c_part + t_part
    }

    fn grads(&self, coeffs: &[Vector3<f64>], durations: &[f64]) -> (Vec<Vector3<f64>>, Vec<f64>) {
        let gc = coeffs
            .iter()
            .zip(&self.w)
            .zip(&self.u)
            .map(|((c, w), u)| 2.0 * w.component_mul(c) + u)
            .collect();
        let gt = durations
            .iter()
            .zip(&self.alpha)
            .map(|(t, a)| 2.0 * a * t)
            .collect();
        (gc, gt)
    }
}

// ---------------------------------------------------------------------------------------------
// Cross-check against GCOPTER (reference n = 8 and energies for n = 16, 32, 64)
// ---------------------------------------------------------------------------------------------

#[test]
fn reference_n8_coefficients_energy_and_gradients() {
    let p = reference_problem(8);
    let mut minco = p.solved();
    let rel = 1e-9;

    let p0 = minco.piece(0).unwrap();
    assert!((p0[0] - Vector3::new(0.0, 0.0, 1.0)).amax() < 1e-12);
    assert!(p0[1].amax() < 1e-12 && p0[2].amax() < 1e-12);
    assert_vec_rel(
        &p0[3],
        [51.661746187506, 73.91335550047262, 11.277727922639443],
        rel,
        "c0_3",
    );
    assert_vec_rel(
        &p0[4],
        [-97.16319285049453, -147.0446036982494, -25.660770932299613],
        rel,
        "c0_4",
    );
    assert_vec_rel(
        &p0[5],
        [51.67940095096501, 79.21699993616649, 14.855467067931684],
        rel,
        "c0_5",
    );
    let p7 = minco.piece(7).unwrap();
    assert_vec_rel(
        &p7[0],
        [14.0, 1.9709597961563672, 1.3769511271716521],
        rel,
        "c7_0",
    );
    assert_vec_rel(
        &p7[5],
        [51.67940095096507, -99.71034927553082, -10.900861065974901],
        rel,
        "c7_5",
    );

    assert_rel(minco.energy(), 75650.62106350838, 1e-12, "energy");

    let mut grad = MincoGrad::new(8);
    let energy = minco.energy_and_grad(&mut grad).unwrap();
    assert_rel(
        energy,
        75650.62106350838,
        1e-12,
        "energy from energy_and_grad",
    );
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
    for (i, want) in dt.iter().enumerate() {
        assert_rel(grad.durations[i], *want, rel, &format!("dE/dT[{i}]"));
    }
    assert_rel(
        grad.uniform_total_duration(),
        -94563.27632938555,
        rel,
        "dE/dT_total",
    );
    assert_vec_rel(
        &grad.waypoints[0],
        [16726.68893165938, 25788.360636768997, 5226.220619866257],
        rel,
        "dE/dq_1",
    );
    // Printed with 6 decimals in the reference: half a unit of the last digit plus 1e-9 relative.
    let tail_want = [
        [12403.056228, -23930.483826, -2616.206656],
        [-4663.833257, 8338.616008, 984.623465],
        [619.940954, -932.408094, -126.562658],
    ];
    for (s, want) in tail_want.iter().enumerate() {
        for (d, w) in want.iter().enumerate() {
            let got = grad.tail[s][d];
            assert!(
                (got - w).abs() <= 5e-7 + 1e-9 * w.abs(),
                "dE/dtail[{s}][{d}]: got {got}, want {w}"
            );
        }
    }
}

#[test]
fn reference_energies_for_larger_n() {
    for (n, want) in [
        (16, 53038.69151739622),
        (32, 48586.05013620369),
        (64, 60820.76320632773),
    ] {
        let minco = reference_problem(n).solved();
        assert_rel(minco.energy(), want, 1e-9, &format!("energy n = {n}"));
        assert_rel(
            jerk_energy(minco.coeffs(), minco.durations()).unwrap(),
            want,
            1e-9,
            &format!("free jerk_energy n = {n}"),
        );
    }
}

#[test]
fn explicit_energy_gradients_match_accumulated_ones() {
    let minco = reference_problem(5).solved();
    let mut gc = vec![Vector3::zeros(); 30];
    let mut gt = vec![0.0; 5];
    minco.energy_grad_coeffs(&mut gc).unwrap();
    minco.energy_grad_durations(&mut gt).unwrap();
    let mut ac = vec![Vector3::zeros(); 30];
    let mut at = vec![0.0; 5];
    let e = minco.accumulate_energy_grad(2.0, &mut ac, &mut at).unwrap();
    assert_rel(e, minco.energy(), 1e-14, "accumulated energy");
    for (a, g) in ac.iter().zip(&gc) {
        assert!((a - 2.0 * g).amax() <= 1e-12 * (1.0 + g.amax()));
    }
    for (a, g) in at.iter().zip(&gt) {
        assert_rel(*a, 2.0 * g, 1e-14, "accumulated dE/dT");
    }
    for piece in gc.chunks_exact(6) {
        assert!(piece[..3].iter().all(|v| *v == Vector3::zeros()));
    }
}

// ---------------------------------------------------------------------------------------------
// Properties
// ---------------------------------------------------------------------------------------------

proptest! {
    /// The solved polynomial meets head and tail, passes through every waypoint and is C⁴ at every
    /// junction (position through snap).
    #[test]
    fn solution_satisfies_the_constraints(p in problem()) {
        let minco = p.solved();
        let n = p.pieces();
        let scale = minco.coeffs().iter().map(|c| c.amax()).fold(1.0, f64::max);
        let tol = 1e-9 * scale;
        let close = |a: Vector3<f64>, b: Vector3<f64>| (a - b).amax() <= tol;
        let start = minco.eval(0, 0.0).unwrap();
        prop_assert!(close(start.position, p.head[0]));
        prop_assert!(close(start.velocity, p.head[1]));
        prop_assert!(close(start.acceleration, p.head[2]));
        let end = minco.eval(n - 1, p.durations[n - 1]).unwrap();
        prop_assert!(close(end.position, p.tail[0]));
        prop_assert!(close(end.velocity, p.tail[1]));
        prop_assert!(close(end.acceleration, p.tail[2]));
        for i in 0..n - 1 {
            let a = minco.eval(i, p.durations[i]).unwrap();
            let b = minco.eval(i + 1, 0.0).unwrap();
            prop_assert!(close(a.position, p.waypoints[i]), "waypoint {i}");
            prop_assert!(close(a.position, b.position), "position at junction {i}");
            prop_assert!(close(a.velocity, b.velocity), "velocity at junction {i}");
            prop_assert!(close(a.acceleration, b.acceleration), "acceleration at junction {i}");
            prop_assert!(close(a.jerk, b.jerk), "jerk at junction {i}");
            prop_assert!(close(a.snap, b.snap), "snap at junction {i}");
        }
    }

    /// The structure-aware solve and adjoint agree with the general banded LU on the same system.
    #[test]
    fn structured_solve_matches_the_general_banded_reference(p in problem(), seed in any::<u64>()) {
        let mut minco = p.solved();
        let (mut a, mut b) = minco.system();
        a.factorize().unwrap();
        a.solve_vec3(&mut b).unwrap();
        let scale = b.iter().map(|v| v.amax()).fold(1.0, f64::max);
        for (row, (got, want)) in minco.coeffs().iter().zip(&b).enumerate() {
            prop_assert!((got - want).amax() <= 1e-10 * scale, "coefficient row {row}");
        }
        let cost = TestCost::new(p.pieces(), seed);
        let (gc, gt) = cost.grads(minco.coeffs(), minco.durations());
        let mut grad = MincoGrad::new(p.pieces());
        minco.propagate_grad(&gc, &gt, &mut grad).unwrap();
        let mut adjoint = gc.clone();
        a.solve_transposed_vec3(&mut adjoint).unwrap();
        let scale = adjoint.iter().map(|v| v.amax()).fold(1.0, f64::max);
        for (row, (got, want)) in minco.adjoint().iter().zip(&adjoint).enumerate() {
            prop_assert!((got - want).amax() <= 1e-10 * scale, "adjoint row {row}");
        }
    }

    /// ∂E/∂q, ∂E/∂T, ∂E/∂tail and ∂E/∂head (explicit energy gradients + propagation) against
    /// central finite differences of the solved energy.
    #[test]
    fn energy_gradients_match_finite_differences(p in problem()) {
        let mut minco = p.solved();
        let mut grad = MincoGrad::new(p.pieces());
        minco.energy_and_grad(&mut grad).unwrap();
        check_all_gradients(&p, &grad, Problem::energy)?;
    }

    /// Propagation of an arbitrary cost K(c, T) with an explicit T term.
    #[test]
    fn propagation_of_an_arbitrary_cost_matches_finite_differences(
        p in problem(), seed in any::<u64>()
    ) {
        let cost = TestCost::new(p.pieces(), seed);
        let mut minco = p.solved();
        let (gc, gt) = cost.grads(minco.coeffs(), minco.durations());
        let mut grad = MincoGrad::new(p.pieces());
        minco.propagate_grad(&gc, &gt, &mut grad).unwrap();
        check_all_gradients(&p, &grad, |q| {
            let m = q.solved();
            cost.value(m.coeffs(), m.durations())
        })?;
    }

    /// Uniform durations T_i = T/n: ∂K/∂T = (1/n) Σ ∂K/∂T_i.
    #[test]
    fn uniform_total_duration_gradient_matches_finite_differences(
        p in problem(), total in 0.5f64..6.0
    ) {
        let n = p.pieces();
        let with_total = |t: f64| {
            let mut q = p.clone();
            q.durations = vec![t / n as f64; n];
            q
        };
        let base = with_total(total);
        let mut minco = base.solved();
        let mut grad = MincoGrad::new(n);
        minco.energy_and_grad(&mut grad).unwrap();
        let analytic = grad.uniform_total_duration();
        let floor = 1e-3 * max_abs(&grad) + 1e-6;
        check_fd("dE/dT_total", analytic, floor, 1e-6 * total, |e| with_total(total + e).energy())?;
    }
}

// ---------------------------------------------------------------------------------------------
// Degenerate and invalid input
// ---------------------------------------------------------------------------------------------

#[test]
fn single_piece_is_the_closed_form_minimum_jerk_move() {
    // Rest-to-rest move by d in time T: p(s) = d (10 s³ − 15 s⁴ + 6 s⁵), s = t/T, E = 720 d²/T⁵.
    let d = Vector3::new(3.0, -1.0, 2.0);
    let t = 1.7;
    let p = Problem {
        head: rest(Vector3::zeros()),
        tail: rest(d),
        waypoints: vec![],
        durations: vec![t],
    };
    let mut minco = p.solved();
    let c = minco.piece(0).unwrap();
    assert!((c[3] - d * (10.0 / t.powi(3))).amax() < 1e-12);
    assert!((c[4] - d * (-15.0 / t.powi(4))).amax() < 1e-12);
    assert!((c[5] - d * (6.0 / t.powi(5))).amax() < 1e-12);
    assert_rel(
        minco.energy(),
        720.0 * d.norm_squared() / t.powi(5),
        1e-12,
        "energy",
    );
    let mut grad = MincoGrad::new(1);
    minco.energy_and_grad(&mut grad).unwrap();
    assert!(grad.waypoints.is_empty());
    // E = 720 ‖tail − head‖²/T⁵ → ∂E/∂tail_p = 1440 d/T⁵, ∂E/∂T = −3600 ‖d‖²/T⁶.
    assert!((grad.tail[0] - d * (1440.0 / t.powi(5))).amax() < 1e-9);
    assert!((grad.head[0] + d * (1440.0 / t.powi(5))).amax() < 1e-9);
    assert_rel(
        grad.durations[0],
        -3600.0 * d.norm_squared() / t.powi(6),
        1e-12,
        "dE/dT",
    );
    assert_eq!(minco.to_pieces().len(), 1);
}

#[test]
fn zero_length_trajectory_has_zero_energy_and_gradient() {
    let q = Vector3::new(1.0, 2.0, 3.0);
    let n = 4;
    let p = Problem {
        head: rest(q),
        tail: rest(q),
        waypoints: vec![q; n - 1],
        durations: vec![0.4, 1.0, 0.7, 2.0],
    };
    let mut minco = p.solved();
    assert!(minco.energy().abs() < 1e-20, "energy {}", minco.energy());
    for piece in minco.to_pieces() {
        assert!((piece[0] - q).amax() < 1e-12);
        assert!(piece[1..].iter().all(|c| c.amax() < 1e-9));
    }
    let mut grad = MincoGrad::new(n);
    minco.energy_and_grad(&mut grad).unwrap();
    assert!(max_abs(&grad) < 1e-9, "gradient {grad:?}");
}

#[test]
fn very_short_durations_give_an_error_or_finite_numbers_never_nan() {
    for &t in &[1e-2, 1e-4, 1e-8, 1e-20, 1e-40, 1e-60, 1e-80, 1e-200, 1e-310] {
        for n in [1, 3] {
            let mut p = reference_problem(n);
            p.durations[0] = t;
            let mut minco = MincoS3::new(n).unwrap();
            match minco.solve(&p.head, &p.tail, &p.waypoints, &p.durations) {
                Ok(()) => {
                    assert!(minco.is_solved());
                    assert!(
                        minco
                            .coeffs()
                            .iter()
                            .all(|c| c.iter().all(|x| x.is_finite()))
                    );
                    assert!(
                        minco.energy().is_finite(),
                        "T = {t:e}: energy {}",
                        minco.energy()
                    );
                    let mut grad = MincoGrad::new(n);
                    if minco.energy_and_grad(&mut grad).is_ok() {
                        assert!(max_abs(&grad).is_finite(), "T = {t:e}: gradient {grad:?}");
                    }
                }
                Err(e) => {
                    assert!(
                        matches!(
                            e,
                            MincoError::SingularPivot { .. } | MincoError::NonFiniteResult { .. }
                        ),
                        "T = {t:e}: unexpected error {e}"
                    );
                    assert!(!minco.is_solved());
                    assert_eq!(minco.energy(), 0.0);
                    assert!(minco.coeffs().iter().all(|c| *c == Vector3::zeros()));
                    let mut grad = MincoGrad::new(n);
                    assert!(matches!(
                        minco.energy_and_grad(&mut grad),
                        Err(MincoError::NotSolved { .. })
                    ));
                }
            }
        }
    }
}

#[test]
fn invalid_input_is_rejected_with_the_field_named() {
    assert_eq!(
        MincoS3::new(0).unwrap_err(),
        MincoError::NoPieces { got: 0 }
    );
    let p = reference_problem(3);
    let mut minco = MincoS3::new(3).unwrap();

    let err = minco
        .solve(&p.head, &p.tail, &p.waypoints[..1], &p.durations)
        .unwrap_err();
    assert_eq!(
        err,
        MincoError::LengthMismatch {
            field: "waypoints",
            expected: 2,
            got: 1
        }
    );

    let err = minco
        .solve(&p.head, &p.tail, &p.waypoints, &p.durations[..2])
        .unwrap_err();
    assert!(matches!(
        err,
        MincoError::LengthMismatch {
            field: "durations",
            ..
        }
    ));

    let mut bad = p.clone();
    bad.waypoints[1].y = f64::NAN;
    let err = minco
        .solve(&bad.head, &bad.tail, &bad.waypoints, &bad.durations)
        .unwrap_err();
    assert!(matches!(
        err,
        MincoError::NonFiniteVector {
            field: "waypoints",
            index: 1,
            ..
        }
    ));
    assert!(
        err.to_string().starts_with("waypoints[1] = (4, NaN,"),
        "{err}"
    );

    let mut bad = p.clone();
    bad.tail[1].z = f64::INFINITY;
    let err = minco
        .solve(&bad.head, &bad.tail, &bad.waypoints, &bad.durations)
        .unwrap_err();
    assert!(matches!(
        err,
        MincoError::NonFiniteVector {
            field: "tail",
            index: 1,
            ..
        }
    ));

    for bad_t in [0.0, -0.5, f64::NAN, f64::INFINITY] {
        let mut bad = p.clone();
        bad.durations[2] = bad_t;
        let err = minco
            .solve(&bad.head, &bad.tail, &bad.waypoints, &bad.durations)
            .unwrap_err();
        assert!(
            matches!(err, MincoError::InvalidDuration { index: 2, .. }),
            "{err}"
        );
    }

    // Nothing was solved yet: propagation refuses.
    let mut grad = MincoGrad::new(3);
    let gc = vec![Vector3::zeros(); 18];
    let gt = vec![0.0; 3];
    assert!(matches!(
        minco.propagate_grad(&gc, &gt, &mut grad),
        Err(MincoError::NotSolved { .. })
    ));

    minco
        .solve(&p.head, &p.tail, &p.waypoints, &p.durations)
        .unwrap();
    assert!(matches!(
        minco.propagate_grad(&gc[..17], &gt, &mut grad),
        Err(MincoError::LengthMismatch {
            field: "grad_c",
            ..
        })
    ));
    assert!(matches!(
        minco.propagate_grad(&gc, &gt, &mut MincoGrad::new(2)),
        Err(MincoError::LengthMismatch { .. })
    ));
    let mut nan_gc = gc.clone();
    nan_gc[4].x = f64::NAN;
    assert!(matches!(
        minco.propagate_grad(&nan_gc, &gt, &mut grad),
        Err(MincoError::NonFiniteVector {
            field: "grad_c",
            index: 4,
            ..
        })
    ));
    assert!(matches!(
        minco.propagate_grad(&gc, &[0.0, f64::NAN, 0.0], &mut grad),
        Err(MincoError::NonFiniteScalar {
            field: "grad_t",
            index: 1,
            ..
        })
    ));
    assert!(minco.piece(3).is_none() && minco.eval(3, 0.0).is_none());
}

#[test]
fn pieces_evaluate_like_the_coefficient_rows() {
    let minco = reference_problem(4).solved();
    let pieces = minco.to_pieces();
    assert_eq!(pieces.len(), 4);
    let mut reused = Vec::new();
    minco.write_pieces(&mut reused);
    assert_eq!(pieces, reused);
    for (i, piece) in pieces.iter().enumerate() {
        assert_eq!(&minco.coeffs()[6 * i..6 * i + 6], piece.as_slice());
        assert_eq!(minco.eval(i, 0.2), Some(eval_piece(piece, 0.2)));
    }
    assert_rel(minco.total_duration(), 2.0, 1e-15, "total duration");
}

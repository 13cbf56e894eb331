//! Regression tests for the bugs `cargo xtask fuzz` (crates/fuzz) found, named after the bug.

use nalgebra::Vector3;
use trust_minco::{MincoError, MincoS3, eval_json, jerk_energy};

#[test]
fn jerk_energy_overflow_is_an_error_naming_the_piece() {
    // Fuzz: finite coefficients whose energy overflowed returned `inf`.
    let mut coeffs = vec![Vector3::zeros(); 12];
    coeffs[6 + 5] = Vector3::new(1e200, 0.0, 0.0);
    let e = jerk_energy(&coeffs, &[1.0, 1.0]).unwrap_err();
    assert!(
        matches!(e, MincoError::NonFiniteResult { index: 1, .. }),
        "{e:?}"
    );
}

#[test]
fn huge_piece_count_is_an_error_before_allocating() {
    for n in [
        usize::MAX,
        usize::MAX / 6 + 1,
        trust_minco::minco::MAX_PIECES + 1,
    ] {
        assert!(
            matches!(MincoS3::new(n), Err(MincoError::TooManyPieces { .. })),
            "{n}"
        );
    }
}

#[test]
fn eval_json_with_1e300_waypoints_never_prints_nan() {
    let input = r#"{"head": [[0,0,0],[0,0,0],[0,0,0]], "tail": [[1e300,0,0],[0,0,0],[0,0,0]],
                    "waypoints": [[-1e300, 1e300, 0]], "durations": [1e-300, 1]}"#;
    match eval_json(input) {
        Ok(out) => assert!(!out.contains("NaN") && !out.contains("null"), "{out}"),
        Err(e) => assert!(!e.to_string().is_empty()),
    }
}

#[test]
fn tiny_speed_limit_names_the_limit_not_an_infinite_cost() {
    // Issue 11: `v_max = 1e-300` gave "cost at the start point = inf" without naming the limit.
    use trust_core::{
        Aabb, GuidePath, InitialGuess, Limits, Scene, State, StaticMap, TrajRequest,
        TrajectoryBackend, Vec3,
    };
    let map =
        StaticMap::new(Aabb::new(Vec3::repeat(-100.0), Vec3::repeat(100.0)).unwrap()).unwrap();
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let guide = GuidePath::new(vec![Vec3::zeros(), Vec3::new(50.0, 0.0, 0.0)]).unwrap();
    for (v_max, a_max) in [(1e-300, 1.0), (1e-9, 1e-9), (1e-6, 1.0)] {
        let req = TrajRequest {
            start: State::at_rest(0.0, Vec3::zeros()),
            goal: Vec3::new(50.0, 0.0, 0.0),
            limits: Limits { v_max, a_max },
            initial: InitialGuess::Guide(&guide),
            deadline: None,
            horizon_s: None,
            max_evaluations: Some(50),
        };
        for backend in [
            &trust_minco::UtfMinco::default() as &dyn TrajectoryBackend,
            &trust_minco::Minco::default(),
        ] {
            match backend.optimize(&req, &scene) {
                Err(e) => {
                    let msg = e.to_string();
                    assert!(msg.contains("v_max"), "{}: {msg}", backend.name());
                }
                Ok(sol) => assert!(sol.costs.total.is_finite(), "{}", backend.name()),
            }
        }
    }
}

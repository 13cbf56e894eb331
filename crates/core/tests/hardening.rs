//! Regression tests for the bugs `cargo xtask fuzz` (crates/fuzz) and issue 11 found at the edges of
//! f64, each named after the bug.

use trust_core::{GuidePath, Limits, PlanError, PolyTraj, State, Vec3};

fn line() -> PolyTraj {
    let mut piece = [Vec3::zeros(); 6];
    piece[1] = Vec3::new(1.0, 0.0, 0.0);
    PolyTraj::new(0.0, vec![10.0], vec![piece]).unwrap()
}

#[test]
fn position_of_nan_time_is_rejected_by_the_checked_accessors() {
    // Issue 11: `position(NaN)` returned a point instead of saying the time is not a number.
    let traj = line();
    let e = traj.checked_position(f64::NAN).unwrap_err();
    assert!(e.to_string().contains("NaN"), "{e}");
    assert!(traj.checked_state(f64::NAN).is_err());
    // The plain accessor maps NaN to the start, with a finite time (it was NaN).
    let s = traj.state(f64::NAN);
    assert_eq!(s.t, traj.t_start());
}

#[test]
fn sampling_at_a_picosecond_step_is_a_count_error_not_an_oom() {
    // Issue 11: allocation until the process was killed.
    let traj = line();
    let e = traj.sample_positions(1e-12).unwrap_err();
    assert!(matches!(e, PlanError::Count(_)), "{e:?}");
    assert!(e.to_string().contains("dt_s"), "{e}");
    assert!(traj.for_each_sample(1e-300, |_, _| {}).is_err());
}

#[test]
fn huge_sample_counts_are_capped() {
    let traj = line();
    assert!((traj.arc_length(usize::MAX) - 10.0).abs() < 1e-9);
    let (v, _) = traj.max_speed_and_acceleration(usize::MAX);
    assert!((v - 1.0).abs() < 1e-12);
    let path = GuidePath::new(vec![Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0)]).unwrap();
    assert!(path.try_resample(usize::MAX).is_err());
    assert_eq!(
        path.resample(usize::MAX).len(),
        trust_core::scale::MAX_SAMPLE_COUNT
    );
}

#[test]
fn out_of_scale_inputs_name_the_field_in_scientific_notation() {
    // Issue 11: huge values were printed as 300-digit decimals.
    let e = GuidePath::new(vec![Vec3::new(0.0, 1e300, 0.0)]).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("path.points[0].y"), "{msg}");
    assert!(msg.contains("1.0e300"), "{msg}");
    assert!(msg.len() < 200, "{msg}");
    let e = Limits::new(1e-300, 1.0).unwrap_err();
    assert!(e.to_string().contains("limits.v_max"), "{e}");
    let e = PolyTraj::hold(f64::MAX, Vec3::zeros(), 1.0).unwrap_err();
    assert!(e.to_string().contains("traj.t_start"), "{e}");
    let s = State::at_rest(0.0, Vec3::new(0.0, 0.0, -2e6));
    assert!(
        s.validate("start")
            .unwrap_err()
            .to_string()
            .contains("start.p.z")
    );
}

#[test]
fn trajectory_whose_derivatives_overflow_is_rejected() {
    let mut piece = [Vec3::zeros(); 6];
    piece[5] = Vec3::new(1e20, 0.0, 0.0);
    let e = PolyTraj::new(0.0, vec![1e5], vec![piece]).unwrap_err();
    assert!(e.to_string().contains("traj.pieces[0]"), "{e}");
}

#[test]
fn empty_guide_path_built_by_hand_is_caught_by_validate() {
    let path = GuidePath { points: vec![] };
    assert!(path.validate("guide").is_err());
    // And its accessors do not panic.
    assert_eq!(path.start(), Vec3::zeros());
    assert!(path.resample(4).is_empty());
}

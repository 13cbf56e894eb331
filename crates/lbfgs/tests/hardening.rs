//! Regression tests for the bugs `cargo xtask fuzz` (crates/fuzz) found, named after the bug.

use trust_lbfgs::{
    Lbfgs, LbfgsError, LbfgsParams, MAX_DIMENSION, MAX_MEMORY, MAX_WORKSPACE_FLOATS, minimize,
};

#[test]
fn huge_past_is_an_error_not_an_allocation_failure() {
    // Fuzz (params::ekf+lbfgs+scenes): `past = u64::MAX` aborted on allocation.
    let params = LbfgsParams {
        past: usize::MAX,
        ..LbfgsParams::default()
    };
    assert!(params.validate().unwrap_err().to_string().contains("past"));
}

#[test]
fn huge_memory_is_an_error_not_a_capacity_overflow_panic() {
    for memory in [usize::MAX, MAX_MEMORY + 1] {
        let params = LbfgsParams {
            memory,
            ..LbfgsParams::default()
        };
        let e = params.validate().unwrap_err();
        assert!(e.to_string().contains("memory"), "{e}");
        let mut x = [1.0, 2.0];
        assert!(
            minimize(
                &mut x,
                |x, g| {
                    g.copy_from_slice(x);
                    0.5 * (x[0] * x[0] + x[1] * x[1])
                },
                &params
            )
            .is_err()
        );
    }
}

#[test]
fn lbfgs_new_usize_max_dimension_is_an_error_not_a_capacity_overflow_panic() {
    // Issue 18: `Lbfgs::new(usize::MAX, …)` panicked with "capacity overflow".
    let e = Lbfgs::new(usize::MAX, LbfgsParams::default()).unwrap_err();
    assert!(
        matches!(
            e,
            LbfgsError::DimensionTooLarge {
                dimension: usize::MAX,
                cap: MAX_DIMENSION
            }
        ),
        "{e:?}"
    );
    let msg = e.to_string();
    assert!(
        msg.contains("dimension") && msg.contains("MAX_DIMENSION"),
        "{msg}"
    );
    assert!(!has_long_digit_run(&msg), "{msg}");
}

#[test]
fn lbfgs_new_2_pow_40_dimension_is_an_error_not_a_70_tb_allocation() {
    // Issue 18: `Lbfgs::new(1 << 40, …)` aborted the process allocating 70 TB.
    for dimension in [1usize << 40, MAX_DIMENSION + 1] {
        let e = Lbfgs::new(dimension, LbfgsParams::default()).unwrap_err();
        assert!(
            matches!(e, LbfgsError::DimensionTooLarge { .. }),
            "{dimension}: {e:?}"
        );
    }
    // The cap itself is accepted with the default memory.
    let solver = Lbfgs::new(MAX_DIMENSION, LbfgsParams::default()).unwrap();
    assert_eq!(solver.dimension(), MAX_DIMENSION);
}

#[test]
fn large_memory_times_dimension_is_a_workspace_error_naming_both() {
    let params = LbfgsParams {
        memory: MAX_MEMORY,
        ..LbfgsParams::default()
    };
    let e = Lbfgs::new(MAX_DIMENSION, params.clone()).unwrap_err();
    assert!(matches!(e, LbfgsError::WorkspaceTooLarge { .. }), "{e:?}");
    let msg = e.to_string();
    assert!(msg.contains("dimension") && msg.contains("memory"), "{msg}");
    assert!(!has_long_digit_run(&msg), "{msg}");
    // Below the workspace cap the same memory is fine.
    assert!(Lbfgs::new(20_000, params).is_ok());
    const { assert!(MAX_WORKSPACE_FLOATS >= (2 * 8 + 6) * MAX_DIMENSION + 3 * 8 + 3) };
}

/// True if `s` has a run of more than 17 decimal digits (an unreadable number).
fn has_long_digit_run(s: &str) -> bool {
    let mut run = 0;
    for c in s.chars() {
        run = if c.is_ascii_digit() { run + 1 } else { 0 };
        if run > 17 {
            return true;
        }
    }
    false
}

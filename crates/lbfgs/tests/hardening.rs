//! Regression tests for the bugs `cargo xtask fuzz` (crates/fuzz) found, named after the bug.

use trust_lbfgs::{LbfgsParams, MAX_MEMORY, minimize};

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

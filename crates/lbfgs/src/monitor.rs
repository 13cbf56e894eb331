//! Per-iteration observation and cancellation.

use std::time::{Duration, Instant};

/// What the solver reports to a [`Monitor`] after each accepted step.
#[derive(Debug, Clone, Copy)]
pub struct Progress<'a> {
    /// Number of completed iterations (1 at the first call).
    pub iteration: usize,
    /// Number of cost evaluations so far, the one at the start point included.
    pub evaluation_count: usize,
    /// Cost at the current point.
    pub cost: f64,
    /// `‖g‖∞` at the current point.
    pub grad_inf_norm: f64,
    /// Step length accepted by this iteration's line search.
    pub step: f64,
    /// The current point.
    pub x: &'a [f64],
    /// The gradient at the current point.
    pub gradient: &'a [f64],
}

/// Observes the solver once per iteration and may cancel it.
///
/// The no-op implementation is `()`: pass `&mut ()` when you need no monitoring.
pub trait Monitor {
    /// Called once after each accepted step. Return `false` to stop the solve; it then ends with
    /// [`crate::Termination::Cancelled`] at the current point (unless the same iteration also met a
    /// convergence test, which is reported instead).
    fn keep_going(&mut self, progress: &Progress<'_>) -> bool {
        let _ = progress;
        true
    }
}

impl Monitor for () {}

/// Cancels the solve at the first iteration that ends at or after a deadline.
///
/// The deadline is checked once per iteration, so a solve overruns it by at most one iteration
/// (one line search, at most `max_linesearch` evaluations).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Deadline {
    /// The instant after which the solve is cancelled.
    pub at: Instant,
}

impl Deadline {
    /// A deadline at `at`.
    pub fn new(at: Instant) -> Self {
        Self { at }
    }

    /// A deadline `budget` from now.
    pub fn after(budget: Duration) -> Self {
        Self {
            at: Instant::now() + budget,
        }
    }
}

impl Monitor for Deadline {
    fn keep_going(&mut self, _progress: &Progress<'_>) -> bool {
        Instant::now() < self.at
    }
}

/// A [`Monitor`] made from a closure; build one with [`monitor_fn`].
#[derive(Debug, Clone, Copy)]
pub struct FnMonitor<F>(pub F);

impl<F> Monitor for FnMonitor<F>
where
    F: FnMut(&Progress<'_>) -> bool,
{
    fn keep_going(&mut self, progress: &Progress<'_>) -> bool {
        (self.0)(progress)
    }
}

/// Wraps a closure `|progress| -> keep_going` as a [`Monitor`].
///
/// ```
/// use trust_lbfgs::{monitor_fn, Progress};
/// let mut costs = Vec::new();
/// let mut monitor = monitor_fn(|p: &Progress<'_>| {
///     costs.push(p.cost);
///     p.iteration < 10
/// });
/// # let _ = &mut monitor;
/// ```
pub fn monitor_fn<F>(f: F) -> FnMonitor<F>
where
    F: FnMut(&Progress<'_>) -> bool,
{
    FnMonitor(f)
}

//! Piecewise-polynomial trajectories (paper eq. Polynomials): quintic pieces in ascending powers of local
//! time, the output of every [`crate::TrajectoryBackend`].

use serde::{Deserialize, Serialize};

use trust_geometry::scale::{self, Quantity};

use crate::error::{check_finite, check_finite_vec, check_positive, check_scaled};
use crate::{PlanError, State, Vec3};

/// Largest accepted bound on any derivative (orders 0 to 5) of a piece over its duration:
/// `Σ_{k≥r} k!/(k−r)!·‖c_k‖_∞·T^{k−r} ≤ MAX_DERIVATIVE_BOUND` for every order `r`. It keeps every
/// evaluation, sample, arc length and energy of an accepted trajectory finite (scale policy,
/// [`crate::scale`]).
pub const MAX_DERIVATIVE_BOUND: f64 = 1.0e30;

/// Coefficients of one quintic piece, ascending powers: `p(s) = Σ_k c[k] s^k`, `s ∈ [0, T_i]`.
pub type Piece = [Vec3; 6];

/// Derivative order for [`PolyTraj::derivative`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Derivative {
    /// Position (order 0).
    Position,
    /// Velocity (order 1).
    Velocity,
    /// Acceleration (order 2).
    Acceleration,
    /// Jerk (order 3).
    Jerk,
    /// Snap (order 4).
    Snap,
}

impl Derivative {
    fn order(self) -> usize {
        match self {
            Derivative::Position => 0,
            Derivative::Velocity => 1,
            Derivative::Acceleration => 2,
            Derivative::Jerk => 3,
            Derivative::Snap => 4,
        }
    }
}

/// Evaluates the `order`-th derivative of one piece at local time `s` (Horner's rule).
pub fn eval_piece(piece: &Piece, order: usize, s: f64) -> Vec3 {
    // Falling-factorial factors k!/(k-order)! for k = order..=5.
    let mut acc = Vec3::zeros();
    for k in (order..6).rev() {
        let mut factor = 1.0;
        for j in 0..order {
            factor *= (k - j) as f64;
        }
        acc = acc * s + piece[k] * factor;
    }
    acc
}

/// A piecewise quintic trajectory starting at absolute time `t_start`.
///
/// Invariants (checked by [`PolyTraj::new`]): at least one piece, durations finite and `> 0`, all
/// coefficients finite. Evaluation outside `[t_start, t_end]` clamps to the ends (a vehicle that has
/// reached the end of its plan holds the final state of the polynomial, not its extrapolation).
///
/// Serializes as `{"t_start", "durations", "pieces"}`; deserializing validates like [`PolyTraj::new`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawPolyTraj", into = "RawPolyTraj")]
pub struct PolyTraj {
    t_start: f64,
    durations: Vec<f64>,
    pieces: Vec<Piece>,
    /// Cumulative end times relative to `t_start`, for O(log n) lookup.
    ends: Vec<f64>,
}

/// The serialized form of [`PolyTraj`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPolyTraj {
    t_start: f64,
    durations: Vec<f64>,
    pieces: Vec<Piece>,
}

impl TryFrom<RawPolyTraj> for PolyTraj {
    type Error = PlanError;
    fn try_from(raw: RawPolyTraj) -> Result<Self, PlanError> {
        PolyTraj::new(raw.t_start, raw.durations, raw.pieces)
    }
}

impl From<PolyTraj> for RawPolyTraj {
    fn from(tr: PolyTraj) -> Self {
        RawPolyTraj {
            t_start: tr.t_start,
            durations: tr.durations,
            pieces: tr.pieces,
        }
    }
}

impl PolyTraj {
    /// A validated trajectory: finite numbers inside the scale policy ([`crate::scale`]): `t_start`
    /// a time, durations in `[1e-9, 1e7]` s with a total of at most `1e7` s, at most
    /// [`scale::MAX_VERTEX_COUNT`] pieces, and every derivative bounded by
    /// [`MAX_DERIVATIVE_BOUND`] over its piece.
    pub fn new(t_start: f64, durations: Vec<f64>, pieces: Vec<Piece>) -> Result<Self, PlanError> {
        check_scaled("traj.t_start", t_start, Quantity::Time)?;
        scale::check_count(
            "traj.durations.len()",
            durations.len() as u128,
            scale::MAX_VERTEX_COUNT,
        )?;
        if durations.is_empty() {
            return Err(PlanError::invalid(
                "traj.durations",
                "[]",
                "at least one piece",
            ));
        }
        if durations.len() != pieces.len() {
            return Err(PlanError::invalid(
                "traj.pieces",
                format!("{} pieces", pieces.len()),
                format!("one piece per duration ({})", durations.len()),
            ));
        }
        for (i, &d) in durations.iter().enumerate() {
            check_positive(&format!("traj.durations[{i}]"), d)?;
            check_scaled(
                &format!("traj.durations[{i}]"),
                d,
                Quantity::PositiveDuration,
            )?;
        }
        for (i, piece) in pieces.iter().enumerate() {
            for (k, c) in piece.iter().enumerate() {
                check_finite_vec(&format!("traj.pieces[{i}][{k}]"), c)?;
            }
            let bound = derivative_bound(piece, durations[i]);
            if bound > MAX_DERIVATIVE_BOUND {
                return Err(PlanError::invalid(
                    format!("traj.pieces[{i}]"),
                    format!(
                        "coefficients whose derivatives reach {} over the piece's {} s",
                        scale::Sci(bound),
                        scale::Sci(durations[i])
                    ),
                    format!(
                        "every derivative bounded by {} (scale policy)",
                        scale::Sci(MAX_DERIVATIVE_BOUND)
                    ),
                ));
            }
        }
        let ends = cumulative(&durations);
        let total = ends.last().copied().unwrap_or(0.0);
        check_scaled("traj total duration", total, Quantity::Duration)?;
        check_scaled("traj.t_end", t_start + total, Quantity::Time)?;
        Ok(PolyTraj {
            t_start,
            durations,
            pieces,
            ends,
        })
    }

    /// A trajectory that holds position `p` (zero velocity) for `duration` seconds from `t_start`.
    pub fn hold(t_start: f64, p: Vec3, duration: f64) -> Result<Self, PlanError> {
        let mut piece = [Vec3::zeros(); 6];
        piece[0] = p;
        PolyTraj::new(t_start, vec![duration], vec![piece])
    }

    /// Absolute start time (s).
    pub fn t_start(&self) -> f64 {
        self.t_start
    }

    /// Absolute end time (s).
    pub fn t_end(&self) -> f64 {
        self.t_start + self.duration()
    }

    /// Total duration (s).
    pub fn duration(&self) -> f64 {
        *self.ends.last().unwrap_or(&0.0)
    }

    /// Number of pieces.
    pub fn piece_count(&self) -> usize {
        self.pieces.len()
    }

    /// Piece durations (s).
    pub fn durations(&self) -> &[f64] {
        &self.durations
    }

    /// Piece coefficients (ascending powers of local time).
    pub fn pieces(&self) -> &[Piece] {
        &self.pieces
    }

    /// The piece index and local time for absolute time `t` (clamped to the trajectory's span).
    pub fn locate(&self, t: f64) -> (usize, f64) {
        let rel = if t.is_finite() {
            (t - self.t_start).clamp(0.0, self.duration())
        } else if t == f64::INFINITY {
            self.duration()
        } else {
            0.0
        };
        // First piece whose end is >= rel.
        let i = self
            .ends
            .partition_point(|&e| e < rel)
            .min(self.pieces.len() - 1);
        let begin = if i == 0 { 0.0 } else { self.ends[i - 1] };
        (i, (rel - begin).clamp(0.0, self.durations[i]))
    }

    /// The derivative `which` at absolute time `t` (clamped).
    pub fn derivative(&self, which: Derivative, t: f64) -> Vec3 {
        let (i, s) = self.locate(t);
        eval_piece(&self.pieces[i], which.order(), s)
    }

    /// Position, velocity and acceleration at absolute time `t`, rejecting a NaN time instead of
    /// clamping it (the plain [`PolyTraj::state`] maps NaN to the start).
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] naming `t` if it is NaN.
    pub fn checked_state(&self, t: f64) -> Result<State, PlanError> {
        if t.is_nan() {
            return Err(PlanError::invalid("t", t, "a time, not NaN"));
        }
        Ok(self.state(t))
    }

    /// Position at absolute time `t`, rejecting a NaN time (see [`PolyTraj::checked_state`]).
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] naming `t` if it is NaN.
    pub fn checked_position(&self, t: f64) -> Result<Vec3, PlanError> {
        Ok(self.checked_state(t)?.p)
    }

    /// Position at absolute time `t` (clamped to the span; a NaN time gives the start: use
    /// [`PolyTraj::checked_position`] to have it rejected).
    pub fn position(&self, t: f64) -> Vec3 {
        self.derivative(Derivative::Position, t)
    }

    /// Velocity at absolute time `t`.
    pub fn velocity(&self, t: f64) -> Vec3 {
        self.derivative(Derivative::Velocity, t)
    }

    /// Acceleration at absolute time `t`.
    pub fn acceleration(&self, t: f64) -> Vec3 {
        self.derivative(Derivative::Acceleration, t)
    }

    /// Jerk at absolute time `t`.
    pub fn jerk(&self, t: f64) -> Vec3 {
        self.derivative(Derivative::Jerk, t)
    }

    /// Snap at absolute time `t`.
    pub fn snap(&self, t: f64) -> Vec3 {
        self.derivative(Derivative::Snap, t)
    }

    /// Position, velocity and acceleration at absolute time `t` as a [`State`].
    pub fn state(&self, t: f64) -> State {
        let (i, s) = self.locate(t);
        let piece = &self.pieces[i];
        State {
            // A NaN time maps to the start, as in `locate`.
            t: if t.is_nan() {
                self.t_start
            } else {
                t.clamp(self.t_start, self.t_end())
            },
            p: eval_piece(piece, 0, s),
            v: eval_piece(piece, 1, s),
            a: eval_piece(piece, 2, s),
        }
    }

    /// Calls `f(t, state)` at `t_start, t_start + dt, …` and always at `t_end`. `dt` must be `> 0`
    /// and give at most [`scale::MAX_SAMPLE_COUNT`] samples.
    ///
    /// # Errors
    /// [`PlanError`] naming `dt_s` if it is not a positive duration, [`PlanError::Count`] if the
    /// duration divided by `dt` exceeds the sample cap.
    pub fn for_each_sample(
        &self,
        dt: f64,
        mut f: impl FnMut(f64, &State),
    ) -> Result<(), PlanError> {
        check_positive("dt_s", dt)?;
        let ratio = (self.duration() / dt).floor();
        // Saturating conversion (the ratio is non-negative here, possibly +inf; 1e30 is far
        // above the cap and leaves room for the + 1).
        let steps = scale::check_count(
            "samples (trajectory duration / dt_s)",
            ratio.min(1e30) as u128 + 1,
            scale::MAX_SAMPLE_COUNT,
        )? - 1;
        for k in 0..=steps {
            let t = self.t_start + k as f64 * dt;
            f(t, &self.state(t));
        }
        if (steps as f64) * dt < self.duration() {
            f(self.t_end(), &self.state(self.t_end()));
        }
        Ok(())
    }

    /// Positions sampled every `dt` seconds (and at the end), with their times.
    pub fn sample_positions(&self, dt: f64) -> Result<Vec<(f64, Vec3)>, PlanError> {
        let mut out = Vec::new();
        self.for_each_sample(dt, |t, s| out.push((t, s.p)))?;
        Ok(out)
    }

    /// Arc length, by Simpson's rule on `samples_per_piece` (even, at least 2) intervals per piece.
    /// The total number of samples is capped at [`scale::MAX_SAMPLE_COUNT`] (fewer per piece).
    pub fn arc_length(&self, samples_per_piece: usize) -> f64 {
        let m = self
            .capped_per_piece(samples_per_piece)
            .max(2)
            .next_multiple_of(2);
        let mut total = 0.0;
        for (piece, &d) in self.pieces.iter().zip(&self.durations) {
            let h = d / m as f64;
            let mut acc = 0.0;
            for j in 0..=m {
                let w = if j == 0 || j == m {
                    1.0
                } else if j % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                acc += w * eval_piece(piece, 1, j as f64 * h).norm();
            }
            total += acc * h / 3.0;
        }
        total
    }

    /// The same trajectory shifted to start at `t_start`.
    pub fn with_start_time(mut self, t_start: f64) -> Result<Self, PlanError> {
        check_finite("traj.t_start", t_start)?;
        check_scaled("traj.t_start", t_start, Quantity::Time)?;
        check_scaled("traj.t_end", t_start + self.duration(), Quantity::Time)?;
        self.t_start = t_start;
        Ok(self)
    }

    /// `samples_per_piece`, reduced so that all pieces together take at most
    /// [`scale::MAX_SAMPLE_COUNT`] samples.
    fn capped_per_piece(&self, samples_per_piece: usize) -> usize {
        samples_per_piece.min(scale::MAX_SAMPLE_COUNT / self.pieces.len().max(1))
    }

    /// The largest speed and acceleration norm over `samples_per_piece + 1` samples per piece
    /// (the total capped at [`scale::MAX_SAMPLE_COUNT`], fewer per piece).
    pub fn max_speed_and_acceleration(&self, samples_per_piece: usize) -> (f64, f64) {
        let m = self.capped_per_piece(samples_per_piece).max(1);
        let mut v_max: f64 = 0.0;
        let mut a_max: f64 = 0.0;
        for (piece, &d) in self.pieces.iter().zip(&self.durations) {
            for j in 0..=m {
                let s = d * j as f64 / m as f64;
                v_max = v_max.max(eval_piece(piece, 1, s).norm());
                a_max = a_max.max(eval_piece(piece, 2, s).norm());
            }
        }
        (v_max, a_max)
    }
}

/// `max_r Σ_{k≥r} k!/(k−r)!·‖c_k‖_∞·T^{k−r}`: bounds every derivative of the piece over `[0, T]`.
fn derivative_bound(piece: &Piece, duration: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for r in 0..6 {
        let mut sum = 0.0;
        for (k, c) in piece.iter().enumerate().skip(r) {
            let falling: f64 = ((k - r + 1)..=k).map(|j| j as f64).product();
            sum += falling * c.amax() * duration.powi((k - r) as i32);
        }
        if sum.is_nan() {
            return f64::INFINITY;
        }
        worst = worst.max(sum);
    }
    worst
}

fn cumulative(durations: &[f64]) -> Vec<f64> {
    durations
        .iter()
        .scan(0.0, |acc, d| {
            *acc += d;
            Some(*acc)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    fn line(v: Vec3, durations: Vec<f64>) -> PolyTraj {
        // Constant velocity, continuous across pieces.
        let mut pieces = Vec::new();
        let mut p = Vec3::zeros();
        for &d in &durations {
            let mut c = [Vec3::zeros(); 6];
            c[0] = p;
            c[1] = v;
            pieces.push(c);
            p += v * d;
        }
        PolyTraj::new(1.0, durations, pieces).unwrap()
    }

    #[test]
    fn constant_velocity_is_evaluated_everywhere() {
        let v = Vec3::new(1.0, -2.0, 0.5);
        let tr = line(v, vec![0.5, 1.0, 0.25]);
        assert_relative_eq!(tr.duration(), 1.75);
        assert_relative_eq!(tr.t_end(), 2.75);
        for &t in &[1.0, 1.3, 1.5, 2.0, 2.6, 2.75] {
            assert_relative_eq!(tr.position(t), v * (t - 1.0), epsilon = 1e-12);
            assert_relative_eq!(tr.velocity(t), v, epsilon = 1e-12);
            assert_relative_eq!(tr.acceleration(t), Vec3::zeros(), epsilon = 1e-12);
        }
        // Clamped outside the span.
        assert_relative_eq!(tr.position(-5.0), Vec3::zeros());
        assert_relative_eq!(tr.position(50.0), v * 1.75, epsilon = 1e-12);
        assert_relative_eq!(tr.position(f64::NAN), Vec3::zeros());
        assert_relative_eq!(tr.arc_length(8), v.norm() * 1.75, epsilon = 1e-9);
    }

    #[test]
    fn rejects_invalid_pieces() {
        let c = [Vec3::zeros(); 6];
        assert!(PolyTraj::new(0.0, vec![], vec![]).is_err());
        assert!(PolyTraj::new(0.0, vec![1.0], vec![c, c]).is_err());
        let e = PolyTraj::new(0.0, vec![1.0, 0.0], vec![c, c])
            .unwrap_err()
            .to_string();
        assert!(e.contains("traj.durations[1]"), "{e}");
        let mut bad = c;
        bad[3].z = f64::NAN;
        let e = PolyTraj::new(0.0, vec![1.0], vec![bad])
            .unwrap_err()
            .to_string();
        assert!(e.contains("traj.pieces[0][3]"), "{e}");
    }

    #[test]
    fn serde_round_trip_validates() {
        let tr = line(Vec3::new(1.0, 0.0, 0.0), vec![0.5, 0.5]);
        let text = serde_json::to_string(&tr).unwrap();
        let back: PolyTraj = serde_json::from_str(&text).unwrap();
        assert_eq!(back, tr);
        assert_relative_eq!(back.position(1.75), Vec3::new(0.75, 0.0, 0.0));
        let bad = text.replace("0.5", "-0.5");
        assert!(serde_json::from_str::<PolyTraj>(&bad).is_err());
    }

    #[test]
    fn sampling_includes_the_end() {
        let tr = PolyTraj::hold(0.0, Vec3::new(1.0, 1.0, 1.0), 1.05).unwrap();
        let s = tr.sample_positions(0.5).unwrap();
        let times: Vec<f64> = s.iter().map(|x| x.0).collect();
        assert_eq!(times.len(), 4);
        assert_relative_eq!(times[3], 1.05);
        assert!(tr.sample_positions(0.0).is_err());
    }

    proptest! {
        /// Derivatives from `eval_piece` match central differences of the next-lower order.
        #[test]
        fn derivatives_match_finite_differences(
            coeffs in prop::array::uniform6(prop::array::uniform3(-3.0..3.0f64)),
            s in 0.1..1.9f64,
        ) {
            let piece: Piece = coeffs.map(|c| Vec3::new(c[0], c[1], c[2]));
            let h = 1e-5;
            for order in 1..5 {
                let fd = trust_numdiff::central_difference(|x| eval_piece(&piece, order - 1, x), s, h);
                let an = eval_piece(&piece, order, s);
                prop_assert!((fd - an).norm() <= 1e-5 * (1.0 + an.norm()), "order {order}: {fd:?} vs {an:?}");
            }
        }
    }
}

//! [`Curve`]: what a [`crate::HomotopyChecker`] compares — untimed paths and timed trajectories alike.

use crate::{GuidePath, PolyTraj, Vec3};

/// A spatial curve, optionally timed.
///
/// Uniform visibility deformation (UVD) matches two curves by arc-length fraction and needs only
/// [`Curve::resample_by_arc_length`]; temporal visibility deformation (TVD, paper Sec. III-A) matches
/// them at the same absolute time and needs [`Curve::time_span`] and [`Curve::position_at_time`].
pub trait Curve {
    /// Length of the curve (m).
    fn length(&self) -> f64;

    /// Writes `count` (at least 2) points evenly spaced by arc length, ends included, into `out`
    /// (cleared first).
    fn resample_by_arc_length(&self, count: usize, out: &mut Vec<Vec3>);

    /// Absolute start and end time (s) for a timed curve, `None` for an untimed path.
    fn time_span(&self) -> Option<(f64, f64)>;

    /// Position at absolute time `t` (clamped to the span) for a timed curve, `None` if untimed.
    fn position_at_time(&self, t: f64) -> Option<Vec3>;
}

impl Curve for GuidePath {
    fn length(&self) -> f64 {
        GuidePath::length(self)
    }

    fn resample_by_arc_length(&self, count: usize, out: &mut Vec<Vec3>) {
        self.resample_into(count, out);
    }

    fn time_span(&self) -> Option<(f64, f64)> {
        None
    }

    fn position_at_time(&self, _t: f64) -> Option<Vec3> {
        None
    }
}

/// Intervals per piece used to integrate a trajectory's arc length for [`Curve`] queries.
const ARC_SAMPLES_PER_PIECE: usize = 16;

impl Curve for PolyTraj {
    fn length(&self) -> f64 {
        self.arc_length(ARC_SAMPLES_PER_PIECE)
    }

    fn resample_by_arc_length(&self, count: usize, out: &mut Vec<Vec3>) {
        // Dense polyline of the trajectory, then uniform resampling of that polyline.
        let dense_count = self.piece_count() * ARC_SAMPLES_PER_PIECE + 1;
        let dt = self.duration() / (dense_count - 1) as f64;
        let points: Vec<Vec3> = (0..dense_count)
            .map(|k| self.position(self.t_start() + k as f64 * dt))
            .collect();
        GuidePath { points }.resample_into(count, out);
    }

    fn time_span(&self) -> Option<(f64, f64)> {
        Some((self.t_start(), self.t_end()))
    }

    fn position_at_time(&self, t: f64) -> Option<Vec3> {
        Some(self.position(t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn trajectory_and_path_agree_on_a_straight_line() {
        let mut c = [Vec3::zeros(); 6];
        c[1] = Vec3::new(2.0, 0.0, 0.0);
        let tr = PolyTraj::new(
            0.0,
            vec![1.0, 1.0],
            vec![c, {
                let mut d = c;
                d[0] = Vec3::new(2.0, 0.0, 0.0);
                d
            }],
        )
        .unwrap();
        let path = GuidePath::new(vec![Vec3::zeros(), Vec3::new(4.0, 0.0, 0.0)]).unwrap();
        assert_relative_eq!(Curve::length(&tr), 4.0, epsilon = 1e-9);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        tr.resample_by_arc_length(9, &mut a);
        path.resample_by_arc_length(9, &mut b);
        for (p, q) in a.iter().zip(&b) {
            assert_relative_eq!(p, q, epsilon = 1e-9);
        }
        assert_eq!(tr.time_span(), Some((0.0, 2.0)));
        assert_eq!(path.time_span(), None);
        assert_eq!(path.position_at_time(0.0), None);
    }
}

//! What the exporters read: the planner's [`PolyTraj`], or raw pieces checked into one.

use trust_core::{Piece, PolyTraj};

use crate::error::FlightStackError;

/// A [`PolyTraj`] from raw parts (`t_start` in s, one duration per quintic piece, coefficients in
/// ascending powers of local time), for pieces that did not come out of our planner.
///
/// Pieces of duration exactly `0.0` cover no time and are dropped; everything else is checked by
/// [`PolyTraj::new`]: at least one piece left, durations in `[1e-9, 1e7]` s, finite coefficients
/// whose derivatives stay within [`trust_core::MAX_DERIVATIVE_BOUND`].
///
/// # Errors
/// [`FlightStackError::InvalidInput`] if the lengths differ; [`FlightStackError::Trajectory`]
/// naming the field (`traj.durations`, `traj.pieces[i][k]`, …) for everything else.
pub fn trajectory_from_parts(
    t_start: f64,
    durations: &[f64],
    pieces: &[Piece],
) -> Result<PolyTraj, FlightStackError> {
    if durations.len() != pieces.len() {
        return Err(FlightStackError::invalid(
            "pieces",
            format!("{} pieces", pieces.len()),
            format!("one piece per duration ({})", durations.len()),
        ));
    }
    let (kept_durations, kept_pieces): (Vec<f64>, Vec<Piece>) = durations
        .iter()
        .zip(pieces)
        .filter(|(d, _)| **d != 0.0)
        .map(|(d, p)| (*d, *p))
        .unzip();
    Ok(PolyTraj::new(t_start, kept_durations, kept_pieces)?)
}

/// Checks that `t` (named `field`) lies in `[traj.t_start(), traj.t_end()]`.
pub(crate) fn check_time(traj: &PolyTraj, field: &str, t: f64) -> Result<(), FlightStackError> {
    if t.is_nan() {
        return Err(FlightStackError::invalid(field, t, "a time (s), not NaN"));
    }
    if t < traj.t_start() || t > traj.t_end() {
        return Err(FlightStackError::TimeOutside {
            field: field.to_string(),
            t,
            t_start: traj.t_start(),
            t_end: traj.t_end(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use trust_core::Vec3;

    fn piece(p0: f64) -> Piece {
        let mut c = [Vec3::zeros(); 6];
        c[0] = Vec3::new(p0, 0.0, 1.0);
        c[1] = Vec3::new(1.0, 0.0, 0.0);
        c
    }

    #[test]
    fn zero_duration_pieces_are_dropped() {
        let tr =
            trajectory_from_parts(2.0, &[1.0, 0.0, 0.5], &[piece(0.0), piece(9.0), piece(1.0)])
                .unwrap();
        assert_eq!(tr.piece_count(), 2);
        assert_eq!(tr.durations(), &[1.0, 0.5]);
    }

    #[test]
    fn invalid_parts_are_typed_errors() {
        let e = trajectory_from_parts(0.0, &[], &[]).unwrap_err();
        assert!(matches!(e, FlightStackError::Trajectory(_)), "{e}");
        let e = trajectory_from_parts(0.0, &[0.0], &[piece(0.0)]).unwrap_err();
        assert!(e.to_string().contains("at least one piece"), "{e}");
        let e = trajectory_from_parts(0.0, &[1.0], &[]).unwrap_err();
        assert!(e.to_string().contains("pieces"), "{e}");
        let e = trajectory_from_parts(0.0, &[-1.0], &[piece(0.0)]).unwrap_err();
        assert!(e.to_string().contains("traj.durations[0]"), "{e}");
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut p = piece(0.0);
            p[4].y = bad;
            let e = trajectory_from_parts(0.0, &[1.0], &[p]).unwrap_err();
            assert!(e.to_string().contains("traj.pieces[0][4]"), "{e}");
            let e = trajectory_from_parts(0.0, &[bad], &[piece(0.0)]).unwrap_err();
            assert!(e.to_string().contains("traj.durations[0]"), "{e}");
        }
    }

    #[test]
    fn times_outside_are_refused() {
        let tr = trajectory_from_parts(1.0, &[1.0], &[piece(0.0)]).unwrap();
        check_time(&tr, "t", 1.0).unwrap();
        check_time(&tr, "t", 2.0).unwrap();
        for t in [0.999, 2.001, f64::INFINITY, f64::NEG_INFINITY] {
            let e = check_time(&tr, "t", t).unwrap_err();
            assert!(matches!(e, FlightStackError::TimeOutside { .. }), "{e}");
        }
        assert!(
            check_time(&tr, "t", f64::NAN)
                .unwrap_err()
                .to_string()
                .contains("NaN")
        );
    }
}

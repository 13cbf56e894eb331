//! Crazyflie: the firmware's `poly4d` pieces (x, y, z, yaw polynomials of degree 7 and a
//! duration), the Crazyswarm `uav_trajectories` CSV, and the Crazyswarm2 upload message.
//!
//! Our pieces are quintics in local time `s ∈ [0, T]` (ascending powers, [`trust_core::Piece`]);
//! the firmware's are one degree-7 polynomial per axis, also in local time and ascending powers
//! (`pptraj.h`: `PP_DEGREE 7`, `p[0]` the constant term). So the conversion pads `s⁶` and `s⁷`
//! with zeros and rounds to `f32`, nothing else.

use serde::{Deserialize, Serialize};
use std::io::Write;
use trust_core::{PolyTraj, Vec3, eval_piece};

use crate::error::{FlightStackError, to_f32};
use crate::frame::{FrameTransform, wrap_angle};
use crate::yaw::{YawPolicy, YawTracker};

/// Bytes of the firmware's trajectory memory (`TRAJECTORY_MEMORY_SIZE 4096` in
/// `src/modules/src/crtp_commander_high_level.c`, bitcraze/crazyflie-firmware release 2026.08).
pub const TRAJECTORY_MEMORY_BYTES: usize = 4096;

/// Bytes of one `struct poly4d` (`float p[4][8]; float duration;`, `pptraj.h`): 33 × 4.
pub const POLY4D_BYTES: usize = 4 * (4 * POLY4D_COEFFICIENTS + 1);

/// Coefficients per axis: degree 7 (`PP_SIZE` in `pptraj.h`).
pub const POLY4D_COEFFICIENTS: usize = 8;

/// The most `poly4d` pieces the trajectory memory holds: 4096 / 132 = 31 (the firmware's comment:
/// "4k allows us to store 31 poly4d pieces"). All trajectories on one Crazyflie share it.
pub const MAX_POLY4D_PIECES: usize = TRAJECTORY_MEMORY_BYTES / POLY4D_BYTES;

/// The most pieces one trajectory definition can name (`uint8_t nPieces` of
/// `crtpCommanderHighLevelDefineTrajectory`), the cap for firmware built with more memory.
pub const MAX_DEFINED_PIECES: usize = u8::MAX as usize;

/// The header of the Crazyswarm `uav_trajectories` CSV (as `genTrajectory` writes it; the
/// loaders skip the first row).
pub const UAV_TRAJECTORIES_CSV_HEADER: &str = "Duration,x^0,x^1,x^2,x^3,x^4,x^5,x^6,x^7,\
y^0,y^1,y^2,y^3,y^4,y^5,y^6,y^7,z^0,z^1,z^2,z^3,z^4,z^5,z^6,z^7,\
yaw^0,yaw^1,yaw^2,yaw^3,yaw^4,yaw^5,yaw^6,yaw^7";

/// One piece of a Crazyflie trajectory, as the firmware's `struct poly4d` holds it: per axis the
/// coefficients of a degree-7 polynomial in ascending powers of local time `s ∈ [0, duration]`
/// (m, and rad for yaw), in the Crazyflie's world frame (right-handed, z up, yaw from +x
/// counter-clockwise).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Poly4d {
    /// x(s) (m).
    pub x: [f32; POLY4D_COEFFICIENTS],
    /// y(s) (m).
    pub y: [f32; POLY4D_COEFFICIENTS],
    /// z(s) (m).
    pub z: [f32; POLY4D_COEFFICIENTS],
    /// yaw(s) (rad, not wrapped: continuous across pieces).
    pub yaw: [f32; POLY4D_COEFFICIENTS],
    /// Duration (s).
    pub duration: f32,
}

/// A [`Poly4d`] evaluated at one local time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Poly4dSample {
    /// Position (m).
    pub position: Vec3,
    /// Velocity (m/s).
    pub velocity: Vec3,
    /// Acceleration (m/s²).
    pub acceleration: Vec3,
    /// Yaw (rad, as the polynomial gives it: not wrapped).
    pub yaw_rad: f64,
    /// Yaw rate (rad/s).
    pub yaw_rate_rad_s: f64,
}

/// The `order`-th derivative of `Σ c[k] s^k` at `s`, in `f64` (Horner's rule).
pub fn poly_derivative(c: &[f32; POLY4D_COEFFICIENTS], order: usize, s: f64) -> f64 {
    let mut acc = 0.0;
    for k in (order..POLY4D_COEFFICIENTS).rev() {
        let falling: f64 = ((k + 1 - order)..=k).map(|j| j as f64).product();
        acc = acc * s + f64::from(c[k]) * falling;
    }
    acc
}

impl Poly4d {
    /// Position, velocity, acceleration and yaw at local time `s` (not clamped), computed in
    /// `f64` from the `f32` coefficients: what the piece stands for, without the firmware's
    /// `f32` arithmetic.
    pub fn evaluate(&self, s: f64) -> Poly4dSample {
        let axes = |order| {
            Vec3::new(
                poly_derivative(&self.x, order, s),
                poly_derivative(&self.y, order, s),
                poly_derivative(&self.z, order, s),
            )
        };
        Poly4dSample {
            position: axes(0),
            velocity: axes(1),
            acceleration: axes(2),
            yaw_rad: poly_derivative(&self.yaw, 0, s),
            yaw_rate_rad_s: poly_derivative(&self.yaw, 1, s),
        }
    }

    /// Checks that every number is finite and the duration `> 0`, naming `field.x[k]` etc.
    pub fn validate(&self, field: &str) -> Result<(), FlightStackError> {
        if !(self.duration.is_finite() && self.duration > 0.0) {
            return Err(FlightStackError::invalid(
                format!("{field}.duration"),
                self.duration,
                "a finite duration > 0 (s)",
            ));
        }
        for (axis, c) in [
            ("x", &self.x),
            ("y", &self.y),
            ("z", &self.z),
            ("yaw", &self.yaw),
        ] {
            if let Some(k) = c.iter().position(|v| !v.is_finite()) {
                return Err(FlightStackError::invalid(
                    format!("{field}.{axis}[{k}]"),
                    c[k],
                    "a finite coefficient",
                ));
            }
        }
        Ok(())
    }
}

/// How a trajectory becomes Crazyflie pieces.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrazyflieParams {
    /// Our world frame → the Crazyflie's world frame (both z up); the identity by default.
    pub world_to_crazyflie: FrameTransform,
    /// The yaw policy (default: hold 0 rad). [`YawPolicy::Uncontrolled`] is refused: `poly4d`
    /// always carries a yaw. [`YawPolicy::FaceVelocity`] is evaluated at the piece boundaries
    /// and each piece's yaw is the straight line between its two ends (unwrapped, so yaw is
    /// continuous across pieces): exact at the boundaries, an approximation inside a piece.
    pub yaw: YawPolicy,
    /// The most pieces the upload may have (default [`MAX_POLY4D_PIECES`], 31, the stock
    /// firmware's memory; at most [`MAX_DEFINED_PIECES`]).
    pub max_pieces: usize,
}

impl Default for CrazyflieParams {
    fn default() -> Self {
        Self {
            world_to_crazyflie: FrameTransform::identity(),
            yaw: YawPolicy::default(),
            max_pieces: MAX_POLY4D_PIECES,
        }
    }
}

impl CrazyflieParams {
    /// Checks every field, naming it (`world_to_crazyflie.yaw_rad`, `yaw`, `max_pieces`).
    pub fn validate(&self) -> Result<(), FlightStackError> {
        self.world_to_crazyflie.validate("world_to_crazyflie")?;
        self.yaw.validate("yaw")?;
        if self.yaw == YawPolicy::Uncontrolled {
            return Err(FlightStackError::Unsupported {
                target: "Crazyflie poly4d",
                what: "an uncontrolled yaw (`yaw.kind = uncontrolled`): choose `fixed` or \
                       `face_velocity`"
                    .into(),
            });
        }
        if !(1..=MAX_DEFINED_PIECES).contains(&self.max_pieces) {
            return Err(FlightStackError::invalid(
                "max_pieces",
                self.max_pieces,
                format!("1 ..= {MAX_DEFINED_PIECES} (uint8 nPieces)"),
            ));
        }
        Ok(())
    }
}

/// The trajectory as Crazyflie pieces: one [`Poly4d`] per quintic piece, positions mapped by
/// `params.world_to_crazyflie` (exact: a rotation and a shift of the coefficients) and padded to
/// degree 7, yaw per `params.yaw`. Start it on the Crazyflie when our clock reads
/// `traj.t_start()`.
///
/// # Errors
/// Invalid `params` ([`CrazyflieParams::validate`], [`FlightStackError::Unsupported`] for an
/// uncontrolled yaw); [`FlightStackError::TooManyPieces`] above `params.max_pieces` (fly a shorter
/// horizon, or upload the rest as a second trajectory when the first is done);
/// [`FlightStackError::NotRepresentable`] naming `pieces[i].x[k]` etc. for a value beyond `f32`.
pub fn to_poly4d(
    traj: &PolyTraj,
    params: &CrazyflieParams,
) -> Result<Vec<Poly4d>, FlightStackError> {
    params.validate()?;
    if traj.piece_count() > params.max_pieces {
        return Err(FlightStackError::TooManyPieces {
            field: "traj.piece_count()".into(),
            count: traj.piece_count(),
            max: params.max_pieces,
            target: "the Crazyflie trajectory memory (max_pieces)",
        });
    }
    let tf = &params.world_to_crazyflie;
    let yaws = boundary_yaws(traj, params)?;
    let mut out = Vec::with_capacity(traj.piece_count());
    for (i, (piece, &duration)) in traj.pieces().iter().zip(traj.durations()).enumerate() {
        let mut axes = [[0.0f32; POLY4D_COEFFICIENTS]; 3];
        for (k, c) in piece.iter().enumerate() {
            let v = if k == 0 { tf.point(c) } else { tf.vector(c) };
            for (a, name) in ["x", "y", "z"].iter().enumerate() {
                axes[a][k] = to_f32(|| format!("pieces[{i}].{name}[{k}]"), v[a])?;
            }
        }
        let mut yaw = [0.0f32; POLY4D_COEFFICIENTS];
        yaw[0] = to_f32(|| format!("pieces[{i}].yaw[0]"), yaws[i])?;
        yaw[1] = to_f32(
            || format!("pieces[{i}].yaw[1]"),
            (yaws[i + 1] - yaws[i]) / duration,
        )?;
        let [x, y, z] = axes;
        out.push(Poly4d {
            x,
            y,
            z,
            yaw,
            duration: to_f32(|| format!("pieces[{i}].duration"), duration)?,
        });
    }
    Ok(out)
}

/// The yaw at each of the `n + 1` piece boundaries in the Crazyflie's frame, unwrapped so that
/// consecutive values differ by at most π.
fn boundary_yaws(traj: &PolyTraj, params: &CrazyflieParams) -> Result<Vec<f64>, FlightStackError> {
    let mut tracker = YawTracker::new(params.yaw)?;
    // The first piece at its start, then every piece at its end.
    let states = traj
        .pieces()
        .first()
        .map(|p| (p, 0.0))
        .into_iter()
        .chain(traj.pieces().iter().zip(traj.durations().iter().copied()));
    let mut yaws: Vec<f64> = Vec::with_capacity(traj.piece_count() + 1);
    for (piece, s) in states {
        let sample = tracker
            .next(&eval_piece(piece, 1, s), &eval_piece(piece, 2, s))
            .ok_or_else(|| FlightStackError::Unsupported {
                target: "Crazyflie poly4d",
                what: "an uncontrolled yaw".into(),
            })?;
        let wrapped = wrap_angle(params.world_to_crazyflie.yaw(sample.yaw_rad));
        let yaw = match yaws.last() {
            None => wrapped,
            Some(&prev) => prev + wrap_angle(wrapped - prev),
        };
        yaws.push(yaw);
    }
    Ok(yaws)
}

/// Writes `pieces` as a Crazyswarm `uav_trajectories` CSV: the header
/// [`UAV_TRAJECTORIES_CSV_HEADER`], then one row per piece (duration, then the eight x, y, z and
/// yaw coefficients), each number the shortest decimal that reads back as the same `f32`.
///
/// # Errors
/// [`FlightStackError::InvalidInput`] naming `pieces[i]…` for a non-finite number or a duration
/// `≤ 0` ([`Poly4d::validate`]); [`FlightStackError::Io`] if writing fails.
pub fn write_uav_trajectories_csv(
    pieces: &[Poly4d],
    out: &mut impl Write,
) -> Result<(), FlightStackError> {
    for (i, p) in pieces.iter().enumerate() {
        p.validate(&format!("pieces[{i}]"))?;
    }
    let io = |source| FlightStackError::Io {
        what: "uav_trajectories CSV",
        source,
    };
    writeln!(out, "{UAV_TRAJECTORIES_CSV_HEADER}").map_err(io)?;
    for p in pieces {
        let mut row = p.duration.to_string();
        for c in [&p.x, &p.y, &p.z, &p.yaw] {
            for v in c {
                row.push(',');
                row.push_str(&v.to_string());
            }
        }
        writeln!(out, "{row}").map_err(io)?;
    }
    Ok(())
}

/// [`write_uav_trajectories_csv`] into a string.
///
/// # Errors
/// As [`write_uav_trajectories_csv`].
pub fn uav_trajectories_csv(pieces: &[Poly4d]) -> Result<String, FlightStackError> {
    let mut buf = Vec::new();
    write_uav_trajectories_csv(pieces, &mut buf)?;
    // Only ASCII digits, signs, letters and punctuation were written.
    Ok(String::from_utf8_lossy(&buf).into_owned())
}

/// `builtin_interfaces/msg/Duration`: `int32 sec`, `uint32 nanosec`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct RosDuration {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds, `< 1e9`.
    pub nanosec: u32,
}

impl RosDuration {
    /// `seconds` rounded to the nanosecond.
    ///
    /// # Errors
    /// [`FlightStackError::InvalidInput`] naming `field` unless `0 ≤ seconds < 2³¹` s.
    pub fn from_seconds(field: &str, seconds: f64) -> Result<Self, FlightStackError> {
        if !(seconds.is_finite() && (0.0..f64::from(i32::MAX)).contains(&seconds)) {
            return Err(FlightStackError::invalid(
                field,
                seconds,
                "a finite duration in [0, 2^31) s",
            ));
        }
        // Below 2.2e18 ns: exact enough and inside i64.
        let ns = (seconds * 1e9).round() as i64;
        let sec = ns.div_euclid(1_000_000_000);
        let nanosec = ns.rem_euclid(1_000_000_000);
        Ok(Self {
            // sec < 2^31 by the check above (rounding up adds at most one second below it).
            sec: i32::try_from(sec).unwrap_or(i32::MAX),
            nanosec: nanosec as u32,
        })
    }

    /// The duration in seconds.
    pub fn as_seconds(&self) -> f64 {
        f64::from(self.sec) + f64::from(self.nanosec) * 1e-9
    }
}

/// Crazyswarm2's `crazyflie_interfaces/msg/TrajectoryPolynomialPiece`, field for field and in the
/// message's order: `float32[] poly_x, poly_y, poly_z, poly_yaw` (eight coefficients each, as the
/// Crazyswarm2 server requires) and `builtin_interfaces/Duration duration`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrajectoryPolynomialPiece {
    /// x coefficients, ascending powers.
    pub poly_x: Vec<f32>,
    /// y coefficients.
    pub poly_y: Vec<f32>,
    /// z coefficients.
    pub poly_z: Vec<f32>,
    /// yaw coefficients.
    pub poly_yaw: Vec<f32>,
    /// The piece's duration.
    pub duration: RosDuration,
}

impl TryFrom<&Poly4d> for TrajectoryPolynomialPiece {
    type Error = FlightStackError;

    /// The message of one piece; the duration is the `f32` duration rounded to the nanosecond.
    fn try_from(p: &Poly4d) -> Result<Self, FlightStackError> {
        p.validate("piece")?;
        Ok(Self {
            poly_x: p.x.to_vec(),
            poly_y: p.y.to_vec(),
            poly_z: p.z.to_vec(),
            poly_yaw: p.yaw.to_vec(),
            duration: RosDuration::from_seconds("piece.duration", f64::from(p.duration))?,
        })
    }
}

/// The request of Crazyswarm2's `crazyflie_interfaces/srv/UploadTrajectory`: `uint8
/// trajectory_id`, `uint32 piece_offset`, `TrajectoryPolynomialPiece[] pieces`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UploadTrajectoryRequest {
    /// Which trajectory (the id `StartTrajectory` names).
    pub trajectory_id: u8,
    /// Where in the trajectory memory the pieces go, counted in pieces.
    pub piece_offset: u32,
    /// The pieces.
    pub pieces: Vec<TrajectoryPolynomialPiece>,
}

/// The upload request for `pieces` at `piece_offset`, refused if they would not fit in
/// `max_pieces` pieces of trajectory memory (use [`MAX_POLY4D_PIECES`] for stock firmware).
///
/// # Errors
/// [`FlightStackError::TooManyPieces`] if `piece_offset + pieces.len() > max_pieces`;
/// [`FlightStackError::InvalidInput`] for an empty `pieces` or a piece with a non-finite number.
pub fn upload_trajectory_request(
    trajectory_id: u8,
    piece_offset: u32,
    pieces: &[Poly4d],
    max_pieces: usize,
) -> Result<UploadTrajectoryRequest, FlightStackError> {
    if pieces.is_empty() {
        return Err(FlightStackError::invalid(
            "pieces",
            "[]",
            "at least one piece",
        ));
    }
    let end = piece_offset as usize + pieces.len();
    if end > max_pieces {
        return Err(FlightStackError::TooManyPieces {
            field: "piece_offset + pieces.len()".into(),
            count: end,
            max: max_pieces,
            target: "the Crazyflie trajectory memory (max_pieces)",
        });
    }
    let pieces = pieces
        .iter()
        .enumerate()
        .map(|(i, p)| {
            p.validate(&format!("pieces[{i}]"))?;
            TrajectoryPolynomialPiece::try_from(p)
        })
        .collect::<Result<_, _>>()?;
    Ok(UploadTrajectoryRequest {
        trajectory_id,
        piece_offset,
        pieces,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::{FRAC_PI_2, PI};
    use trust_core::Piece;

    fn line(v: Vec3, durations: &[f64]) -> PolyTraj {
        let mut p = Vec3::new(0.5, -0.5, 1.0);
        let pieces = durations
            .iter()
            .map(|&d| {
                let mut c: Piece = [Vec3::zeros(); 6];
                c[0] = p;
                c[1] = v;
                p += v * d;
                c
            })
            .collect();
        PolyTraj::new(0.0, durations.to_vec(), pieces).unwrap()
    }

    #[test]
    fn the_memory_holds_31_pieces() {
        assert_eq!(POLY4D_BYTES, 132);
        assert_eq!(MAX_POLY4D_PIECES, 31);
        assert_eq!(UAV_TRAJECTORIES_CSV_HEADER.split(',').count(), 33);
        assert!(UAV_TRAJECTORIES_CSV_HEADER.starts_with("Duration,x^0,"));
        assert!(UAV_TRAJECTORIES_CSV_HEADER.ends_with(",yaw^6,yaw^7"));
    }

    #[test]
    fn quintic_is_padded_exactly() {
        let mut c: Piece = [Vec3::zeros(); 6];
        for (k, ck) in c.iter_mut().enumerate() {
            *ck = Vec3::new(k as f64 + 0.5, -(k as f64), 0.25 * k as f64);
        }
        let tr = PolyTraj::new(3.0, vec![0.75], vec![c]).unwrap();
        let p = to_poly4d(&tr, &CrazyflieParams::default()).unwrap();
        assert_eq!(p.len(), 1);
        assert_eq!(p[0].duration, 0.75);
        assert_eq!(p[0].x, [0.5, 1.5, 2.5, 3.5, 4.5, 5.5, 0.0, 0.0]);
        assert_eq!(p[0].y, [0.0, -1.0, -2.0, -3.0, -4.0, -5.0, 0.0, 0.0]);
        assert_eq!(p[0].z, [0.0, 0.25, 0.5, 0.75, 1.0, 1.25, 0.0, 0.0]);
        assert_eq!(p[0].yaw, [0.0; 8]);
        for s in [0.0, 0.3, 0.75] {
            let e = p[0].evaluate(s);
            assert_relative_eq!(e.position, tr.position(3.0 + s), epsilon = 1e-12);
            assert_relative_eq!(e.velocity, tr.velocity(3.0 + s), epsilon = 1e-12);
            assert_relative_eq!(e.acceleration, tr.acceleration(3.0 + s), epsilon = 1e-12);
        }
    }

    #[test]
    fn the_transform_moves_the_coefficients() {
        let tr = line(Vec3::new(1.0, 0.0, 0.0), &[1.0]);
        let params = CrazyflieParams {
            world_to_crazyflie: FrameTransform {
                yaw_rad: FRAC_PI_2,
                offset_m: Vec3::new(0.0, 0.0, 0.5),
            },
            yaw: YawPolicy::Fixed { yaw_rad: 0.25 },
            ..CrazyflieParams::default()
        };
        let p = to_poly4d(&tr, &params).unwrap();
        let e = p[0].evaluate(1.0);
        // (1.5, −0.5, 1) rotated a quarter turn, then lifted.
        assert_relative_eq!(e.position, Vec3::new(0.5, 1.5, 1.5), epsilon = 1e-6);
        assert_relative_eq!(e.velocity, Vec3::new(0.0, 1.0, 0.0), epsilon = 1e-6);
        assert_relative_eq!(e.yaw_rad, 0.25 + FRAC_PI_2, epsilon = 1e-6);
        assert_eq!(e.yaw_rate_rad_s, 0.0);
    }

    #[test]
    fn facing_the_velocity_is_continuous_and_unwrapped() {
        // West, then at rest, then east-south-east: the boundary yaws are π, π, π and
        // atan2(−0.1, 1) ≈ −0.0997 rad, which from π is nearer counter-clockwise (+3.04 rad, to
        // 2π − 0.0997) than clockwise (−3.24 rad).
        let mut pieces = Vec::new();
        for v in [
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::zeros(),
            Vec3::new(1.0, -0.1, 0.0),
        ] {
            let mut c: Piece = [Vec3::zeros(); 6];
            c[1] = v;
            pieces.push(c);
        }
        let tr = PolyTraj::new(0.0, vec![1.0, 1.0, 1.0], pieces).unwrap();
        let params = CrazyflieParams {
            yaw: YawPolicy::FaceVelocity {
                min_speed_m_s: 0.05,
                initial_yaw_rad: 0.0,
            },
            ..CrazyflieParams::default()
        };
        let p = to_poly4d(&tr, &params).unwrap();
        let ends: Vec<(f64, f64)> = p
            .iter()
            .map(|q| {
                (
                    q.evaluate(0.0).yaw_rad,
                    q.evaluate(f64::from(q.duration)).yaw_rad,
                )
            })
            .collect();
        // Continuous across pieces.
        for w in ends.windows(2) {
            assert_relative_eq!(w[0].1, w[1].0, epsilon = 1e-6);
        }
        assert_relative_eq!(ends[0].0, PI, epsilon = 1e-6);
        assert_relative_eq!(ends[1].1, PI, epsilon = 1e-6);
        let step = ends[2].1 - ends[2].0;
        assert_relative_eq!(step, PI - 0.1f64.atan(), epsilon = 1e-6);
        assert_relative_eq!(wrap_angle(ends[2].1), (-0.1f64).atan2(1.0), epsilon = 1e-6);
    }

    #[test]
    fn limits_and_unsupported_settings_are_typed_errors() {
        let tr = line(Vec3::new(0.1, 0.0, 0.0), &[0.5; 32]);
        let e = to_poly4d(&tr, &CrazyflieParams::default()).unwrap_err();
        assert!(
            matches!(
                e,
                FlightStackError::TooManyPieces {
                    count: 32,
                    max: 31,
                    ..
                }
            ),
            "{e}"
        );
        let more = CrazyflieParams {
            max_pieces: 32,
            ..CrazyflieParams::default()
        };
        assert_eq!(to_poly4d(&tr, &more).unwrap().len(), 32);
        for max_pieces in [0, 256] {
            let bad = CrazyflieParams {
                max_pieces,
                ..CrazyflieParams::default()
            };
            assert!(
                to_poly4d(&tr, &bad)
                    .unwrap_err()
                    .to_string()
                    .contains("max_pieces")
            );
        }
        let uncontrolled = CrazyflieParams {
            yaw: YawPolicy::Uncontrolled,
            ..CrazyflieParams::default()
        };
        let e = to_poly4d(&tr, &uncontrolled).unwrap_err();
        assert!(matches!(e, FlightStackError::Unsupported { .. }), "{e}");
    }

    #[test]
    fn csv_rows_read_back_as_the_same_f32() {
        let tr = line(Vec3::new(0.1, 0.2, -0.3), &[0.7, 1.3]);
        let p = to_poly4d(&tr, &CrazyflieParams::default()).unwrap();
        let text = uav_trajectories_csv(&p).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3);
        assert_eq!(lines[0], UAV_TRAJECTORIES_CSV_HEADER);
        for (line, piece) in lines[1..].iter().zip(&p) {
            let v: Vec<f32> = line.split(',').map(|x| x.parse().unwrap()).collect();
            assert_eq!(v.len(), 33);
            assert_eq!(v[0], piece.duration);
            assert_eq!(&v[1..9], &piece.x);
            assert_eq!(&v[25..33], &piece.yaw);
        }
        let mut bad = p[0];
        bad.z[3] = f32::NAN;
        let e = uav_trajectories_csv(&[p[1], bad]).unwrap_err();
        assert!(e.to_string().contains("pieces[1].z[3]"), "{e}");
        bad = p[0];
        bad.duration = 0.0;
        assert!(
            uav_trajectories_csv(&[bad])
                .unwrap_err()
                .to_string()
                .contains("duration")
        );
    }

    #[test]
    fn ros_durations_round_to_the_nanosecond() {
        let d = RosDuration::from_seconds("d", 1.25).unwrap();
        assert_eq!((d.sec, d.nanosec), (1, 250_000_000));
        let d = RosDuration::from_seconds("d", 2.999_999_999_7).unwrap();
        assert_eq!((d.sec, d.nanosec), (3, 0));
        assert_relative_eq!(
            RosDuration::from_seconds("d", 0.7).unwrap().as_seconds(),
            0.7
        );
        for bad in [-1.0, f64::NAN, f64::INFINITY, 3e9] {
            assert!(RosDuration::from_seconds("d", bad).is_err());
        }
    }

    #[test]
    fn upload_request_checks_the_memory() {
        let tr = line(Vec3::new(0.1, 0.0, 0.0), &[0.5; 3]);
        let p = to_poly4d(&tr, &CrazyflieParams::default()).unwrap();
        let req = upload_trajectory_request(1, 28, &p, MAX_POLY4D_PIECES).unwrap();
        assert_eq!(req.pieces.len(), 3);
        assert_eq!(req.pieces[0].poly_x.len(), 8);
        assert_eq!(
            req.pieces[2].duration,
            RosDuration {
                sec: 0,
                nanosec: 500_000_000
            }
        );
        let e = upload_trajectory_request(1, 29, &p, MAX_POLY4D_PIECES).unwrap_err();
        assert!(
            matches!(e, FlightStackError::TooManyPieces { count: 32, .. }),
            "{e}"
        );
        assert!(upload_trajectory_request(1, 0, &[], MAX_POLY4D_PIECES).is_err());
    }
}

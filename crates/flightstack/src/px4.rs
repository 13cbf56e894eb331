//! PX4: `px4_msgs/msg/TrajectorySetpoint` of [`PX4_RELEASE`] and the MAVLink
//! `SET_POSITION_TARGET_LOCAL_NED` it corresponds to, sampled from a trajectory in NED.

use serde::{Deserialize, Serialize};
use trust_core::scale::{self, MAX_SAMPLE_COUNT};
use trust_core::{PolyTraj, Vec3};

use crate::error::{FlightStackError, to_f32, vec_to_f32};
use crate::frame::{FrameTransform, enu_to_ned, yaw_enu_to_ned, yaw_rate_enu_to_ned};
use crate::input::check_time;
use crate::yaw::{YawPolicy, YawTracker};

/// The PX4 release whose `TrajectorySetpoint` layout [`TrajectorySetpoint`] mirrors
/// (`msg/TrajectorySetpoint.msg`, docs.px4.io/v1.15/en/msg_docs/TrajectorySetpoint). v1.14 has
/// the same fields; from v1.16 the file also declares the constant `MESSAGE_VERSION = 0`, a
/// constant and not a field.
pub const PX4_RELEASE: &str = "v1.15";

/// The slowest sampling rate accepted (Hz): PX4 leaves offboard mode unless setpoints (or
/// `OffboardControlMode`) keep arriving faster than 2 Hz (PX4 user guide, "Offboard Mode"), so
/// this is a floor; stream faster in practice (MAVSDK resends at 20 Hz).
pub const MIN_STREAM_RATE_HZ: f64 = 2.0;

/// The fastest sampling rate (Hz): one setpoint per microsecond, the timestamp's resolution.
pub const MAX_SAMPLE_RATE_HZ: f64 = 1.0e6;

/// `px4_msgs/msg/TrajectorySetpoint` of PX4 [`PX4_RELEASE`], field for field and in the message's
/// order (so a serde-based ROS 2 client can publish it as is): local NED frame, SI units, NaN
/// meaning "not controlled". Exports from this crate control position, velocity and
/// acceleration always and yaw/yawspeed per the [`YawPolicy`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrajectorySetpoint {
    /// `uint64 timestamp`: time since the flight controller's start (µs).
    pub timestamp: u64,
    /// `float32[3] position`: NED (m).
    pub position: [f32; 3],
    /// `float32[3] velocity`: NED (m/s).
    pub velocity: [f32; 3],
    /// `float32[3] acceleration`: NED (m/s²).
    pub acceleration: [f32; 3],
    /// `float32[3] jerk`: NED (m/s³), for logging only.
    pub jerk: [f32; 3],
    /// `float32 yaw`: from north, clockwise (rad, −π..π); NaN when not controlled.
    pub yaw: f32,
    /// `float32 yawspeed`: about NED's z axis (rad/s); NaN when not controlled.
    pub yawspeed: f32,
}

/// MAVLink `POSITION_TARGET_TYPEMASK` bit: ignore `x` (bit 1); `y`, `z`, `vx`, … follow in the
/// order of [`SetPositionTargetLocalNed`]'s fields, one bit each.
pub const TYPE_MASK_X_IGNORE: u16 = 1;
/// MAVLink `POSITION_TARGET_TYPEMASK_YAW_IGNORE` (bit 11, 1024).
pub const TYPE_MASK_YAW_IGNORE: u16 = 1 << 10;
/// MAVLink `POSITION_TARGET_TYPEMASK_YAW_RATE_IGNORE` (bit 12, 2048).
pub const TYPE_MASK_YAW_RATE_IGNORE: u16 = 1 << 11;
/// MAVLink `MAV_FRAME_LOCAL_NED`.
pub const MAV_FRAME_LOCAL_NED: u8 = 1;

/// The fields of MAVLink's `SET_POSITION_TARGET_LOCAL_NED` (message 84), in the order of its
/// definition (not its wire order, which a MAVLink library handles).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SetPositionTargetLocalNed {
    /// Time since system boot (ms).
    pub time_boot_ms: u32,
    /// System id of the vehicle.
    pub target_system: u8,
    /// Component id of the autopilot.
    pub target_component: u8,
    /// [`MAV_FRAME_LOCAL_NED`].
    pub coordinate_frame: u8,
    /// Which fields the vehicle ignores (`POSITION_TARGET_TYPEMASK`).
    pub type_mask: u16,
    /// North (m).
    pub x: f32,
    /// East (m).
    pub y: f32,
    /// Down (m).
    pub z: f32,
    /// North velocity (m/s).
    pub vx: f32,
    /// East velocity (m/s).
    pub vy: f32,
    /// Down velocity (m/s).
    pub vz: f32,
    /// North acceleration (m/s²).
    pub afx: f32,
    /// East acceleration (m/s²).
    pub afy: f32,
    /// Down acceleration (m/s²).
    pub afz: f32,
    /// Yaw (rad).
    pub yaw: f32,
    /// Yaw rate (rad/s).
    pub yaw_rate: f32,
}

impl TrajectorySetpoint {
    /// Whether yaw is controlled (not NaN).
    pub fn yaw_controlled(&self) -> bool {
        !self.yaw.is_nan()
    }

    /// The same setpoint as MAVLink `SET_POSITION_TARGET_LOCAL_NED` in `MAV_FRAME_LOCAL_NED`:
    /// each NaN field becomes its ignore bit (and 0 in the field), as PX4's MAVLink receiver maps
    /// an ignore bit back to NaN. This crate's setpoints give `type_mask = 0` with yaw controlled
    /// (position, velocity, acceleration, yaw and yaw rate) and
    /// `TYPE_MASK_YAW_IGNORE | TYPE_MASK_YAW_RATE_IGNORE` without. Jerk has no MAVLink field.
    /// `time_boot_ms` is the timestamp truncated to milliseconds.
    ///
    /// # Errors
    /// [`FlightStackError::NotRepresentable`] for a timestamp past `u32::MAX` ms (49.7 days);
    /// [`FlightStackError::InvalidInput`] for an infinite field.
    pub fn to_mavlink(
        &self,
        target_system: u8,
        target_component: u8,
    ) -> Result<SetPositionTargetLocalNed, FlightStackError> {
        let ms = self.timestamp / 1000;
        let time_boot_ms = u32::try_from(ms).map_err(|_| FlightStackError::NotRepresentable {
            field: "time_boot_ms".into(),
            value: ms as f64,
            target: "u32",
        })?;
        let fields = [
            ("position[0]", self.position[0]),
            ("position[1]", self.position[1]),
            ("position[2]", self.position[2]),
            ("velocity[0]", self.velocity[0]),
            ("velocity[1]", self.velocity[1]),
            ("velocity[2]", self.velocity[2]),
            ("acceleration[0]", self.acceleration[0]),
            ("acceleration[1]", self.acceleration[1]),
            ("acceleration[2]", self.acceleration[2]),
            ("yaw", self.yaw),
            ("yawspeed", self.yawspeed),
        ];
        let mut type_mask = 0u16;
        let mut values = [0.0f32; 11];
        for (bit, ((name, x), out)) in fields.iter().zip(values.iter_mut()).enumerate() {
            if x.is_nan() {
                // Bits 1..=9 for x..afz; bit 10 is FORCE_SET; yaw and yaw rate are bits 11, 12.
                let shift = if bit < 9 { bit } else { bit + 1 };
                type_mask |= 1 << shift;
            } else if x.is_infinite() {
                return Err(FlightStackError::invalid(
                    format!("setpoint.{name}"),
                    x,
                    "a finite number or NaN (not controlled)",
                ));
            } else {
                *out = *x;
            }
        }
        let [x, y, z, vx, vy, vz, afx, afy, afz, yaw, yaw_rate] = values;
        Ok(SetPositionTargetLocalNed {
            time_boot_ms,
            target_system,
            target_component,
            coordinate_frame: MAV_FRAME_LOCAL_NED,
            type_mask,
            x,
            y,
            z,
            vx,
            vy,
            vz,
            afx,
            afy,
            afz,
            yaw,
            yaw_rate,
        })
    }
}

/// How a trajectory becomes PX4 setpoints.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Px4Params {
    /// Our world frame → the ENU twin of PX4's local frame (same origin, x east, y north, z up);
    /// the identity by default (our world origin is PX4's local origin, our x is east).
    pub world_to_enu: FrameTransform,
    /// The yaw policy (default: hold 0 rad, see [`YawPolicy`]).
    pub yaw: YawPolicy,
}

impl Px4Params {
    /// Checks every field, naming it (`world_to_enu.offset_m`, `yaw.min_speed_m_s`, …).
    pub fn validate(&self) -> Result<(), FlightStackError> {
        self.world_to_enu.validate("world_to_enu")?;
        self.yaw.validate("yaw")
    }
}

/// The setpoint at absolute time `t` (s, inside the trajectory's span), stamped `timestamp_us`:
/// the trajectory's position, velocity, acceleration and jerk mapped by `world_to_enu` and then
/// to NED, with the yaw `yaw` gives (NaN if it does not control yaw).
///
/// Feed one `yaw` tracker the stream's times in order; a caller that wants to hold the end
/// state after the trajectory ends passes `t.min(traj.t_end())`.
///
/// # Errors
/// [`FlightStackError::TimeOutside`] or [`FlightStackError::InvalidInput`] for a time outside
/// the span or NaN; an invalid `world_to_enu`; [`FlightStackError::NotRepresentable`] naming the
/// field if a controlled value does not fit in `f32` (never NaN where a value is controlled).
pub fn setpoint_at(
    traj: &PolyTraj,
    t: f64,
    timestamp_us: u64,
    world_to_enu: &FrameTransform,
    yaw: &mut YawTracker,
) -> Result<TrajectorySetpoint, FlightStackError> {
    world_to_enu.validate("world_to_enu")?;
    check_time(traj, "t", t)?;
    setpoint_unchecked(traj, t, timestamp_us, world_to_enu, yaw)
}

/// [`setpoint_at`] after its checks.
fn setpoint_unchecked(
    traj: &PolyTraj,
    t: f64,
    timestamp_us: u64,
    world_to_enu: &FrameTransform,
    yaw: &mut YawTracker,
) -> Result<TrajectorySetpoint, FlightStackError> {
    let s = traj.state(t);
    let jerk = traj.jerk(t);
    let ned = |v: &Vec3| enu_to_ned(&world_to_enu.vector(v));
    let (yaw_ned, yawspeed_ned) = match yaw.next(&s.v, &s.a) {
        None => (f32::NAN, f32::NAN),
        Some(y) => (
            to_f32(|| "yaw".into(), yaw_enu_to_ned(world_to_enu.yaw(y.yaw_rad)))?,
            to_f32(|| "yawspeed".into(), yaw_rate_enu_to_ned(y.yaw_rate_rad_s))?,
        ),
    };
    Ok(TrajectorySetpoint {
        timestamp: timestamp_us,
        position: vec_to_f32("position", &enu_to_ned(&world_to_enu.point(&s.p)))?,
        velocity: vec_to_f32("velocity", &ned(&s.v))?,
        acceleration: vec_to_f32("acceleration", &ned(&s.a))?,
        jerk: vec_to_f32("jerk", &ned(&jerk))?,
        yaw: yaw_ned,
        yawspeed: yawspeed_ned,
    })
}

/// The times (s) of a stream at `rate_hz` over the trajectory: `t_start + k / rate_hz` for
/// `k = 0, 1, …` up to the end, and the end itself when the last of those falls more than 1 µs
/// short of it (so the stream always ends on the final state).
///
/// # Errors
/// [`FlightStackError::InvalidInput`] naming `rate_hz` unless it is finite and in
/// `[MIN_STREAM_RATE_HZ, MAX_SAMPLE_RATE_HZ]`; [`FlightStackError::Count`] above
/// [`trust_core::scale::MAX_SAMPLE_COUNT`] samples.
pub fn stream_times(traj: &PolyTraj, rate_hz: f64) -> Result<Vec<f64>, FlightStackError> {
    if !(rate_hz.is_finite() && (MIN_STREAM_RATE_HZ..=MAX_SAMPLE_RATE_HZ).contains(&rate_hz)) {
        return Err(FlightStackError::invalid(
            "rate_hz",
            rate_hz,
            format!(
                "a rate in [{MIN_STREAM_RATE_HZ}, {MAX_SAMPLE_RATE_HZ:e}] Hz (PX4 leaves offboard \
                 mode below 2 Hz; timestamps are whole µs)"
            ),
        ));
    }
    let duration = traj.duration();
    // duration ≤ 1e7 s and rate ≤ 1e6 Hz: the product is far below u128 range.
    let grid = (duration * rate_hz).floor() as u128 + 1;
    scale::check_count(
        "setpoints (duration × rate_hz + 2)",
        grid + 1,
        MAX_SAMPLE_COUNT,
    )?;
    let mut times: Vec<f64> = (0..grid)
        .map(|k| (k as f64 / rate_hz).min(duration))
        .collect();
    let last = times.last().copied().unwrap_or(0.0);
    if duration - last > 1e-6 {
        times.push(duration);
    }
    Ok(times.into_iter().map(|dt| traj.t_start() + dt).collect())
}

/// The setpoints of a stream at `rate_hz` over the whole trajectory ([`stream_times`]), the first
/// stamped `start_timestamp_us` (PX4's clock at the trajectory's `t_start`), the others
/// `start_timestamp_us + round((t − t_start) · 1e6)`.
///
/// Send them at their timestamps; PX4 needs the stream (or `OffboardControlMode`) faster than
/// [`MIN_STREAM_RATE_HZ`] before and during offboard mode, so keep sending (the last setpoint, or
/// the next plan's) after the trajectory ends.
///
/// # Errors
/// Invalid `params` or `rate_hz`, too many samples (see [`stream_times`]); a timestamp past
/// `u64::MAX`; a controlled value beyond `f32` ([`setpoint_at`]).
pub fn sample_setpoints(
    traj: &PolyTraj,
    start_timestamp_us: u64,
    rate_hz: f64,
    params: &Px4Params,
) -> Result<Vec<TrajectorySetpoint>, FlightStackError> {
    params.validate()?;
    let mut yaw = YawTracker::new(params.yaw)?;
    let times = stream_times(traj, rate_hz)?;
    times
        .iter()
        .map(|&t| {
            // t − t_start ≤ 1e7 s: at most 1e13 µs, exact in u64.
            let offset_us = ((t - traj.t_start()) * 1e6).round() as u64;
            let timestamp = start_timestamp_us.checked_add(offset_us).ok_or_else(|| {
                FlightStackError::NotRepresentable {
                    field: "timestamp".into(),
                    value: start_timestamp_us as f64 + offset_us as f64,
                    target: "u64",
                }
            })?;
            setpoint_unchecked(traj, t, timestamp, &params.world_to_enu, &mut yaw)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::FRAC_PI_2;
    use trust_core::Piece;

    /// From (1, 2, 3) east at 2 m/s with acceleration (0, 0, 1) in the first second.
    fn east() -> PolyTraj {
        let mut c: Piece = [Vec3::zeros(); 6];
        c[0] = Vec3::new(1.0, 2.0, 3.0);
        c[1] = Vec3::new(2.0, 0.0, 0.0);
        c[2] = Vec3::new(0.0, 0.0, 0.5);
        PolyTraj::new(10.0, vec![1.0], vec![c]).unwrap()
    }

    fn tracker(p: YawPolicy) -> YawTracker {
        YawTracker::new(p).unwrap()
    }

    #[test]
    fn one_setpoint_in_ned() {
        let tr = east();
        let mut yaw = tracker(YawPolicy::FaceVelocity {
            min_speed_m_s: 0.05,
            initial_yaw_rad: 0.0,
        });
        let sp = setpoint_at(&tr, 10.0, 7, &FrameTransform::identity(), &mut yaw).unwrap();
        assert_eq!(sp.timestamp, 7);
        assert_eq!(sp.position, [2.0, 1.0, -3.0]);
        assert_eq!(sp.velocity, [0.0, 2.0, 0.0]);
        assert_eq!(sp.acceleration, [0.0, 0.0, -1.0]);
        assert_eq!(sp.jerk, [0.0, 0.0, -0.0]);
        // Facing east: 90° in NED.
        assert_relative_eq!(sp.yaw, FRAC_PI_2 as f32);
        assert_eq!(sp.yawspeed, 0.0);
        let sp = setpoint_at(&tr, 11.0, 8, &FrameTransform::identity(), &mut yaw).unwrap();
        assert_eq!(sp.position, [2.0, 3.0, -3.5]);
    }

    #[test]
    fn uncontrolled_yaw_is_nan_and_nothing_else_is() {
        let tr = east();
        let mut yaw = tracker(YawPolicy::Uncontrolled);
        let sp = setpoint_at(&tr, 10.5, 0, &FrameTransform::identity(), &mut yaw).unwrap();
        assert!(sp.yaw.is_nan() && sp.yawspeed.is_nan() && !sp.yaw_controlled());
        let controlled = [sp.position, sp.velocity, sp.acceleration, sp.jerk];
        assert!(controlled.iter().flatten().all(|x| x.is_finite()));
    }

    #[test]
    fn times_outside_and_bad_frames_are_refused() {
        let tr = east();
        let mut yaw = tracker(YawPolicy::default());
        let id = FrameTransform::identity();
        for t in [9.99, 11.01, f64::INFINITY] {
            let e = setpoint_at(&tr, t, 0, &id, &mut yaw).unwrap_err();
            assert!(matches!(e, FlightStackError::TimeOutside { .. }), "{e}");
        }
        assert!(setpoint_at(&tr, f64::NAN, 0, &id, &mut yaw).is_err());
        let bad = FrameTransform {
            yaw_rad: f64::INFINITY,
            ..id
        };
        let e = setpoint_at(&tr, 10.0, 0, &bad, &mut yaw).unwrap_err();
        assert!(e.to_string().contains("world_to_enu.yaw_rad"), "{e}");
    }

    #[test]
    fn a_yaw_rate_beyond_f32_is_an_error_not_infinity() {
        // Barely faster than the threshold with a huge sideways acceleration.
        let mut c: Piece = [Vec3::zeros(); 6];
        c[1] = Vec3::new(2e-9, 0.0, 0.0);
        c[2] = Vec3::new(0.0, 5e29, 0.0);
        let tr = PolyTraj::new(0.0, vec![1e-9], vec![c]).unwrap();
        let mut yaw = tracker(YawPolicy::FaceVelocity {
            min_speed_m_s: 1e-9,
            initial_yaw_rad: 0.0,
        });
        let e = setpoint_at(&tr, 0.0, 0, &FrameTransform::identity(), &mut yaw).unwrap_err();
        assert!(e.to_string().contains("yawspeed"), "{e}");
    }

    #[test]
    fn stream_times_cover_the_span() {
        let tr = east();
        let times = stream_times(&tr, 4.0).unwrap();
        assert_eq!(times, vec![10.0, 10.25, 10.5, 10.75, 11.0]);
        let times = stream_times(&tr, 3.0).unwrap();
        assert_eq!(times.len(), 4);
        assert_relative_eq!(times[3], 11.0);
        let times = stream_times(&tr, 2.5).unwrap();
        assert_eq!(times.len(), 4, "{times:?}"); // 0, 0.4, 0.8 and the end
        assert_eq!(*times.last().unwrap(), 11.0);
        assert!(times.windows(2).all(|w| w[1] > w[0]));
    }

    #[test]
    fn bad_rates_are_refused() {
        let tr = east();
        for r in [0.0, -5.0, 1.9, f64::NAN, f64::INFINITY, 2e6] {
            let e = stream_times(&tr, r).unwrap_err();
            assert!(e.to_string().contains("rate_hz"), "{r}: {e}");
        }
        let long = PolyTraj::hold(0.0, Vec3::zeros(), 1e6).unwrap();
        let e = stream_times(&long, 10.0).unwrap_err();
        assert!(matches!(e, FlightStackError::Count(_)), "{e}");
    }

    #[test]
    fn sampled_stream_is_stamped_in_microseconds() {
        let tr = east();
        let sps = sample_setpoints(&tr, 1_000_000, 4.0, &Px4Params::default()).unwrap();
        let stamps: Vec<u64> = sps.iter().map(|s| s.timestamp).collect();
        assert_eq!(
            stamps,
            vec![1_000_000, 1_250_000, 1_500_000, 1_750_000, 2_000_000]
        );
        // Fixed yaw 0 (east) is 90° in NED.
        assert!(
            sps.iter()
                .all(|s| s.yaw == FRAC_PI_2 as f32 && s.yawspeed == 0.0)
        );
        let e = sample_setpoints(&tr, u64::MAX - 10, 4.0, &Px4Params::default()).unwrap_err();
        assert!(e.to_string().contains("timestamp"), "{e}");
        let bad = Px4Params {
            yaw: YawPolicy::Fixed { yaw_rad: f64::NAN },
            ..Px4Params::default()
        };
        assert!(sample_setpoints(&tr, 0, 4.0, &bad).is_err());
    }

    #[test]
    fn mavlink_masks_what_is_not_controlled() {
        let tr = east();
        let mut yaw = tracker(YawPolicy::default());
        let sp = setpoint_at(&tr, 10.5, 2_500_900, &FrameTransform::identity(), &mut yaw).unwrap();
        let m = sp.to_mavlink(1, 1).unwrap();
        assert_eq!(m.type_mask, 0);
        assert_eq!(m.time_boot_ms, 2_500);
        assert_eq!(m.coordinate_frame, MAV_FRAME_LOCAL_NED);
        assert_eq!([m.x, m.y, m.z], sp.position);
        assert_eq!([m.vx, m.vy, m.vz], sp.velocity);
        assert_eq!([m.afx, m.afy, m.afz], sp.acceleration);
        assert_eq!((m.yaw, m.yaw_rate), (sp.yaw, sp.yawspeed));

        let mut yaw = tracker(YawPolicy::Uncontrolled);
        let sp = setpoint_at(&tr, 10.5, 0, &FrameTransform::identity(), &mut yaw).unwrap();
        let m = sp.to_mavlink(1, 1).unwrap();
        assert_eq!(
            m.type_mask,
            TYPE_MASK_YAW_IGNORE | TYPE_MASK_YAW_RATE_IGNORE
        );
        assert_eq!(m.type_mask, 0x0C00);
        assert_eq!((m.yaw, m.yaw_rate), (0.0, 0.0));

        let mut only_z = sp;
        only_z.position[0] = f32::NAN;
        only_z.velocity[2] = f32::NAN;
        let m = only_z.to_mavlink(1, 1).unwrap();
        assert_eq!(m.type_mask, TYPE_MASK_X_IGNORE | 32 | 0x0C00);

        let mut inf = sp;
        inf.acceleration[1] = f32::INFINITY;
        assert!(
            inf.to_mavlink(1, 1)
                .unwrap_err()
                .to_string()
                .contains("acceleration[1]")
        );
        let mut late = sp;
        late.timestamp = (u32::MAX as u64 + 1) * 1000;
        assert!(
            late.to_mavlink(1, 1)
                .unwrap_err()
                .to_string()
                .contains("time_boot_ms")
        );
    }
}

//! Messages in, planner types out, and back: free functions, each checking its input and
//! naming the offending field ([`Ros2Error::Invalid`]). Times are **node times** (s since the
//! node's origin, a ROS time `origin_s`): the planner works in small times (its scale policy
//! bounds them), ROS stamps are seconds since the Unix epoch.

use nalgebra::{Quaternion as NaQuaternion, UnitQuaternion};
use trust_core::{Forecast, ObstacleShape, PolyTraj, State, Vec3};
use trust_flightstack::yaw::YawSample;

use crate::error::Ros2Error;
use crate::heading::Heading;
use crate::msg::builtin_interfaces::{Duration, Time};
use crate::msg::geometry_msgs::{Point, Pose, PoseStamped, Quaternion, Transform, Twist, Vector3};
use crate::msg::nav_msgs::{Odometry, Path};
use crate::msg::std_msgs::{ColorRGBA, Header};
use crate::msg::tf2_msgs::TransformStamped;
use crate::msg::trajectory_msgs::{MultiDOFJointTrajectory, MultiDOFJointTrajectoryPoint};
use crate::msg::visualization_msgs::Marker;

/// Node time ↔ ROS time: node time 0 is ROS time `origin_s` (s since the epoch).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clock {
    /// The ROS time (s) of node time 0.
    pub origin_s: f64,
}

impl Clock {
    /// The node time of a ROS stamp.
    pub fn node_time(&self, stamp: &Time) -> f64 {
        (f64::from(stamp.sec) - self.origin_s) + f64::from(stamp.nanosec) * 1e-9
    }

    /// The ROS stamp of node time `t`.
    ///
    /// # Errors
    /// [`Ros2Error::Invalid`] for a non-finite time or one outside `int32` seconds.
    pub fn stamp(&self, t: f64) -> Result<Time, Ros2Error> {
        Time::from_seconds(self.origin_s + t)
    }

    /// A header at node time `t` in `frame`.
    ///
    /// # Errors
    /// As [`Clock::stamp`].
    pub fn header(&self, t: f64, frame: &str) -> Result<Header, Ros2Error> {
        Ok(Header {
            stamp: self.stamp(t)?,
            frame_id: frame.to_owned(),
        })
    }
}

fn check_frame(field: &str, got: &str, expected: &str) -> Result<(), Ros2Error> {
    if got == expected {
        Ok(())
    } else {
        Err(Ros2Error::invalid(
            field,
            format!("{got:?}"),
            format!("the node's world frame {expected:?}"),
        ))
    }
}

fn finite_vec(field: &str, v: Vec3) -> Result<Vec3, Ros2Error> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(v)
    } else {
        Err(Ros2Error::invalid(
            field,
            format!("({}, {}, {})", v.x, v.y, v.z),
            "finite components",
        ))
    }
}

/// The unit quaternion of `q`, which must be finite and of norm ≥ 1e-6 (it is normalized).
///
/// # Errors
/// [`Ros2Error::Invalid`] naming `field` for a NaN, infinite or zero quaternion.
pub fn unit_quaternion(field: &str, q: &Quaternion) -> Result<UnitQuaternion<f64>, Ros2Error> {
    let n = q.norm();
    if !(n.is_finite() && n >= 1e-6) {
        return Err(Ros2Error::invalid(
            field,
            format!("(x {}, y {}, z {}, w {})", q.x, q.y, q.z, q.w),
            "a finite quaternion of non-zero norm",
        ));
    }
    Ok(UnitQuaternion::from_quaternion(NaQuaternion::new(
        q.w, q.x, q.y, q.z,
    )))
}

/// The vehicle state of an odometry message, at the message's node time: the position of the
/// pose (which must be in `world_frame`), the velocity of the twist rotated into the world frame
/// (the twist is in `child_frame_id`, REP 105: the body frame unless it names the world frame),
/// zero acceleration (odometry has none).
///
/// # Errors
/// [`Ros2Error::Invalid`] naming the field: another frame, a NaN or infinite position or
/// velocity, a zero or non-finite orientation, a stamp outside the clock's range.
pub fn odometry_state(
    msg: &Odometry,
    world_frame: &str,
    clock: &Clock,
) -> Result<State, Ros2Error> {
    check_frame("odom.header.frame_id", &msg.header.frame_id, world_frame)?;
    let t = clock.node_time(&msg.header.stamp);
    let p = finite_vec("odom.pose.pose.position", msg.pose.pose.position.into())?;
    let q = unit_quaternion("odom.pose.pose.orientation", &msg.pose.pose.orientation)?;
    let v_child = finite_vec("odom.twist.twist.linear", msg.twist.twist.linear.into())?;
    let v = if msg.child_frame_id == world_frame {
        v_child
    } else {
        q * v_child
    };
    Ok(State {
        t,
        p,
        v,
        a: Vec3::zeros(),
    })
}

/// The transform from `msg`'s frame (the world frame) to `body_frame` at `msg`'s stamp: the
/// odometry's position and orientation (normalized), for `/tf`. The child is `body_frame`, not
/// `msg.child_frame_id`, which may name the world frame (a twist given in the world).
///
/// # Errors
/// [`Ros2Error::Invalid`] naming the field for a non-finite position or a zero or non-finite
/// orientation.
pub fn odometry_transform(msg: &Odometry, body_frame: &str) -> Result<TransformStamped, Ros2Error> {
    let p = finite_vec("odom.pose.pose.position", msg.pose.pose.position.into())?;
    let q = unit_quaternion("odom.pose.pose.orientation", &msg.pose.pose.orientation)?;
    Ok(TransformStamped {
        header: msg.header.clone(),
        child_frame_id: body_frame.to_owned(),
        transform: Transform {
            translation: p.into(),
            rotation: Quaternion {
                x: q.i,
                y: q.j,
                z: q.k,
                w: q.w,
            },
        },
    })
}

/// The goal position of a `PoseStamped` (its orientation is checked, then ignored: the planner
/// plans positions).
///
/// # Errors
/// [`Ros2Error::Invalid`] naming the field: another frame, a non-finite position, a zero or
/// non-finite orientation.
pub fn goal_position(msg: &PoseStamped, world_frame: &str) -> Result<Vec3, Ros2Error> {
    check_frame("goal.header.frame_id", &msg.header.frame_id, world_frame)?;
    unit_quaternion("goal.pose.orientation", &msg.pose.orientation)?;
    finite_vec("goal.pose.position", msg.pose.position.into())
}

/// The sample times of `traj` from `from` (clamped into its span) to its end every `dt`, the
/// end included.
///
/// # Errors
/// [`Ros2Error::Invalid`] for a `dt` that is not finite and `> 0` or more than 100 000 samples.
pub fn sample_times(traj: &PolyTraj, from: f64, dt: f64) -> Result<Vec<f64>, Ros2Error> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(Ros2Error::invalid(
            "trajectory_dt_s",
            dt,
            "a finite step > 0 s",
        ));
    }
    let t0 = from.clamp(traj.t_start(), traj.t_end());
    let span = traj.t_end() - t0;
    let n = (span / dt - 1e-9).ceil().max(0.0);
    if n > 100_000.0 {
        return Err(Ros2Error::invalid(
            "trajectory_dt_s",
            dt,
            format!("a step giving at most 100000 samples over {span} s"),
        ));
    }
    let n = n as usize;
    let mut out: Vec<f64> = (0..n).map(|k| t0 + k as f64 * dt).collect();
    out.push(traj.t_end());
    Ok(out)
}

/// The yaw sample as a rotation about +z, checked finite.
fn yaw_rotation(field: &str, yaw: &YawSample) -> Result<Quaternion, Ros2Error> {
    if !(yaw.yaw_rad.is_finite() && yaw.yaw_rate_rad_s.is_finite()) {
        return Err(Ros2Error::invalid(
            field,
            format!("yaw {} rad, rate {} rad/s", yaw.yaw_rad, yaw.yaw_rate_rad_s),
            "a finite yaw and yaw rate",
        ));
    }
    Ok(Quaternion::from_yaw(yaw.yaw_rad))
}

/// One trajectory point of `traj` at node time `t`: position and the rotation by `yaw` about
/// +z (`transforms[0]`), velocity with the yaw rate as `angular.z` (`velocities[0]`),
/// acceleration with zero angular part (`accelerations[0]`), all in the world frame;
/// `time_from_start = t − start`. `heading` gives the yaw ([`Heading::next`], module
/// [`crate::heading`]).
///
/// # Errors
/// [`Ros2Error::Invalid`] for a negative or non-finite `t − start` or a non-finite sample.
pub fn trajectory_point(
    traj: &PolyTraj,
    t: f64,
    start: f64,
    heading: &mut Heading,
) -> Result<MultiDOFJointTrajectoryPoint, Ros2Error> {
    let s = traj.state(t);
    let p = finite_vec("trajectory.position", s.p)?;
    let v = finite_vec("trajectory.velocity", s.v)?;
    let a = finite_vec("trajectory.acceleration", s.a)?;
    let yaw = heading.next(&v, &a)?;
    let rotation = yaw_rotation("trajectory.yaw", &yaw)?;
    let since = t - start;
    if since.is_nan() || since < 0.0 {
        return Err(Ros2Error::invalid(
            "time_from_start",
            since,
            "a time >= 0 s after the header stamp",
        ));
    }
    Ok(MultiDOFJointTrajectoryPoint {
        transforms: vec![Transform {
            translation: p.into(),
            rotation,
        }],
        velocities: vec![Twist {
            linear: v.into(),
            angular: Vector3 {
                x: 0.0,
                y: 0.0,
                z: yaw.yaw_rate_rad_s,
            },
        }],
        accelerations: vec![Twist {
            linear: a.into(),
            angular: Vector3::default(),
        }],
        time_from_start: Duration::from_seconds(since)?,
    })
}

/// `traj` from node time `from` on as a `MultiDOFJointTrajectory` sampled every `dt`
/// ([`sample_times`]), stamped at the first sample, one joint named `body_frame`, the yaws
/// from `heading` fed the samples in order (pass [`Heading::ahead`]'s copy).
///
/// # Errors
/// As [`sample_times`] and [`trajectory_point`].
pub fn trajectory_message(
    traj: &PolyTraj,
    from: f64,
    dt: f64,
    clock: &Clock,
    frames: (&str, &str),
    heading: &mut Heading,
) -> Result<MultiDOFJointTrajectory, Ros2Error> {
    let (world_frame, body_frame) = frames;
    let times = sample_times(traj, from, dt)?;
    let start = times[0];
    let points = times
        .iter()
        .map(|&t| trajectory_point(traj, t, start, heading))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(MultiDOFJointTrajectory {
        header: clock.header(start, world_frame)?,
        joint_names: vec![body_frame.to_owned()],
        points,
    })
}

/// `traj` from node time `from` on as a `nav_msgs/Path` (positions every `dt`, each pose
/// stamped with its time, oriented by the yaw `heading` gives, as in [`trajectory_message`]).
///
/// # Errors
/// As [`sample_times`]; [`Ros2Error::Invalid`] for a non-finite sample.
pub fn path_message(
    traj: &PolyTraj,
    from: f64,
    dt: f64,
    clock: &Clock,
    world_frame: &str,
    heading: &mut Heading,
) -> Result<Path, Ros2Error> {
    let times = sample_times(traj, from, dt)?;
    let poses = times
        .iter()
        .map(|&t| {
            let s = traj.state(t);
            let yaw = heading.next(&s.v, &s.a)?;
            Ok(PoseStamped {
                header: clock.header(t, world_frame)?,
                pose: Pose {
                    position: finite_vec("path.position", s.p)?.into(),
                    orientation: yaw_rotation("path.yaw", &yaw)?,
                },
            })
        })
        .collect::<Result<Vec<_>, Ros2Error>>()?;
    Ok(Path {
        header: clock.header(times[0], world_frame)?,
        poses,
    })
}

/// A marker with every field at its default but these.
fn marker(header: &Header, ns: &str, id: i32, kind: i32, color: ColorRGBA) -> Marker {
    Marker {
        header: header.clone(),
        ns: ns.to_owned(),
        id,
        kind,
        action: Marker::ADD,
        color,
        ..Marker::default()
    }
}

/// Colours of the markers: the main branch, the other branches, the forecasts.
const MAIN: ColorRGBA = ColorRGBA {
    r: 0.12,
    g: 0.47,
    b: 0.71,
    a: 1.0,
};
const OTHER: ColorRGBA = ColorRGBA {
    r: 0.5,
    g: 0.5,
    b: 0.5,
    a: 0.6,
};
const FORECAST: ColorRGBA = ColorRGBA {
    r: 1.0,
    g: 0.5,
    b: 0.05,
    a: 0.5,
};

/// The markers of one cycle at node time `now`: first a `DELETEALL` (the previous cycle's
/// markers go), then each branch as a line strip (namespace `branches`, the main one first and
/// coloured, width 0.05 m) sampled every `dt` from `now`, then each forecast at `now` as a
/// sphere or a vertical cylinder of its current radius (namespace `forecasts`).
///
/// # Errors
/// As [`sample_times`]; [`Ros2Error::Invalid`] for a non-finite sample or forecast.
pub fn markers(
    branches: &[(&PolyTraj, bool)],
    forecasts: &[Forecast],
    now: f64,
    dt: f64,
    clock: &Clock,
    world_frame: &str,
) -> Result<Vec<Marker>, Ros2Error> {
    let header = clock.header(now, world_frame)?;
    let mut out = vec![Marker {
        action: Marker::DELETEALL,
        ..marker(&header, "", 0, 0, ColorRGBA::default())
    }];
    for (i, (traj, is_main)) in branches.iter().enumerate() {
        let color = if *is_main { MAIN } else { OTHER };
        let mut m = marker(&header, "branches", i as i32, Marker::LINE_STRIP, color);
        m.scale.x = 0.05;
        m.points = sample_times(traj, now, dt)?
            .iter()
            .map(|&t| finite_vec("branch.position", traj.position(t)).map(Point::from))
            .collect::<Result<_, _>>()?;
        out.push(m);
    }
    for (i, f) in forecasts.iter().enumerate() {
        let c = finite_vec("forecast.center", f.center(now))?;
        let r = f.radius(now);
        if !r.is_finite() {
            return Err(Ros2Error::invalid("forecast.radius", r, "a finite radius"));
        }
        let kind = match f.shape {
            ObstacleShape::Sphere => Marker::SPHERE,
            ObstacleShape::Cylinder { .. } => Marker::CYLINDER,
        };
        let height = 2.0 * f.vertical_half_extent(now);
        let mut m = marker(&header, "forecasts", i as i32, kind, FORECAST);
        m.pose.position = c.into();
        m.scale = Vector3 {
            x: 2.0 * r,
            y: 2.0 * r,
            z: height,
        };
        out.push(m);
    }
    Ok(out)
}

#!/usr/bin/env python3
"""An independent DDS peer for `trust-node`: Eclipse Cyclone DDS (Python binding, pinned in
`requirements.txt`), which shares no code with ros2-client/RustDDS.

The ROS 2 message types are declared here as Cyclone IDL structs, written from the ROS 2 `.msg`
definitions (common_interfaces, geometry2's tf2_msgs and rcl_interfaces' rosgraph_msgs as in
Humble and Jazzy, px4_msgs of PX4 v1.15, and our `crates/ros2/msg/trust_msgs`), not from the
Rust structs. ROS 2 on DDS: the topic `/odom` is the DDS topic `rt/odom`, the type
`nav_msgs/msg/Odometry` the DDS type `nav_msgs::msg::dds_::Odometry_`, payloads XCDR1
little-endian.

The peer publishes odometry, a goal and two moving obstacles with known values, receives every
topic the node publishes and checks each message field by field (frames, stamps, finite
numbers, the plan from the vehicle to the goal, the yaw policy, the obstacles' forecasts, /tf).
A field whose layout differs on the two sides either fails to decode here or decodes to values
that fail a check.

    peer.py --domain N [--px4] [--sim-time START] [--timeout S]
    peer.py --domain N --observe-world START [--timeout S]
    peer.py --domain N --cloud "x,y,z;x,y,z;..." [--timeout S]

With `--sim-time START` the peer is also the node's clock (the node runs with
`--use-sim-time`): it publishes `/clock` from START s on and stamps its messages with it; every
stamp the node publishes must follow that clock. With `--observe-world START` it publishes
nothing and checks a `trust-sim dds-world` flight whose clock starts at START s: `/clock`, the
world's odometry, and the node's `/tf` and `trajectory` on the world's clock. With `--cloud
POINTS` it publishes odometry and the points given (in the map frame) as two PointCloud2
messages of layouts unlike the node's own encoder: the first half in `map`, FLOAT32
little-endian after an `intensity` field; the second half in `base_link` (moved into the body
frame here, by the odometry's pose), FLOAT64 big-endian in a 2-row organized cloud with NaN
holes and padded rows. It publishes them for 3 s after the node's first `/tf` (discovery
done); the test then checks the node's map.

Exit status 0 when every check passed, 1 on a failed check or a timeout (the reason on stderr).
Run it restricted to loopback: CYCLONEDDS_URI (see `crates/ros2/tests/cyclone_interop.rs`).
"""

import argparse
import math
import struct
import sys
import time
from dataclasses import dataclass, field

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl import types as t
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration


def dds(pkg, name):
    """The DDS type name of the ROS 2 message `pkg/msg/name`."""
    return f"{pkg}::msg::dds_::{name}_"


# --- builtin_interfaces, std_msgs ---------------------------------------------------------------


@dataclass
class Time(IdlStruct, typename=dds("builtin_interfaces", "Time")):
    sec: t.int32 = 0
    nanosec: t.uint32 = 0


@dataclass
class Duration(IdlStruct, typename=dds("builtin_interfaces", "Duration")):
    sec: t.int32 = 0
    nanosec: t.uint32 = 0


@dataclass
class Header(IdlStruct, typename=dds("std_msgs", "Header")):
    stamp: Time = field(default_factory=Time)
    frame_id: str = ""


@dataclass
class ColorRGBA(IdlStruct, typename=dds("std_msgs", "ColorRGBA")):
    r: t.float32 = 0.0
    g: t.float32 = 0.0
    b: t.float32 = 0.0
    a: t.float32 = 0.0


# --- geometry_msgs ------------------------------------------------------------------------------


@dataclass
class Point(IdlStruct, typename=dds("geometry_msgs", "Point")):
    x: t.float64 = 0.0
    y: t.float64 = 0.0
    z: t.float64 = 0.0


@dataclass
class Vector3(IdlStruct, typename=dds("geometry_msgs", "Vector3")):
    x: t.float64 = 0.0
    y: t.float64 = 0.0
    z: t.float64 = 0.0


@dataclass
class Quaternion(IdlStruct, typename=dds("geometry_msgs", "Quaternion")):
    x: t.float64 = 0.0
    y: t.float64 = 0.0
    z: t.float64 = 0.0
    w: t.float64 = 1.0


@dataclass
class Pose(IdlStruct, typename=dds("geometry_msgs", "Pose")):
    position: Point = field(default_factory=Point)
    orientation: Quaternion = field(default_factory=Quaternion)


@dataclass
class PoseStamped(IdlStruct, typename=dds("geometry_msgs", "PoseStamped")):
    header: Header = field(default_factory=Header)
    pose: Pose = field(default_factory=Pose)


@dataclass
class PoseWithCovariance(IdlStruct, typename=dds("geometry_msgs", "PoseWithCovariance")):
    pose: Pose = field(default_factory=Pose)
    covariance: t.array[t.float64, 36] = field(default_factory=lambda: [0.0] * 36)


@dataclass
class Twist(IdlStruct, typename=dds("geometry_msgs", "Twist")):
    linear: Vector3 = field(default_factory=Vector3)
    angular: Vector3 = field(default_factory=Vector3)


@dataclass
class TwistWithCovariance(IdlStruct, typename=dds("geometry_msgs", "TwistWithCovariance")):
    twist: Twist = field(default_factory=Twist)
    covariance: t.array[t.float64, 36] = field(default_factory=lambda: [0.0] * 36)


@dataclass
class Transform(IdlStruct, typename=dds("geometry_msgs", "Transform")):
    translation: Vector3 = field(default_factory=Vector3)
    rotation: Quaternion = field(default_factory=Quaternion)


@dataclass
class TransformStamped(IdlStruct, typename=dds("geometry_msgs", "TransformStamped")):
    header: Header = field(default_factory=Header)
    child_frame_id: str = ""
    transform: Transform = field(default_factory=Transform)


# --- tf2_msgs, rosgraph_msgs --------------------------------------------------------------------


@dataclass
class TFMessage(IdlStruct, typename=dds("tf2_msgs", "TFMessage")):
    transforms: t.sequence[TransformStamped] = field(default_factory=list)


@dataclass
class Clock(IdlStruct, typename=dds("rosgraph_msgs", "Clock")):
    clock: Time = field(default_factory=Time)


# --- nav_msgs, trajectory_msgs ------------------------------------------------------------------


@dataclass
class Odometry(IdlStruct, typename=dds("nav_msgs", "Odometry")):
    header: Header = field(default_factory=Header)
    child_frame_id: str = ""
    pose: PoseWithCovariance = field(default_factory=PoseWithCovariance)
    twist: TwistWithCovariance = field(default_factory=TwistWithCovariance)


@dataclass
class Path(IdlStruct, typename=dds("nav_msgs", "Path")):
    header: Header = field(default_factory=Header)
    poses: t.sequence[PoseStamped] = field(default_factory=list)


@dataclass
class MultiDOFJointTrajectoryPoint(
    IdlStruct, typename=dds("trajectory_msgs", "MultiDOFJointTrajectoryPoint")
):
    transforms: t.sequence[Transform] = field(default_factory=list)
    velocities: t.sequence[Twist] = field(default_factory=list)
    accelerations: t.sequence[Twist] = field(default_factory=list)
    time_from_start: Duration = field(default_factory=Duration)


@dataclass
class MultiDOFJointTrajectory(IdlStruct, typename=dds("trajectory_msgs", "MultiDOFJointTrajectory")):
    header: Header = field(default_factory=Header)
    joint_names: t.sequence[str] = field(default_factory=list)
    points: t.sequence[MultiDOFJointTrajectoryPoint] = field(default_factory=list)


# --- sensor_msgs, visualization_msgs (Humble/Jazzy Marker, with textures and meshes) -----------


@dataclass
class CompressedImage(IdlStruct, typename=dds("sensor_msgs", "CompressedImage")):
    header: Header = field(default_factory=Header)
    format: str = ""
    data: t.sequence[t.uint8] = field(default_factory=list)


@dataclass
class UVCoordinate(IdlStruct, typename=dds("visualization_msgs", "UVCoordinate")):
    u: t.float32 = 0.0
    v: t.float32 = 0.0


@dataclass
class MeshFile(IdlStruct, typename=dds("visualization_msgs", "MeshFile")):
    filename: str = ""
    data: t.sequence[t.uint8] = field(default_factory=list)


@dataclass
class Marker(IdlStruct, typename=dds("visualization_msgs", "Marker")):
    header: Header = field(default_factory=Header)
    ns: str = ""
    id: t.int32 = 0
    type: t.int32 = 0
    action: t.int32 = 0
    pose: Pose = field(default_factory=Pose)
    scale: Vector3 = field(default_factory=Vector3)
    color: ColorRGBA = field(default_factory=ColorRGBA)
    lifetime: Duration = field(default_factory=Duration)
    frame_locked: bool = False
    points: t.sequence[Point] = field(default_factory=list)
    colors: t.sequence[ColorRGBA] = field(default_factory=list)
    texture_resource: str = ""
    texture: CompressedImage = field(default_factory=CompressedImage)
    uv_coordinates: t.sequence[UVCoordinate] = field(default_factory=list)
    text: str = ""
    mesh_resource: str = ""
    mesh_file: MeshFile = field(default_factory=MeshFile)
    mesh_use_embedded_materials: bool = False


MARKER_SPHERE, MARKER_CYLINDER, MARKER_LINE_STRIP = 2, 3, 4
MARKER_ADD, MARKER_DELETEALL = 0, 3


@dataclass
class MarkerArray(IdlStruct, typename=dds("visualization_msgs", "MarkerArray")):
    markers: t.sequence[Marker] = field(default_factory=list)


# --- trust_msgs (crates/ros2/msg/trust_msgs/msg) ------------------------------------------------

SHAPE_SPHERE, SHAPE_CYLINDER = 0, 1


@dataclass
class MovingObstacle(IdlStruct, typename=dds("trust_msgs", "MovingObstacle")):
    id: t.uint32 = 0
    shape: t.uint8 = 0
    size: Vector3 = field(default_factory=Vector3)
    position: Point = field(default_factory=Point)
    velocity: Vector3 = field(default_factory=Vector3)
    covariance: t.array[t.float64, 36] = field(default_factory=lambda: [0.0] * 36)


@dataclass
class MovingObstacleArray(IdlStruct, typename=dds("trust_msgs", "MovingObstacleArray")):
    header: Header = field(default_factory=Header)
    obstacles: t.sequence[MovingObstacle] = field(default_factory=list)


@dataclass
class PlannerEvent(IdlStruct, typename=dds("trust_msgs", "PlannerEvent")):
    header: Header = field(default_factory=Header)
    cycle_count: t.uint64 = 0
    cycle_time_ms: t.float64 = 0.0
    has_plan: bool = False
    fallback: bool = False
    events: t.sequence[str] = field(default_factory=list)


# --- px4_msgs (PX4 v1.15) -----------------------------------------------------------------------


@dataclass
class TrajectorySetpoint(IdlStruct, typename=dds("px4_msgs", "TrajectorySetpoint")):
    timestamp: t.uint64 = 0
    position: t.array[t.float32, 3] = field(default_factory=lambda: [0.0] * 3)
    velocity: t.array[t.float32, 3] = field(default_factory=lambda: [0.0] * 3)
    acceleration: t.array[t.float32, 3] = field(default_factory=lambda: [0.0] * 3)
    jerk: t.array[t.float32, 3] = field(default_factory=lambda: [0.0] * 3)
    yaw: t.float32 = 0.0
    yawspeed: t.float32 = 0.0


# --- the scene the peer sends (inside scenarios/quickstart.toml's 40 x 20 x 10 m world) ---------

# --- sensor_msgs (PointField.msg, PointCloud2.msg) -------------------------------------------


@dataclass
class PointField(IdlStruct, typename=dds("sensor_msgs", "PointField")):
    name: str = ""
    offset: t.uint32 = 0
    datatype: t.uint8 = 0
    count: t.uint32 = 0


@dataclass
class PointCloud2(IdlStruct, typename=dds("sensor_msgs", "PointCloud2")):
    header: Header = field(default_factory=Header)
    height: t.uint32 = 0
    width: t.uint32 = 0
    fields: t.sequence[PointField] = field(default_factory=list)
    is_bigendian: bool = False
    point_step: t.uint32 = 0
    row_step: t.uint32 = 0
    data: t.sequence[t.uint8] = field(default_factory=list)
    is_dense: bool = False


# PointField.msg's datatype constants.
FLOAT32, FLOAT64 = 7, 8


WORLD, BODY = "map", "base_link"
START = (2.0, 10.0, 3.0)
GOAL = (8.0, 10.0, 3.0)
# The vehicle's heading the peer sends (90°: facing north, ENU) and the way to the goal (east).
ODOM_YAW = math.pi / 2
ODOM_Q = (0.0, 0.0, math.sqrt(0.5), math.sqrt(0.5))
TRAVEL_YAW = math.atan2(GOAL[1] - START[1], GOAL[0] - START[0])
# The node's default yaw policy (docs/ros2.md, "Yaw"): face the horizontal velocity above this
# horizontal speed, hold the last yaw below it.
YAW_MIN_SPEED = 0.3
# (id, shape, size, position): off the way from START to GOAL.
OBSTACLES = [
    (7, SHAPE_SPHERE, (1.0, 1.0, 1.0), (30.0, 4.0, 6.0)),
    (9, SHAPE_CYLINDER, (0.8, 0.8, 3.0), (34.0, 16.0, 3.0)),
]


class CheckFailed(Exception):
    pass


def check(cond, what):
    if not cond:
        raise CheckFailed(what)


class PeerClock:
    """The ROS time the node should follow: the system clock, or with --sim-time the peer's own
    simulated clock (START s when the peer starts, then with the monotonic clock)."""

    def __init__(self, sim_start=None):
        self.sim_start = sim_start
        self.t0 = time.monotonic()

    def now(self):
        if self.sim_start is None:
            return time.time()
        return self.sim_start + (time.monotonic() - self.t0)


CLOCK = PeerClock()


def to_stamp(s):
    ns = round(s * 1e9)
    return Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def now_stamp():
    return to_stamp(CLOCK.now())


def seconds(stamp):
    return stamp.sec + stamp.nanosec * 1e-9


def check_stamp(stamp, what):
    check(0 <= stamp.nanosec < 1_000_000_000, f"{what}.nanosec = {stamp.nanosec}: not in [0, 1e9)")
    age = CLOCK.now() - seconds(stamp)
    check(-5.0 < age < 30.0, f"{what} = {seconds(stamp):.3f}: {age:.3f} s from the peer's clock")


def check_header(h, what):
    check(h.frame_id == WORLD, f"{what}.header.frame_id = {h.frame_id!r}, expected {WORLD!r}")
    check_stamp(h.stamp, f"{what}.header.stamp")


def finite(values, what):
    values = list(values)
    check(all(isinstance(v, float) and math.isfinite(v) for v in values), f"{what} not finite: {values}")


def xyz(v):
    return (v.x, v.y, v.z)


def dist(a, b):
    return math.dist(a, b)


def check_identity(q, what):
    finite((q.x, q.y, q.z, q.w), what)
    check(abs(q.x) + abs(q.y) + abs(q.z) < 1e-9 and abs(q.w - 1.0) < 1e-9, f"{what} = {q}: not the identity")


def wrap(a):
    """`a` wrapped to (-pi, pi]."""
    r = math.fmod(a, 2 * math.pi)
    if r <= -math.pi:
        r += 2 * math.pi
    elif r > math.pi:
        r -= 2 * math.pi
    return r


def yaw_of(q, what):
    """The yaw of a rotation about +z only (x = y = 0, unit norm)."""
    finite((q.x, q.y, q.z, q.w), what)
    check(q.x == 0.0 and q.y == 0.0, f"{what} = {q}: not a rotation about z alone")
    check(abs(q.z * q.z + q.w * q.w - 1.0) < 1e-12, f"{what} = {q}: not a unit quaternion")
    return 2.0 * math.atan2(q.z, q.w)


def check_held_yaw(yaw, what):
    """A yaw held while slow: the vehicle's own heading (the odometry's) or the way it went."""
    check(min(abs(wrap(yaw - ODOM_YAW)), abs(wrap(yaw - TRAVEL_YAW))) < 0.2,
          f"{what} = {yaw:.4f} rad: slow, so the held yaw: the odometry's {ODOM_YAW:.4f} or the travel "
          f"heading {TRAVEL_YAW:.4f}")


def check_yaw(yaw, rate, v, a, what, held):
    """The yaw policy in the world frame (ENU) at velocity v and acceleration a: facing the
    velocity with the rate of its heading when faster than YAW_MIN_SPEED, else the held yaw
    (`held`, the previous sample's, or one of check_held_yaw's when None) and rate 0."""
    speed2 = v[0] ** 2 + v[1] ** 2
    if math.sqrt(speed2) > YAW_MIN_SPEED:
        heading = math.atan2(v[1], v[0])
        check(abs(wrap(yaw - heading)) < 1e-6, f"{what}: yaw {yaw:.6f} rad, the velocity {v} heads {heading:.6f}")
        expected = (v[0] * a[1] - v[1] * a[0]) / speed2
        check(abs(rate - expected) <= 1e-6 * max(1.0, abs(expected)),
              f"{what}: yaw rate {rate} rad/s, the heading turns at {expected} rad/s")
    else:
        check(rate == 0.0, f"{what}: yaw rate {rate} rad/s while slow ({math.sqrt(speed2):.3f} m/s)")
        if held is None:
            check_held_yaw(yaw, what)
        else:
            check(abs(wrap(yaw - held)) < 1e-12, f"{what}: yaw {yaw} rad while slow, the last was {held}")


def check_point(p, what, held):
    """A MultiDOFJointTrajectoryPoint of one joint (`held`: the previous point's yaw, or None);
    returns its position and yaw."""
    check(
        len(p.transforms) == len(p.velocities) == len(p.accelerations) == 1,
        f"{what}: {len(p.transforms)}/{len(p.velocities)}/{len(p.accelerations)} transforms/velocities/"
        "accelerations, expected one each",
    )
    tr = p.transforms[0]
    finite(xyz(tr.translation), f"{what}.translation")
    yaw = yaw_of(tr.rotation, f"{what}.rotation")
    for name, tw, limit in (("velocity", p.velocities[0], 10.5), ("acceleration", p.accelerations[0], 40.0)):
        finite(xyz(tw.linear) + xyz(tw.angular), f"{what}.{name}")
        check(math.hypot(*xyz(tw.linear)) <= limit, f"{what}.{name} = {xyz(tw.linear)}: above {limit}")
    vel, acc = p.velocities[0], p.accelerations[0]
    check((vel.angular.x, vel.angular.y) == (0.0, 0.0), f"{what}.velocity.angular = {xyz(vel.angular)}: not about z")
    check(xyz(acc.angular) == (0.0, 0.0, 0.0), f"{what}.acceleration.angular = {xyz(acc.angular)}, expected 0")
    check_yaw(yaw, vel.angular.z, xyz(vel.linear), xyz(acc.linear), f"{what} yaw", held)
    check(0 <= p.time_from_start.nanosec < 1_000_000_000, f"{what}.time_from_start.nanosec out of range")
    check(0 <= seconds(p.time_from_start) < 120.0, f"{what}.time_from_start = {seconds(p.time_from_start)}")
    x = xyz(tr.translation)
    check(all(lo - 1.0 <= c <= hi + 1.0 for c, lo, hi in zip(x, (0, 0, 0), (40, 20, 10))),
          f"{what}.translation = {x}: outside the world")
    return x, yaw


def match_path_yaws(state, stamp, kind, yaws):
    """The path and the trajectory of one cycle (same stamp) carry the same yaws."""
    key = (stamp.sec, stamp.nanosec)
    state[kind][key] = yaws
    other = state["path_yaws" if kind == "trajectory_yaws" else "trajectory_yaws"].get(key)
    if other is not None:
        check(len(other) == len(yaws) and all(abs(wrap(a - b)) < 1e-9 for a, b in zip(other, yaws)),
              f"path and trajectory of the cycle at {seconds(stamp):.3f}: yaws differ")
        state["yaws_matched"] = True


def holds_in_place(first, last):
    """A plan that ends where it starts, short of the goal: the node's first cycles at rest hold
    the vehicle's place while its first route is searched (decoded and checked all the same, but
    not yet the plan toward the goal the peer waits for)."""
    return dist(last, first) < 0.1 and dist(last, GOAL) >= 1.0


def check_trajectory(m, state):
    check_header(m.header, "trajectory")
    check(list(m.joint_names) == [BODY], f"trajectory.joint_names = {m.joint_names}, expected [{BODY!r}]")
    check(len(m.points) >= 2, f"trajectory: {len(m.points)} points")
    last_t = -1.0
    held = None
    yaws = []
    for k, p in enumerate(m.points):
        _, held = check_point(p, f"trajectory.points[{k}]", held)
        yaws.append(held)
        tk = seconds(p.time_from_start)
        check(tk > last_t, f"trajectory.points[{k}].time_from_start = {tk} not after {last_t}")
        last_t = tk
    match_path_yaws(state, m.header.stamp, "trajectory_yaws", yaws)
    first = xyz(m.points[0].transforms[0].translation)
    last = xyz(m.points[-1].transforms[0].translation)
    check(dist(first, START) < 1.0, f"trajectory starts at {first}, the vehicle is at {START}")
    if holds_in_place(first, last):
        return None
    check(dist(last, GOAL) < 1.0, f"trajectory ends at {last}, the goal is {GOAL}")
    return f"{len(m.points)} points from {fmt(first)} to {fmt(last)} in {last_t:.2f} s"


def check_path(m, state):
    check_header(m.header, "path")
    check(len(m.poses) >= 2, f"path: {len(m.poses)} poses")
    yaws = []
    for k, ps in enumerate(m.poses):
        check_header(ps.header, f"path.poses[{k}]")
        finite(xyz(ps.pose.position), f"path.poses[{k}].position")
        yaws.append(yaw_of(ps.pose.orientation, f"path.poses[{k}].orientation"))
    match_path_yaws(state, m.header.stamp, "path_yaws", yaws)
    first, last = xyz(m.poses[0].pose.position), xyz(m.poses[-1].pose.position)
    check(dist(first, START) < 1.0, f"path starts at {first}, the vehicle is at {START}")
    if holds_in_place(first, last):
        return None
    check(dist(last, GOAL) < 1.0, f"path ends at {last}, the goal is {GOAL}")
    return f"{len(m.poses)} poses from {fmt(first)} to {fmt(last)}"


def check_setpoint(m, state):
    check_header(m.header, "setpoint")
    check(list(m.joint_names) == [BODY], f"setpoint.joint_names = {m.joint_names}")
    check(len(m.points) == 1, f"setpoint: {len(m.points)} points, expected 1")
    x, _ = check_point(m.points[0], "setpoint.points[0]", None)
    check(seconds(m.points[0].time_from_start) == 0.0, "setpoint.time_from_start is not 0")
    check(dist(x, START) < 1.0, f"setpoint at {x}: the vehicle (held at {START}) is not there")
    return f"at {fmt(x)}"


def check_px4_setpoint(m, state):
    # NED: north (ROS y), east (ROS x), down (-z).
    check(m.timestamp > 0 and abs(m.timestamp * 1e-6 - CLOCK.now()) < 30.0,
          f"px4 setpoint.timestamp = {m.timestamp} µs: not the ROS time")
    for name in ("position", "velocity", "acceleration", "jerk"):
        v = [float(c) for c in getattr(m, name)]
        check(len(v) == 3, f"px4 setpoint.{name} has {len(v)} elements")
        if name != "jerk":
            finite(v, f"px4 setpoint.{name}")
    ned = [float(c) for c in m.position]
    expected = (START[1], START[0], -START[2])
    check(dist(ned, expected) < 1.0, f"px4 setpoint.position = {ned}, expected near NED {expected}")
    # PX4's yaw is from north, clockwise seen from above: the heading of the horizontal NED
    # velocity (north, east) is atan2(east, north), turning at (v_n a_e - v_e a_n) / |v|^2 about
    # down. Slow, the held yaw: the odometry's (ENU 90°, north: NED 0) or the travel heading.
    yaw, rate = float(m.yaw), float(m.yawspeed)
    finite((yaw, rate), "px4 setpoint.yaw/yawspeed")
    check(-math.pi <= yaw <= math.pi, f"px4 setpoint.yaw = {yaw}: outside [-π, π]")
    (vn, ve, _), (an, ae, _) = m.velocity, m.acceleration
    speed2 = vn * vn + ve * ve
    if math.sqrt(speed2) > YAW_MIN_SPEED * 1.001:
        heading = math.atan2(ve, vn)
        check(abs(wrap(yaw - heading)) < 1e-4, f"px4 setpoint.yaw = {yaw}: the NED velocity heads {heading}")
        expected = (vn * ae - ve * an) / speed2
        check(abs(rate - expected) <= 1e-3 * max(1.0, abs(expected)),
              f"px4 setpoint.yawspeed = {rate}: the NED heading turns at {expected}")
        kind = "facing the velocity"
    elif math.sqrt(speed2) < YAW_MIN_SPEED * 0.999:
        check(rate == 0.0, f"px4 setpoint.yawspeed = {rate} while slow")
        odom_ned, travel_ned = wrap(math.pi / 2 - ODOM_YAW), wrap(math.pi / 2 - TRAVEL_YAW)
        check(min(abs(wrap(yaw - odom_ned)), abs(wrap(yaw - travel_ned))) < 0.2,
              f"px4 setpoint.yaw = {yaw} while slow: expected the held {odom_ned} or {travel_ned}")
        kind = "held"
    else:
        kind = "at the threshold (float32)"
    state["px4_yaws"][kind] = state["px4_yaws"].get(kind, 0) + 1
    return f"NED {fmt(ned)}, yaw {yaw:.3f} ({kind})"


def check_tf(m, state):
    check(len(m.transforms) == 1, f"tf: {len(m.transforms)} transforms, expected 1")
    tr = m.transforms[0]
    check_header(tr.header, "tf.transforms[0]")
    check(tr.child_frame_id == BODY, f"tf.child_frame_id = {tr.child_frame_id!r}, expected {BODY!r}")
    key = (tr.header.stamp.sec, tr.header.stamp.nanosec)
    check(key in state["odom_stamps"], f"tf stamp {seconds(tr.header.stamp):.9f}: not one of the odometry's")
    x = xyz(tr.transform.translation)
    check(x == START, f"tf.translation = {x}, the odometry's position is {START}")
    q = tr.transform.rotation
    check(max(abs(a - b) for a, b in zip((q.x, q.y, q.z, q.w), ODOM_Q)) < 1e-12,
          f"tf.rotation = {q}: the odometry's orientation is {ODOM_Q}")
    return f"{WORLD} -> {BODY} at {fmt(x)}, stamped as an odometry sent"


def check_markers(m, state):
    check(len(m.markers) >= 1, "markers: empty array")
    first = m.markers[0]
    check(first.action == MARKER_DELETEALL, f"markers[0].action = {first.action}, expected DELETEALL")
    forecasts = {}
    branches = 0
    for k, mk in enumerate(m.markers):
        what = f"markers[{k}]"
        check_header(mk.header, what)
        check(mk.texture_resource == "" and mk.text == "" and mk.mesh_resource == "" and
              len(mk.texture.data) == 0 and len(mk.uv_coordinates) == 0 and len(mk.mesh_file.data) == 0
              and not mk.mesh_use_embedded_materials and not mk.frame_locked,
              f"{what}: texture/mesh fields not empty")
        for c in ("r", "g", "b", "a"):
            v = getattr(mk.color, c)
            check(0.0 <= v <= 1.0, f"{what}.color.{c} = {v}")
        if k == 0:
            continue
        check(mk.action == MARKER_ADD, f"{what}.action = {mk.action}, expected ADD")
        check_identity(mk.pose.orientation, f"{what}.pose.orientation")
        if mk.ns == "branches":
            check(mk.type == MARKER_LINE_STRIP, f"{what}.type = {mk.type}, expected LINE_STRIP")
            check(len(mk.points) >= 2, f"{what}: {len(mk.points)} points")
            for p in mk.points:
                finite(xyz(p), f"{what}.points")
            check(abs(mk.scale.x - 0.05) < 1e-9, f"{what}.scale.x = {mk.scale.x}, expected 0.05")
            branches += 1
        elif mk.ns == "forecasts":
            c = xyz(mk.pose.position)
            finite(c + xyz(mk.scale), what)
            forecasts[(mk.type, round(c[0]), round(c[1]), round(c[2]))] = mk
        else:
            raise CheckFailed(f"{what}.ns = {mk.ns!r}: expected 'branches' or 'forecasts'")
    # Every obstacle sent is drawn where it was sent, of at least its size.
    found = []
    for oid, shape, size, pos in OBSTACLES:
        kind = MARKER_SPHERE if shape == SHAPE_SPHERE else MARKER_CYLINDER
        mk = next((v for (ty, *_), v in forecasts.items()
                   if ty == kind and dist(xyz(v.pose.position), pos) < 0.5), None)
        if mk is None:
            continue
        check(mk.scale.x >= size[0] - 1e-6 and abs(mk.scale.x - mk.scale.y) < 1e-9,
              f"forecast of obstacle {oid}: scale {xyz(mk.scale)}, size sent {size}")
        if shape == SHAPE_CYLINDER:
            check(mk.scale.z >= size[2] - 1e-6, f"forecast of obstacle {oid}: height {mk.scale.z} < {size[2]}")
        found.append(oid)
    if branches >= 1 and len(found) == len(OBSTACLES):
        state["markers_complete"] = True
    return f"{branches} branches, forecasts of obstacles {found}"


def check_event(m, state):
    check_header(m.header, "events")
    check(m.cycle_count >= 1, f"events.cycle_count = {m.cycle_count}")
    check(math.isfinite(m.cycle_time_ms) and 0.0 <= m.cycle_time_ms < 60_000.0,
          f"events.cycle_time_ms = {m.cycle_time_ms}")
    check(isinstance(m.has_plan, bool) and isinstance(m.fallback, bool), "events: flags are not bools")
    for e in m.events:
        check(e.startswith("{") and e.endswith("}"), f"events.events: {e!r} is not a JSON object")
    return f"cycle {m.cycle_count}, {m.cycle_time_ms:.1f} ms, has_plan {m.has_plan}, {len(m.events)} events"


def fmt(v):
    return "(" + ", ".join(f"{c:.2f}" for c in v) + ")"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--domain", type=int, required=True)
    ap.add_argument("--px4", action="store_true", help="the node runs with --px4")
    ap.add_argument("--sim-time", type=float, metavar="START",
                    help="publish /clock from START s (the node runs with --use-sim-time)")
    ap.add_argument("--observe-world", type=float, metavar="START",
                    help="only observe a trust-sim dds-world flight whose clock starts at START s")
    ap.add_argument("--cloud", metavar="POINTS",
                    help="publish these map-frame points (x,y,z;...) as point clouds")
    ap.add_argument("--timeout", type=float, default=40.0)
    args = ap.parse_args()
    global CLOCK
    CLOCK = PeerClock(args.sim_time)

    dp = DomainParticipant(args.domain)
    best_effort = Qos(Policy.Reliability.BestEffort, Policy.Durability.Volatile, Policy.History.KeepLast(10))
    reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.Volatile,
                   Policy.History.KeepLast(10))

    def writer(name, ty, qos):
        return DataWriter(dp, Topic(dp, "rt/" + name, ty), qos=qos)

    def reader(name, ty, qos):
        return DataReader(dp, Topic(dp, "rt/" + name, ty), qos=qos)

    if args.observe_world is not None:
        return observe_world(args, reader, best_effort, reliable)
    if args.cloud is not None:
        return publish_clouds(args, writer, reader, best_effort, reliable)

    clock_w = writer("clock", Clock, reliable) if args.sim_time is not None else None
    odom_w = writer("odom", Odometry, best_effort)
    goal_w = writer("goal", PoseStamped, reliable)  # as RViz's "2D Goal Pose"
    obst_w = writer("obstacles", MovingObstacleArray, best_effort)

    checks = {
        "trajectory": (reader("trajectory", MultiDOFJointTrajectory, reliable), check_trajectory),
        "path": (reader("path", Path, reliable), check_path),
        "markers": (reader("markers", MarkerArray, reliable), check_markers),
        "events": (reader("events", PlannerEvent, reliable), check_event),
        "tf": (reader("tf", TFMessage, reliable), check_tf),
    }
    if args.px4:
        checks["fmu/in/trajectory_setpoint"] = (
            reader("fmu/in/trajectory_setpoint", TrajectorySetpoint, best_effort), check_px4_setpoint)
    else:
        checks["setpoint"] = (reader("setpoint", MultiDOFJointTrajectory, best_effort), check_setpoint)

    state = {"markers_complete": False, "yaws_matched": False, "odom_stamps": set(),
             "trajectory_yaws": {}, "path_yaws": {}, "px4_yaws": {}}
    passed = {}
    deadline = time.monotonic() + args.timeout
    next_publish = time.monotonic()
    while time.monotonic() < deadline:
        if clock_w is not None:
            clock_w.write(Clock(clock=now_stamp()))
        if time.monotonic() >= next_publish:
            stamp = now_stamp()
            state["odom_stamps"].add((stamp.sec, stamp.nanosec))
            odom = Odometry(header=Header(stamp=stamp, frame_id=WORLD), child_frame_id=BODY)
            odom.pose.pose.position = Point(*START)
            # A yaw of 90°: the (zero) body-frame twist stays zero in the world.
            odom.pose.pose.orientation = Quaternion(*ODOM_Q)
            odom.pose.covariance = [0.01 if i % 7 == 0 else 0.0 for i in range(36)]
            odom_w.write(odom)
            goal_w.write(PoseStamped(header=Header(stamp=stamp, frame_id=WORLD),
                                     pose=Pose(position=Point(*GOAL))))
            obst_w.write(MovingObstacleArray(
                header=Header(stamp=stamp, frame_id=WORLD),
                obstacles=[MovingObstacle(id=i, shape=s, size=Vector3(*size), position=Point(*p),
                                          covariance=[0.04 if k % 7 == 0 else 0.0 for k in range(36)])
                           for i, s, size, p in OBSTACLES]))
            next_publish += 0.1
        for name, (rd, fn) in checks.items():
            for sample in rd.take(N=50):
                try:
                    summary = fn(sample, state)
                except CheckFailed as e:
                    print(f"peer: FAILED {name}: {e}", file=sys.stderr)
                    return 1
                if summary is None:
                    continue
                if name not in passed:
                    print(f"peer: {name} ok: {summary}", file=sys.stderr)
                passed[name] = summary
        if len(passed) == len(checks) and state["markers_complete"] and state["yaws_matched"]:
            print(f"peer: markers complete: {passed['markers']}", file=sys.stderr)
            print("peer: a path and a trajectory of one cycle carry the same yaws", file=sys.stderr)
            if state["px4_yaws"]:
                print(f"peer: px4 yaws checked: {state['px4_yaws']}", file=sys.stderr)
            print("peer: every check passed", file=sys.stderr)
            return 0
        time.sleep(0.01)
    missing = [n for n in checks if n not in passed]
    if not state["markers_complete"]:
        missing.append("markers with a branch and both obstacles' forecasts")
    if not state["yaws_matched"]:
        missing.append("a path and a trajectory of the same cycle")
    print(f"peer: FAILED: nothing (valid) within {args.timeout} s from {missing}; received {sorted(passed)}",
          file=sys.stderr)
    return 1


def observe_world(args, reader, best_effort, reliable):
    """Checks a `trust-sim dds-world` flight whose clock starts at args.observe_world: its
    `/clock` (decoded field by field: increasing, from the start given on), its odometry on that
    clock, and the node's `/tf` (the world's odometry, same stamps) and `trajectory` (stamped on
    the world's clock: the node follows /clock)."""
    start = args.observe_world
    clock_r = reader("clock", Clock, best_effort)
    odom_r = reader("odom", Odometry, best_effort)
    tf_r = reader("tf", TFMessage, reliable)
    traj_r = reader("trajectory", MultiDOFJointTrajectory, reliable)
    latest = None
    clocks, odom_stamps, tf_matched, trajectories = 0, {}, 0, 0
    deadline = time.monotonic() + args.timeout
    try:
        while time.monotonic() < deadline:
            for c in clock_r.take(N=100):
                s = seconds(c.clock)
                check(0 <= c.clock.nanosec < 1_000_000_000, f"clock.nanosec = {c.clock.nanosec}")
                check(start <= s < start + 600.0, f"clock = {s:.3f}: not on the world's clock from {start}")
                check(latest is None or s >= latest, f"clock went back: {s:.6f} after {latest}")
                latest = s
                clocks += 1
            for o in odom_r.take(N=100):
                s = seconds(o.header.stamp)
                check(o.header.frame_id == WORLD, f"world odom.header.frame_id = {o.header.frame_id!r}")
                check(start <= s < start + 600.0, f"world odom stamp {s:.3f}: not on the world's clock")
                q = o.pose.pose.orientation
                check(abs(q.x ** 2 + q.y ** 2 + q.z ** 2 + q.w ** 2 - 1.0) < 1e-9, f"world odom orientation {q}")
                odom_stamps[(o.header.stamp.sec, o.header.stamp.nanosec)] = o
            for m in tf_r.take(N=100):
                check(len(m.transforms) == 1, f"tf: {len(m.transforms)} transforms")
                tr = m.transforms[0]
                check((tr.header.frame_id, tr.child_frame_id) == (WORLD, BODY),
                      f"tf frames {tr.header.frame_id!r} -> {tr.child_frame_id!r}")
                o = odom_stamps.get((tr.header.stamp.sec, tr.header.stamp.nanosec))
                if o is None:
                    continue  # an odometry this peer did not receive (best effort)
                check(xyz(tr.transform.translation) == xyz(o.pose.pose.position), "tf translation is not the odometry's")
                q, r = tr.transform.rotation, o.pose.pose.orientation
                check(max(abs(a - b) for a, b in zip((q.x, q.y, q.z, q.w), (r.x, r.y, r.z, r.w))) < 1e-9,
                      f"tf rotation {q} is not the odometry's {r}")
                tf_matched += 1
            for m in traj_r.take(N=10):
                s = seconds(m.header.stamp)
                check(latest is not None and abs(s - latest) < 5.0,
                      f"trajectory stamped {s:.3f}: the world's clock reads {latest}")
                trajectories += 1
            if clocks >= 50 and tf_matched >= 5 and trajectories >= 3:
                print(f"peer: world clock ok: {clocks} /clock from {start} on, now {latest:.3f}", file=sys.stderr)
                print(f"peer: tf ok: {tf_matched} transforms equal to the world's odometry of the same stamp",
                      file=sys.stderr)
                print(f"peer: trajectory ok: {trajectories} stamped on the world's clock", file=sys.stderr)
                print("peer: every check passed", file=sys.stderr)
                return 0
            time.sleep(0.01)
    except CheckFailed as e:
        print(f"peer: FAILED observing the world: {e}", file=sys.stderr)
        return 1
    print(f"peer: FAILED: within {args.timeout} s {clocks} /clock, {tf_matched} tf matched, "
          f"{trajectories} trajectories", file=sys.stderr)
    return 1


def cloud_message(frame, stamp, rows, f64, big_endian, row_padding):
    """A PointCloud2 of `rows` (lists of (x, y, z), NaN for a hole) built from the message
    definition: an `intensity` FLOAT32 at offset 0, then x, y, z (FLOAT64 or FLOAT32) after a
    4-byte gap, point_step rounded up to 8, `row_padding` bytes after each row."""
    size = 8 if f64 else 4
    kind = FLOAT64 if f64 else FLOAT32
    offsets = {"x": 8, "y": 8 + size, "z": 8 + 2 * size}
    point_step = (8 + 3 * size + 7) // 8 * 8
    width = len(rows[0])
    row_step = width * point_step + row_padding
    order = ">" if big_endian else "<"
    data = bytearray(row_step * len(rows))
    for r, row in enumerate(rows):
        for c, (x, y, z) in enumerate(row):
            at = r * row_step + c * point_step
            struct.pack_into(order + "f", data, at, 1.0)  # intensity
            for name, v in (("x", x), ("y", y), ("z", z)):
                struct.pack_into(order + ("d" if f64 else "f"), data, at + offsets[name], v)
    fields = [PointField(name="intensity", offset=0, datatype=FLOAT32, count=1)] + [
        PointField(name=n, offset=offsets[n], datatype=kind, count=1) for n in ("z", "x", "y")]
    dense = all(all(math.isfinite(v) for v in p) for row in rows for p in row)
    return PointCloud2(header=Header(stamp=stamp, frame_id=frame), height=len(rows), width=width,
                       fields=fields, is_bigendian=big_endian, point_step=point_step, row_step=row_step,
                       data=list(data), is_dense=dense)


def to_body(p):
    """A map-frame point in the body frame of the odometry sent (at START, yaw ODOM_YAW)."""
    dx, dy, dz = (p[0] - START[0], p[1] - START[1], p[2] - START[2])
    c, s = math.cos(ODOM_YAW), math.sin(ODOM_YAW)
    return (c * dx + s * dy, -s * dx + c * dy, dz)


def publish_clouds(args, writer, reader, best_effort, reliable):
    """--cloud: odometry at START (yaw ODOM_YAW) and the points as two clouds (module docs),
    every 0.1 s, for 3 s after the node's first /tf."""
    points = [tuple(float(c) for c in p.split(",")) for p in args.cloud.split(";") if p]
    check(len(points) >= 2 and all(len(p) == 3 for p in points), f"--cloud {args.cloud!r}: x,y,z;x,y,z...")
    half = len(points) // 2
    in_map, in_body = points[:half], [to_body(p) for p in points[half:]]
    width = (len(in_body) + 1) // 2
    nan = (math.nan, math.nan, math.nan)
    body_rows = [in_body[:width], in_body[width:] + [nan] * (2 * width - len(in_body))]
    odom_w = writer("odom", Odometry, best_effort)
    cloud_w = writer("cloud", PointCloud2, best_effort)
    tf_r = reader("tf", TFMessage, reliable)
    seen_tf = None
    sent = 0
    deadline = time.monotonic() + args.timeout
    while time.monotonic() < deadline:
        stamp = now_stamp()
        odom = Odometry(header=Header(stamp=stamp, frame_id=WORLD), child_frame_id=BODY)
        odom.pose.pose.position = Point(*START)
        odom.pose.pose.orientation = Quaternion(*ODOM_Q)
        odom_w.write(odom)
        # The clouds after their odometry, stamped as it: the node places them by that pose.
        time.sleep(0.01)
        cloud_w.write(cloud_message(WORLD, stamp, [in_map], f64=False, big_endian=False, row_padding=0))
        cloud_w.write(cloud_message(BODY, stamp, body_rows, f64=True, big_endian=True, row_padding=5))
        sent += 1
        if seen_tf is None and tf_r.take(N=10):
            seen_tf = time.monotonic()
            print("peer: the node's /tf received: discovery done", file=sys.stderr)
        if seen_tf is not None and time.monotonic() - seen_tf > 3.0:
            print(f"peer: {sent} pairs of clouds sent ({len(in_map)} map-frame points FLOAT32 LE, "
                  f"{len(in_body)} body-frame points FLOAT64 BE in 2 rows)", file=sys.stderr)
            return 0
        time.sleep(0.09)
    print(f"peer: FAILED: no /tf from the node within {args.timeout} s", file=sys.stderr)
    return 1


if __name__ == "__main__":
    sys.exit(main())

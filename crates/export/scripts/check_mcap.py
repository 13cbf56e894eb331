#!/usr/bin/env python3
"""Independent check of a `trust-sim export --mcap` file with the Python `mcap` reader.

Usage: python3 check_mcap.py FILE.mcap

Checks the channels, their schemas and encodings, that the summary's message counts match the
messages actually read, that every JSON message parses and every CDR message starts with the
CDR_LE encapsulation header and decodes (PoseStamped: frame "world", 7 finite float64), that
the per-state topics have one message per state and the periodic ones (obstacles, paths) fewer. When `mcap-ros2-support` is installed, every
ROS 2 message is also decoded by its own CDR decoder from the `ros2msg` schema text in the file,
and the last path must end at the last pose. Exit status 1 on the first failure.
"""
import json
import math
import struct
import sys
from collections import Counter

from mcap.reader import make_reader

EXPECTED = {
    "/vehicle/pose": ("foxglove.PoseInFrame", "jsonschema", "json"),
    "/tf": ("foxglove.FrameTransform", "jsonschema", "json"),
    "/scene/map": ("foxglove.SceneUpdate", "jsonschema", "json"),
    "/scene/obstacles": ("foxglove.SceneUpdate", "jsonschema", "json"),
    "/scene/path": ("foxglove.SceneUpdate", "jsonschema", "json"),
    "/ros/vehicle/pose": ("geometry_msgs/msg/PoseStamped", "ros2msg", "cdr"),
    "/ros/vehicle/path": ("nav_msgs/msg/Path", "ros2msg", "cdr"),
}
OPTIONAL = {"/scene/branches": ("foxglove.SceneUpdate", "jsonschema", "json")}


def fail(message):
    print(f"check_mcap: FAIL: {message}")
    sys.exit(1)


def pose_stamped(data):
    """Decodes a CDR geometry_msgs/msg/PoseStamped: (sec, nanosec, frame_id, 7 floats)."""
    if data[:4] != b"\x00\x01\x00\x00":
        fail(f"CDR encapsulation header {data[:4]!r}, expected 00 01 00 00")
    body = data[4:]
    sec, nanosec, length = struct.unpack_from("<iII", body, 0)
    frame = body[12:12 + length - 1].decode()
    offset = 12 + length
    offset += (8 - offset % 8) % 8
    values = struct.unpack_from("<7d", body, offset)
    return sec, nanosec, frame, values


def main():
    if len(sys.argv) != 2:
        fail("usage: check_mcap.py FILE.mcap")
    path = sys.argv[1]
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        if summary is None:
            fail("no summary section")
        channels = {}
        for c in summary.channels.values():
            s = summary.schemas[c.schema_id]
            channels[c.topic] = (s.name, s.encoding, c.message_encoding)
        for topic, want in EXPECTED.items():
            if channels.get(topic) != want:
                fail(f"{topic}: {channels.get(topic)}, expected {want}")
        for topic, got in channels.items():
            if topic not in EXPECTED and OPTIONAL.get(topic) != got:
                fail(f"unexpected channel {topic}: {got}")
        counts = Counter()
        last_time = -1
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            counts[channel.topic] += 1
            if message.log_time < last_time:
                fail(f"{channel.topic}: log time {message.log_time} after {last_time}")
            last_time = message.log_time
            if channel.message_encoding == "json":
                json.loads(message.data)
            elif schema.name == "geometry_msgs/msg/PoseStamped":
                sec, nanosec, frame, values = pose_stamped(message.data)
                if frame != "world" or not all(math.isfinite(v) for v in values):
                    fail(f"{channel.topic}: frame {frame!r}, values {values}")
                if sec * 1_000_000_000 + nanosec != message.log_time:
                    fail(f"{channel.topic}: stamp {sec}.{nanosec} vs log time {message.log_time}")
        by_topic = {summary.channels[i].topic: n
                    for i, n in summary.statistics.channel_message_counts.items()}
        if dict(counts) != by_topic:
            fail(f"messages read {dict(counts)} differ from the summary's counts {by_topic}")
        states = counts["/vehicle/pose"]
        for topic in ("/tf", "/ros/vehicle/pose"):
            if counts[topic] != states:
                fail(f"{topic}: {counts[topic]} messages, /vehicle/pose has {states}")
        # Obstacles at 10 Hz, scene paths at 2 Hz, ROS paths at 0.2 Hz (and each at the end):
        # fewer than the states, and in that order.
        if not (1 <= counts["/ros/vehicle/path"] <= counts["/scene/path"]
                <= counts["/scene/obstacles"] <= states):
            fail(f"periodic topic counts {dict(counts)}")
        if counts["/scene/map"] != 1:
            fail(f"map count {counts['/scene/map']}")
    ros2 = decode_ros2(path)
    print(f"check_mcap: ok: {path}: {sum(counts.values())} messages, "
          + ", ".join(f"{t} {n}" for t, n in sorted(counts.items())) + f"; {ros2}")


def decode_ros2(path):
    try:
        from mcap_ros2.decoder import DecoderFactory
    except ImportError:
        return "ROS 2 decoding skipped (pip install mcap-ros2-support)"
    last_pose, last_path, n = None, None, 0
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, channel, _, msg in reader.iter_decoded_messages(
                topics=["/ros/vehicle/pose", "/ros/vehicle/path"], log_time_order=False):
            n += 1
            if channel.topic == "/ros/vehicle/pose":
                last_pose = msg
            else:
                last_path = msg
    end = last_path.poses[-1].pose.position
    if (end.x, end.y, end.z) != (last_pose.pose.position.x, last_pose.pose.position.y,
                                 last_pose.pose.position.z):
        fail(f"the last path ends at {end}, the last pose is {last_pose.pose.position}")
    return f"{n} ROS 2 messages decoded by mcap_ros2"


if __name__ == "__main__":
    main()

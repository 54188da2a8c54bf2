#!/usr/bin/python3
"""Writes a stretch of a 7-Scenes frames-layout folder as a ROS bag, for tests/io/bag_test.cpp.

ROS 1 (--format ros1): written by Debian's python3-rosbag (rosbag.Bag) with the genpy message
classes of python3-sensor-msgs, python3-tf2-msgs and python3-geometry-msgs: serialization and
container are theirs, not ours.

rosbag2 SQLite (--format rosbag2): the container (metadata.yaml, .db3 with rosbag2's topics and
messages tables) written with Python's sqlite3 module, and each message serialized to CDR
(XCDR1 little-endian) by hand in this script, from the .msg definitions: ours, not an independent
tool's. With --cdr-tool (tests/ros/cyclone_cdr), every message is serialized by Cyclone DDS
instead, as a ROS 2 recorder on rmw_cyclonedds_cpp stores it (its encapsulation options and
trailing padding included).

Topics: /camera/color/image_raw (bgr8), /camera/depth/image_raw (16UC1 mm or 32FC1 m),
/camera/depth/camera_info, /tf (world -> camera_link, one per frame), /tf_static
(camera_link -> camera_depth_optical_frame). The colour stamps lag the depth stamps by 5 ms.

MCAP (--format mcap, chunks none, lz4 or zstd via Debian's python3-lz4 and python3-zstandard): the
container written by this script from the published specification, messages in the same
hand-serialized CDR (or Cyclone's, with --cdr-tool).
"""
import argparse
import math
import os
import sqlite3
import struct
import subprocess
import sys

import cv2
import numpy as np

OPTICAL = "camera_depth_optical_frame"
# camera_link (x forward, y left, z up) to the optical frame (x right, y down, z forward): REP 103.
R_LINK_OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


def quaternion(R):
    """(x, y, z, w) of a rotation matrix (Shepperd)."""
    t = np.trace(R)
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        return ((R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s, 0.25 * s)
    i = int(np.argmax(np.diag(R)))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = math.sqrt(1.0 + R[i, i] - R[j, j] - R[k, k]) * 2
    q = [0.0, 0.0, 0.0]
    q[i] = 0.25 * s
    q[j] = (R[j, i] + R[i, j]) / s
    q[k] = (R[k, i] + R[i, k]) / s
    return (q[0], q[1], q[2], (R[k, j] - R[j, k]) / s)


def rotation(q):
    x, y, z, w = q
    n = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def rigid(pose):
    """The pose as TF can carry it: 7-Scenes' rotations are orthonormal to about 1e-5 only, a
    quaternion makes them exactly so."""
    out = pose.copy()
    out[:3, :3] = rotation(quaternion(pose[:3, :3]))
    return out


def write_oracle(folder, out, first, count, frames):
    """The same frames as a frames-layout folder (images linked) with the rigid poses the bag
    carries: the oracle the tests compare the bag with."""
    os.makedirs(out, exist_ok=True)
    names = sorted(f[: -len(".depth.png")] for f in os.listdir(folder) if f.endswith(".depth.png"))[first : first + count]
    for src in ["camera-intrinsics.txt"]:
        with open(os.path.join(folder, src)) as a, open(os.path.join(out, src), "w") as b:
            b.write(a.read())
    for name, (_, _, pose) in zip(names, frames):
        for ext in (".color.jpg", ".color.png", ".depth.png"):
            if os.path.exists(os.path.join(folder, name + ext)) and not os.path.exists(os.path.join(out, name + ext)):
                os.symlink(os.path.abspath(os.path.join(folder, name + ext)), os.path.join(out, name + ext))
        np.savetxt(os.path.join(out, name + ".pose.txt"), pose, fmt="%.17g")


def load(folder, first, count):
    K = np.loadtxt(os.path.join(folder, "camera-intrinsics.txt"))
    names = sorted(f[: -len(".color.jpg")] for f in os.listdir(folder) if f.endswith(".color.jpg") or f.endswith(".color.png"))
    if not names:
        names = sorted(f[: -len(".color.png")] for f in os.listdir(folder) if f.endswith(".color.png"))
    frames = []
    for name in names[first : first + count]:
        ext = ".color.jpg" if os.path.exists(os.path.join(folder, name + ".color.jpg")) else ".color.png"
        bgr = cv2.imread(os.path.join(folder, name + ext), cv2.IMREAD_COLOR)
        depth = cv2.imread(os.path.join(folder, name + ".depth.png"), cv2.IMREAD_UNCHANGED)
        pose = rigid(np.loadtxt(os.path.join(folder, name + ".pose.txt")))
        frames.append((bgr, depth, pose))
    return K, frames


def depth_payload(depth, encoding):
    if encoding == "16UC1":
        return depth.astype("<u2"), 2
    metres = depth.astype(np.float32) / 1000.0
    metres[(depth == 0) | (depth == 65535)] = np.nan
    return metres.astype("<f4"), 4


def link_pose(pose):
    """T_world_link such that T_world_link * T_link_optical is the frame's T_world_camera."""
    T_link_optical = np.eye(4)
    T_link_optical[:3, :3] = R_LINK_OPTICAL
    return pose @ np.linalg.inv(T_link_optical)


def write_ros1(path, K, frames, depth_encoding, compression, t0):
    import genpy
    import rosbag
    from geometry_msgs.msg import TransformStamped
    from sensor_msgs.msg import CameraInfo, Image
    from tf2_msgs.msg import TFMessage

    def stamp(t):
        return genpy.Time.from_sec(t)

    def transform(t, parent, child, T):
        m = TransformStamped()
        m.header.stamp = stamp(t)
        m.header.frame_id = parent
        m.child_frame_id = child
        m.transform.translation.x, m.transform.translation.y, m.transform.translation.z = (float(v) for v in T[:3, 3])
        q = quaternion(T[:3, :3])
        m.transform.rotation.x, m.transform.rotation.y, m.transform.rotation.z, m.transform.rotation.w = q
        return m

    with rosbag.Bag(path, "w", compression=compression) as bag:
        T_link_optical = np.eye(4)
        T_link_optical[:3, :3] = R_LINK_OPTICAL
        bag.write("/tf_static", TFMessage([transform(t0, "camera_link", OPTICAL, T_link_optical)]), stamp(t0))
        for i, (bgr, depth, pose) in enumerate(frames):
            t = t0 + i / 15.0
            bag.write("/tf", TFMessage([transform(t, "world", "camera_link", link_pose(pose))]), stamp(t))
            info = CameraInfo()
            info.header.stamp = stamp(t)
            info.header.frame_id = OPTICAL
            info.height, info.width = depth.shape
            info.distortion_model = "plumb_bob"
            info.D = [0.0] * 5
            info.K = [float(v) for v in K.flatten()]
            info.R = [1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0]
            info.P = [K[0, 0], 0, K[0, 2], 0, 0, K[1, 1], K[1, 2], 0, 0, 0, 1, 0]
            bag.write("/camera/depth/camera_info", info, stamp(t))
            d = Image()
            d.header.stamp = stamp(t)
            d.header.frame_id = OPTICAL
            d.height, d.width = depth.shape
            payload, size = depth_payload(depth, depth_encoding)
            d.encoding = depth_encoding
            d.is_bigendian = 0
            d.step = d.width * size
            d.data = payload.tobytes()
            bag.write("/camera/depth/image_raw", d, stamp(t))
            c = Image()
            c.header.stamp = stamp(t + 0.005)
            c.header.frame_id = "camera_color_optical_frame"
            c.height, c.width = bgr.shape[:2]
            c.encoding = "bgr8"
            c.step = c.width * 3
            c.data = bgr.tobytes()
            bag.write("/camera/color/image_raw", c, stamp(t + 0.005))


class Cdr:
    """XCDR1 little-endian, as ROS 2's middlewares write it: each primitive aligned to its size,
    counted from the end of the 4-byte encapsulation header; strings with a trailing NUL."""

    def __init__(self):
        self.b = bytearray(b"\x00\x01\x00\x00")

    def align(self, n):
        while (len(self.b) - 4) % n:
            self.b.append(0)

    def u8(self, v):
        self.b += struct.pack("<B", v)

    def u32(self, v):
        self.align(4)
        self.b += struct.pack("<I", v)

    def i32(self, v):
        self.align(4)
        self.b += struct.pack("<i", v)

    def f64(self, v):
        self.align(8)
        self.b += struct.pack("<d", v)

    def string(self, s):
        data = s.encode() + b"\x00"
        self.u32(len(data))
        self.b += data

    def header(self, t, frame):
        sec = int(math.floor(t))
        self.i32(sec)
        self.u32(int(round((t - sec) * 1e9)))
        self.string(frame)

    def octets(self, data):
        self.u32(len(data))
        self.b += data


def cdr_image(t, frame, height, width, encoding, step, data):
    c = Cdr()
    c.header(t, frame)
    c.u32(height)
    c.u32(width)
    c.string(encoding)
    c.u8(0)
    c.u32(step)
    c.octets(data)
    return bytes(c.b)


def cdr_tf(transforms):
    c = Cdr()
    c.u32(len(transforms))
    for t, parent, child, T in transforms:
        c.header(t, parent)
        c.string(child)
        for v in T[:3, 3]:
            c.f64(float(v))
        for v in quaternion(T[:3, :3]):
            c.f64(float(v))
    return bytes(c.b)


def cdr_info(t, frame, height, width, K):
    c = Cdr()
    c.header(t, frame)
    c.u32(height)
    c.u32(width)
    c.string("plumb_bob")
    c.u32(5)
    for _ in range(5):
        c.f64(0.0)
    for v in K.flatten():
        c.f64(float(v))
    for v in (1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0):
        c.f64(float(v))
    for v in (K[0, 0], 0, K[0, 2], 0, 0, K[1, 1], K[1, 2], 0, 0, 0, 1, 0):
        c.f64(float(v))
    c.u32(0)
    c.u32(0)
    for _ in range(4):
        c.u32(0)
    c.u8(0)
    return bytes(c.b)


class HandCdr:
    """The messages serialized by this script."""
    image = staticmethod(cdr_image)
    tf = staticmethod(cdr_tf)
    info = staticmethod(cdr_info)


class CycloneCdr:
    """The messages serialized by Cyclone DDS (tests/ros/cyclone_cdr.cpp, protocol there)."""

    def __init__(self, tool):
        self.p = subprocess.Popen([tool], stdin=subprocess.PIPE, stdout=subprocess.PIPE)

    def ask(self, text, data=b""):
        self.p.stdin.write(text.encode() + b"\n" + data)
        self.p.stdin.flush()
        head = self.p.stdout.read(4)
        if len(head) != 4:
            sys.exit("cyclone_cdr gave no answer to: " + text.split("\n")[0])
        return self.p.stdout.read(struct.unpack("<I", head)[0])

    @staticmethod
    def stamp(t, frame):
        sec = int(math.floor(t))
        return "%d %d %s" % (sec, int(round((t - sec) * 1e9)), frame)

    def image(self, t, frame, height, width, encoding, step, data):
        return self.ask("image %s %d %d %s %d %d" % (self.stamp(t, frame), height, width, encoding, step, len(data)), data)

    def tf(self, transforms):
        lines = ["tf %d" % len(transforms)]
        for t, parent, child, T in transforms:
            values = [float(v) for v in T[:3, 3]] + [float(v) for v in quaternion(T[:3, :3])]
            lines.append("%s %s %s" % (self.stamp(t, parent), child, " ".join(repr(v) for v in values)))
        return self.ask("\n".join(lines))

    def info(self, t, frame, height, width, K):
        P = (K[0, 0], 0, K[0, 2], 0, 0, K[1, 1], K[1, 2], 0, 0, 0, 1, 0)
        values = [0.0] * 5 + list(K.flatten()) + [1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0] + list(P)
        return self.ask("info %s %d %d plumb_bob 5 %s" % (self.stamp(t, frame), height, width,
                                                          " ".join(repr(float(v)) for v in values)))


TOPICS = [("/tf", "tf2_msgs/msg/TFMessage"), ("/tf_static", "tf2_msgs/msg/TFMessage"),
          ("/camera/depth/camera_info", "sensor_msgs/msg/CameraInfo"), ("/camera/depth/image_raw", "sensor_msgs/msg/Image"),
          ("/camera/color/image_raw", "sensor_msgs/msg/Image")]


def cdr_rows(K, frames, depth_encoding, t0, cdr):
    """(topic id in TOPICS from 1, time, CDR bytes) of every message, in order."""
    cdr_image, cdr_tf, cdr_info = cdr.image, cdr.tf, cdr.info
    rows = []
    T_link_optical = np.eye(4)
    T_link_optical[:3, :3] = R_LINK_OPTICAL
    rows.append((2, t0, cdr_tf([(t0, "camera_link", OPTICAL, T_link_optical)])))
    for i, (bgr, depth, pose) in enumerate(frames):
        t = t0 + i / 15.0
        h, w = depth.shape
        payload, size = depth_payload(depth, depth_encoding)
        rows.append((1, t, cdr_tf([(t, "world", "camera_link", link_pose(pose))])))
        rows.append((3, t, cdr_info(t, OPTICAL, h, w, K)))
        rows.append((4, t, cdr_image(t, OPTICAL, h, w, depth_encoding, w * size, payload.tobytes())))
        rows.append((5, t + 0.005, cdr_image(t + 0.005, "camera_color_optical_frame", h, w, "bgr8", w * 3, bgr.tobytes())))
    return rows


def write_rosbag2(folder, K, frames, depth_encoding, t0, cdr):
    os.makedirs(folder, exist_ok=True)
    db_name = os.path.basename(folder.rstrip("/")) + "_0.db3"
    db = sqlite3.connect(os.path.join(folder, db_name))
    db.execute("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
               "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL)")
    db.execute("CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, data BLOB NOT NULL)")
    for i, (name, type_) in enumerate(TOPICS, 1):
        db.execute("INSERT INTO topics VALUES (?, ?, ?, 'cdr', '')", (i, name, type_))
    rows = cdr_rows(K, frames, depth_encoding, t0, cdr)
    for topic, t, data in rows:
        db.execute("INSERT INTO messages(topic_id, timestamp, data) VALUES (?, ?, ?)", (topic, int(round(t * 1e9)), data))
    db.commit()
    db.close()
    with open(os.path.join(folder, "metadata.yaml"), "w") as f:
        f.write("rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n"
                "  relative_file_paths:\n    - %s\n  message_count: %d\n" % (db_name, len(rows)))


def write_mcap(path, K, frames, depth_encoding, compression, t0, lie_crc, cdr):
    """MCAP from its specification (mcap.dev/spec): a Header, one Schema and one Channel per
    topic, the messages in chunks of one frame each (CRC-32 of the uncompressed records), Data End,
    an empty summary, Footer. Written by us, not by an independent tool."""
    import binascii

    def record(op, content):
        return struct.pack("<BQ", op, len(content)) + content

    def string(s):
        b = s.encode()
        return struct.pack("<I", len(b)) + b

    magic = b"\x89MCAP0\r\n"
    out = bytearray(magic)
    out += record(0x01, string("ros2") + string("scenewatch tests/io/make_bag.py"))
    for i, (name, type_) in enumerate(TOPICS, 1):
        out += record(0x03, struct.pack("<H", i) + string(type_) + string("ros2msg") + struct.pack("<I", 0))
        out += record(0x04, struct.pack("<HH", i, i) + string(name) + string("cdr") + struct.pack("<I", 0))
    rows = cdr_rows(K, frames, depth_encoding, t0, cdr)
    # One chunk per frame: the rows from one /tf message to the next.
    groups, current = [], []
    for row in rows:
        if row[0] == 1 and current:
            groups.append(current)
            current = []
        current.append(row)
    groups.append(current)
    sequence = 0
    for group in groups:
        records = bytearray()
        for topic, t, data in group:
            ns = int(round(t * 1e9))
            sequence += 1
            records += record(0x05, struct.pack("<HIQQ", topic, sequence, ns, ns) + data)
        crc = binascii.crc32(bytes(records)) & 0xFFFFFFFF
        if lie_crc:
            crc ^= 0x1
        if compression == "lz4":
            import lz4.frame
            packed = lz4.frame.compress(bytes(records))
        elif compression == "zstd":
            import zstandard
            packed = zstandard.ZstdCompressor().compress(bytes(records))
        else:
            packed = bytes(records)
        start = int(round(group[0][1] * 1e9))
        end = int(round(group[-1][1] * 1e9))
        name = "" if compression == "none" else compression
        out += record(0x06, struct.pack("<QQQI", start, end, len(records), crc) + string(name) + struct.pack("<Q", len(packed)) + packed)
    out += record(0x0F, struct.pack("<I", 0))
    out += record(0x02, struct.pack("<QQI", 0, 0, 0))
    out += magic
    with open(path, "wb") as f:
        f.write(out)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("folder")
    p.add_argument("out")
    p.add_argument("--first", type=int, default=0)
    p.add_argument("--count", type=int, default=10)
    p.add_argument("--format", choices=["ros1", "rosbag2", "mcap"], default="ros1")
    p.add_argument("--compression", choices=["none", "bz2", "lz4", "zstd"], default="none")
    p.add_argument("--lie-crc", action="store_true", help="mcap: every chunk's CRC off by one bit")
    p.add_argument("--oracle", help="also write the frames as a folder with the bag's (rigid) poses here")
    p.add_argument("--depth-encoding", choices=["16UC1", "32FC1"], default="16UC1")
    p.add_argument("--cdr-tool", help="rosbag2, mcap: serialize the messages with this tests/ros/cyclone_cdr")
    a = p.parse_args()
    K, frames = load(a.folder, a.first, a.count)
    t0 = 1700000000.0
    if a.oracle:
        write_oracle(a.folder, a.oracle, a.first, a.count, frames)
    cdr = CycloneCdr(a.cdr_tool) if a.cdr_tool else HandCdr
    if a.format == "ros1":
        write_ros1(a.out, K, frames, a.depth_encoding, a.compression, t0)
    elif a.format == "rosbag2":
        write_rosbag2(a.out, K, frames, a.depth_encoding, t0, cdr)
    else:
        write_mcap(a.out, K, frames, a.depth_encoding, a.compression, t0, a.lie_crc, cdr)


if __name__ == "__main__":
    main()

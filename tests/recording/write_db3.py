#!/usr/bin/env python3
"""Writes a rosbag2 sqlite3 file with Python's sqlite3 and hand-packed CDR (struct), independent of the C++:
realsense-ros 4.x topics, a wall 1.5 m ahead of a static camera, 4 frames at 15 Hz, 64x48 16UC1, /tf_static and
/odom. Usage: write_db3.py OUT.db3 humble|jazzy [nomessages|badtype]"""
import sqlite3
import struct
import sys


class Cdr:
    def __init__(self):
        self.b = bytearray(b"\x00\x01\x00\x00")

    def align(self, n):
        while (len(self.b) - 4) % n:
            self.b.append(0)

    def put(self, fmt, *values):
        self.align(struct.calcsize("<" + fmt.lstrip("0123456789")[0]))
        self.b += struct.pack("<" + fmt, *values)

    def string(self, s):
        data = s.encode() + b"\x00"
        self.put("I", len(data))
        self.b += data

    def header(self, t, frame):
        self.put("iI", int(t), int(round((t - int(t)) * 1e9)))
        self.string(frame)


def main():
    out, distro = sys.argv[1], sys.argv[2]
    mode = sys.argv[3] if len(sys.argv) > 3 else ""
    db = sqlite3.connect(out)
    db.execute("CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL)")
    db.execute("INSERT INTO schema VALUES (?, ?)", (4 if distro == "jazzy" else 3, distro))
    hash_col = ", type_description_hash TEXT NOT NULL" if distro == "jazzy" else ""
    db.execute("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
               "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL%s)" % hash_col)
    db.execute("CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL)")
    if mode != "nomessages":
        db.execute("CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
                   "data BLOB NOT NULL)")
    if distro == "jazzy":
        db.execute("CREATE TABLE message_definitions(id INTEGER PRIMARY KEY, topic_type TEXT NOT NULL, "
                   "encoding TEXT NOT NULL, encoded_message_definition TEXT NOT NULL, type_description_hash TEXT NOT NULL)")
        db.execute("INSERT INTO message_definitions VALUES (1, 'sensor_msgs/msg/Image', 'ros2msg', ?, '')",
                   ("std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\n"
                    "uint32 step\nuint8[] data\n",))
    topics = [(1, "/camera/camera/depth/image_rect_raw", "sensor_msgs/msg/Image" if mode != "badtype" else "sensor_msgs/Image"),
              (2, "/camera/camera/depth/camera_info", "sensor_msgs/msg/CameraInfo"),
              (3, "/tf_static", "tf2_msgs/msg/TFMessage"), (4, "/odom", "nav_msgs/msg/Odometry")]
    for tid, name, type_ in topics:
        row = (tid, name, type_, "cdr", "")
        db.execute("INSERT INTO topics VALUES (?, ?, ?, ?, ?%s)" % (", ''" if distro == "jazzy" else ""), row)
    if mode == "nomessages":
        db.commit()
        return
    W, H, t0, msg_id = 64, 48, 50.0, 0

    def add(topic_id, t, cdr):
        nonlocal msg_id
        msg_id += 1
        db.execute("INSERT INTO messages VALUES (?, ?, ?, ?)", (msg_id, topic_id, int(round(t * 1e9)), bytes(cdr.b)))

    c = Cdr()  # /tf_static: base_link -> camera_link -> camera_depth_optical_frame
    c.put("I", 2)
    for parent, child, q in (("base_link", "camera_link", (0, 0, 0, 1)),
                             ("camera_link", "camera_depth_optical_frame", (-0.5, 0.5, -0.5, 0.5))):
        c.header(t0, parent)
        c.string(child)
        c.put("3d", 0.0, 0.0, 0.4)
        c.put("4d", *q)
    add(3, t0, c)
    for i in range(4):
        t = t0 + i / 15.0
        c = Cdr()  # odometry: the robot still at x = 1
        c.header(t, "odom")
        c.string("base_link")
        c.put("7d", 1.0, 0, 0, 0, 0, 0, 1)
        c.put("36d", *([0.0] * 36))
        c.put("6d", *([0.0] * 6))
        c.put("36d", *([0.0] * 36))
        add(4, t, c)
        c = Cdr()
        c.header(t, "camera_depth_optical_frame")
        c.put("II", H, W)
        c.string("plumb_bob")
        c.put("I", 5)
        c.put("5d", 0, 0, 0, 0, 0)
        c.put("9d", 100, 0, 31.5, 0, 100, 23.5, 0, 0, 1)
        c.put("9d", 1, 0, 0, 0, 1, 0, 0, 0, 1)
        c.put("12d", 100, 0, 31.5, 0, 0, 100, 23.5, 0, 0, 0, 1, 0)
        c.put("II", 0, 0)
        c.put("IIII", 0, 0, 0, 0)
        c.put("B", 0)
        add(2, t, c)
        c = Cdr()
        c.header(t, "camera_depth_optical_frame")
        c.put("II", H, W)
        c.string("16UC1")
        c.put("B", 0)
        c.put("I", W * 2)
        c.put("I", W * H * 2)
        c.b += struct.pack("<%dH" % (W * H), *([1500] * (W * H)))
        add(1, t, c)
    db.commit()


if __name__ == "__main__":
    main()

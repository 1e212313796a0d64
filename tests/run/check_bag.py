#!/usr/bin/python3
"""Checks a stvl-bench ROS 1 bag against an expectations JSON.

Usage: /usr/bin/python3 check_bag.py BAG EXPECT.json
(Debian's python3-rosbag is installed for /usr/bin/python3 only.) Exit status: 0 when every check passes, 1 when
one fails (each failure is printed as a line starting with FAIL), 2 on bad arguments or an unreadable bag.

Expectations (every key optional):
{
  "compression": "none" | "bz2" | "lz4",
  "only_listed_topics": true,            # no topic in the bag beyond those under "topics"
  "topics": {
    "/camera/depth/points": {"type": "sensor_msgs/PointCloud2", "count": 4, "min_count": 1,
                             "frame_id": "camera_depth_optical_frame", "latched": false}
  },
  "tf_edges": [["map", "odom"], ["odom", "base_link"]],   # parent, child pairs found on /tf or /tf_static
  "depth": {"topic": "/camera/depth/image_rect_raw", "values_mm": [[...], ...]},   # one list per message
  "reprojection": false | {"image": ..., "info": ..., "cloud": ..., "tolerance_m": 0.002,
                           "tolerance_rel": 0.001, "tolerance_px": 0.05, "min_fraction": 0.99,
                           "complete": false, "max_frames": 3}
                  | [{...}, ...]        # one per camera
}
Checks made whenever the data is present, without expectations: the bag opens and `/usr/bin/rosbag info`
exits 0; header stamps (TF: transform stamps, Clock: clock) strictly increase per topic and equal the record
time; images, clouds and grids are self-consistent; the depth image reprojected with the camera info (pinhole,
K) gives the points of the cloud with the same stamp (default topics: /camera/depth/image_rect_raw,
/camera/depth/camera_info, /camera/depth/points).
"""
import array
import json
import math
import struct
import subprocess
import sys

import rosbag

FLOAT32 = 7
DEFAULT_REPROJECTION = {
    "image": "/camera/depth/image_rect_raw",
    "info": "/camera/depth/camera_info",
    "cloud": "/camera/depth/points",
    "tolerance_m": 0.002,
    "tolerance_rel": 0.001,
    "tolerance_px": 0.05,
    "min_fraction": 0.99,
    "complete": False,
    "max_frames": 3,
}


class Checker:
    def __init__(self):
        self.failures = []
        self.passed = 0

    def check(self, ok, message):
        if ok:
            self.passed += 1
        else:
            self.failures.append(message)
            print("FAIL: " + message)
        return ok


def stamp_of(msg):
    if hasattr(msg, "header"):
        return msg.header.stamp
    if hasattr(msg, "transforms") and msg.transforms:
        return msg.transforms[0].header.stamp
    if hasattr(msg, "clock"):
        return msg.clock
    return None


def frame_of(msg):
    if hasattr(msg, "header"):
        return msg.header.frame_id
    return None


def cloud_xyz(msg, c, topic):
    """Returns (xs, ys, zs) as flat float sequences, or None when the layout is unusable."""
    offsets = {f.name: f for f in msg.fields}
    for name in ("x", "y", "z"):
        f = offsets.get(name)
        if not c.check(f is not None and f.datatype == FLOAT32 and f.count == 1,
                       "%s: field %s must be one float32" % (topic, name)):
            return None
    n = msg.width * msg.height
    if not c.check(len(msg.data) == msg.row_step * msg.height and msg.row_step >= msg.point_step * msg.width,
                   "%s: data has %d bytes, row_step %d x height %d" % (topic, len(msg.data), msg.row_step,
                                                                       msg.height)):
        return None
    if not c.check(not msg.is_bigendian, "%s: big-endian clouds are not supported" % topic):
        return None
    ox, oy, oz = offsets["x"].offset, offsets["y"].offset, offsets["z"].offset
    if msg.point_step == 12 and (ox, oy, oz) == (0, 4, 8) and msg.row_step == 12 * msg.width:
        values = array.array("f")
        values.frombytes(bytes(msg.data))
        if sys.byteorder != "little":
            values.byteswap()
        return values[0::3], values[1::3], values[2::3]
    xs, ys, zs = [], [], []
    data = bytes(msg.data)
    for row in range(msg.height):
        for col in range(msg.width):
            base = row * msg.row_step + col * msg.point_step
            xs.append(struct.unpack_from("<f", data, base + ox)[0])
            ys.append(struct.unpack_from("<f", data, base + oy)[0])
            zs.append(struct.unpack_from("<f", data, base + oz)[0])
    assert len(xs) == n
    return xs, ys, zs


def depth_values(msg):
    values = array.array("H")
    data = bytes(msg.data)
    if msg.step == 2 * msg.width:
        values.frombytes(data)
    else:
        for row in range(msg.height):
            values.frombytes(data[row * msg.step: row * msg.step + 2 * msg.width])
    if (sys.byteorder == "little") == bool(msg.is_bigendian):
        values.byteswap()
    return values


def check_message(topic, msg, c):
    kind = msg._type
    if kind == "sensor_msgs/Image":
        if c.check(msg.encoding in ("16UC1", "mono16"), "%s: encoding %s, expected 16UC1" % (topic, msg.encoding)):
            c.check(msg.step >= 2 * msg.width and len(msg.data) == msg.step * msg.height,
                    "%s: %d bytes for %dx%d step %d" % (topic, len(msg.data), msg.width, msg.height, msg.step))
    elif kind == "sensor_msgs/PointCloud2":
        c.check(len(msg.data) == msg.row_step * msg.height,
                "%s: %d bytes, expected row_step %d x height %d" % (topic, len(msg.data), msg.row_step, msg.height))
        names = [f.name for f in msg.fields]
        c.check(names[:3] == ["x", "y", "z"], "%s: fields %s, expected x y z first" % (topic, names))
    elif kind == "nav_msgs/OccupancyGrid":
        info = msg.info
        c.check(len(msg.data) == info.width * info.height and info.resolution > 0,
                "%s: %d cells for %dx%d at %g m" % (topic, len(msg.data), info.width, info.height, info.resolution))
        c.check(all(-1 <= v <= 100 for v in msg.data), "%s: occupancy values outside -1..100" % topic)
    elif kind == "sensor_msgs/CameraInfo":
        c.check(len(msg.K) == 9 and msg.K[0] > 0 and msg.K[4] > 0 and msg.K[8] == 1,
                "%s: bad K %s" % (topic, list(msg.K)))


def reproject(frames, conf, c):
    """frames: list of (image msg, info msg, cloud msg) with equal stamps."""
    tol_m, tol_rel, tol_px = conf["tolerance_m"], conf["tolerance_rel"], conf["tolerance_px"]
    for image, info, cloud in frames:
        where = "reprojection at t=%.9f" % image.header.stamp.to_sec()
        if not c.check(image.header.frame_id == info.header.frame_id == cloud.header.frame_id,
                       "%s: frames differ: image %s, info %s, cloud %s" % (
                           where, image.header.frame_id, info.header.frame_id, cloud.header.frame_id)):
            continue
        if not c.check((info.width, info.height) == (image.width, image.height),
                       "%s: camera_info %dx%d, image %dx%d" % (where, info.width, info.height, image.width,
                                                               image.height)):
            continue
        fx, cx, fy, cy = info.K[0], info.K[2], info.K[4], info.K[5]
        depth = depth_values(image)
        xyz = cloud_xyz(cloud, c, "cloud")
        if xyz is None:
            continue
        w, h = image.width, image.height
        hit = bytearray(w * h)
        finite = matched = 0
        first_bad = None
        for x, y, z in zip(*xyz):
            if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
                continue
            finite += 1
            if z <= 0:
                first_bad = first_bad or "point (%g, %g, %g) behind the camera" % (x, y, z)
                continue
            u = fx * x / z + cx
            v = fy * y / z + cy
            ui, vi = int(round(u)), int(round(v))
            if not (0 <= ui < w and 0 <= vi < h) or abs(u - ui) > tol_px or abs(v - vi) > tol_px:
                first_bad = first_bad or "point (%g, %g, %g) projects to pixel (%.3f, %.3f)" % (x, y, z, u, v)
                continue
            d_m = depth[vi * w + ui] * 0.001
            if d_m <= 0 or abs(d_m - z) > tol_m + tol_rel * z:
                first_bad = first_bad or "point z %.4f m, depth at (%d, %d) is %.4f m" % (z, ui, vi, d_m)
                continue
            if hit[vi * w + ui]:
                first_bad = first_bad or "two points on pixel (%d, %d)" % (ui, vi)
                continue
            hit[vi * w + ui] = 1
            matched += 1
        valid = sum(1 for d in depth if d > 0)
        fraction = matched / finite if finite else 1.0
        c.check(fraction >= conf["min_fraction"],
                "%s: %d of %d points match the depth image (%.4f < %.4f); first mismatch: %s" % (
                    where, matched, finite, fraction, conf["min_fraction"], first_bad))
        if conf["complete"]:
            c.check(matched == valid, "%s: %d valid depth pixels but %d matching points" % (where, valid, matched))
        print("reprojection t=%.3f: %d points, %d matched, %d valid pixels" % (
            image.header.stamp.to_sec(), finite, matched, valid))


def main(argv):
    if len(argv) != 3:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    bag_path, expect_path = argv[1], argv[2]
    with open(expect_path) as f:
        expect = json.load(f)
    c = Checker()

    info_run = subprocess.run(["/usr/bin/rosbag", "info", bag_path], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, universal_newlines=True)
    c.check(info_run.returncode == 0, "rosbag info exited %d: %s" % (info_run.returncode, info_run.stdout[-500:]))

    try:
        bag = rosbag.Bag(bag_path)
    except Exception as e:  # rosbag raises several unrelated types
        print("cannot open bag %s: %s" % (bag_path, e), file=sys.stderr)
        return 2
    with bag:
        c.check(bag.version == 200, "bag format %s, expected 2.0" % bag.version)
        if "compression" in expect:
            got = bag.get_compression_info().compression
            c.check(got == expect["compression"], "compression %s, expected %s" % (got, expect["compression"]))

        types, topics_info = bag.get_type_and_topic_info()
        latched = {}
        for conn in bag._connections.values():
            value = conn.header.get("latching", b"0")
            latched.setdefault(conn.topic, set()).add(value in (b"1", "1"))

        topics = expect.get("topics", {})
        for topic, spec in topics.items():
            if not c.check(topic in topics_info, "topic %s missing" % topic):
                continue
            got = topics_info[topic]
            if "type" in spec:
                c.check(got.msg_type == spec["type"], "%s: type %s, expected %s" % (topic, got.msg_type, spec["type"]))
            if "count" in spec:
                c.check(got.message_count == spec["count"],
                        "%s: %d messages, expected %d" % (topic, got.message_count, spec["count"]))
            if "min_count" in spec:
                c.check(got.message_count >= spec["min_count"],
                        "%s: %d messages, expected at least %d" % (topic, got.message_count, spec["min_count"]))
            if "latched" in spec:
                c.check(latched.get(topic) == {bool(spec["latched"])},
                        "%s: latching %s, expected %s" % (topic, sorted(latched.get(topic, [])), spec["latched"]))
        if expect.get("only_listed_topics"):
            extra = sorted(set(topics_info) - set(topics))
            c.check(not extra, "unexpected topics %s" % extra)

        last_stamp = {}
        tf_edges = set()
        by_stamp = {}  # topic -> {stamp ns: msg} for the reprojection topics
        depth_msgs = []
        given = expect.get("reprojection", {})
        confs = [] if given is False else [dict(DEFAULT_REPROJECTION, **g) for g in
                                           (given if isinstance(given, list) else [given])]
        wanted = {conf[k] for conf in confs for k in ("image", "info", "cloud")}
        depth_spec = expect.get("depth")

        for topic, msg, t in bag.read_messages():
            spec = topics.get(topic, {})
            stamp = stamp_of(msg)
            if stamp is not None:
                c.check(stamp == t, "%s: stamp %s differs from record time %s" % (topic, stamp, t))
                prev = last_stamp.get(topic)
                c.check(prev is None or stamp > prev,
                        "%s: stamp %s does not increase (previous %s)" % (topic, stamp, prev))
                last_stamp[topic] = stamp
            if "frame_id" in spec and frame_of(msg) is not None:
                c.check(frame_of(msg) == spec["frame_id"],
                        "%s: frame_id %s, expected %s" % (topic, frame_of(msg), spec["frame_id"]))
            if msg._type == "tf2_msgs/TFMessage":
                for tr in msg.transforms:
                    tf_edges.add((tr.header.frame_id, tr.child_frame_id))
                    c.check(tr.header.stamp == msg.transforms[0].header.stamp,
                            "%s: transforms in one message with different stamps" % topic)
                    q = tr.transform.rotation
                    c.check(abs(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w - 1) < 1e-6,
                            "%s: %s->%s rotation not a unit quaternion" % (topic, tr.header.frame_id,
                                                                         tr.child_frame_id))
            check_message(topic, msg, c)
            if topic in wanted:
                by_stamp.setdefault(topic, {})[stamp.to_nsec()] = msg
            if depth_spec and topic == depth_spec.get("topic", DEFAULT_REPROJECTION["image"]):
                depth_msgs.append(msg)

        for parent, child in expect.get("tf_edges", []):
            c.check((parent, child) in tf_edges, "tf edge %s -> %s missing" % (parent, child))

        if depth_spec:
            want = depth_spec["values_mm"]
            if c.check(len(want) == len(depth_msgs), "depth: %d images, expected %d" % (len(depth_msgs), len(want))):
                for i, (msg, values) in enumerate(zip(depth_msgs, want)):
                    got = depth_values(msg).tolist()
                    if not c.check(got == values, "depth image %d differs from the expected values" % i):
                        bad = next(j for j in range(min(len(got), len(values))) if got[j] != values[j]) \
                            if len(got) == len(values) else None
                        print("  first difference at index %s (sizes %d, %d)" % (bad, len(got), len(values)))

        for conf in confs:
            own = [conf["image"], conf["info"], conf["cloud"]]
            if all(t in by_stamp for t in own):
                frames = []
                images, infos, clouds = by_stamp[conf["image"]], by_stamp[conf["info"]], by_stamp[conf["cloud"]]
                for ns in sorted(clouds):
                    if ns in images and ns in infos:
                        frames.append((images[ns], infos[ns], clouds[ns]))
                c.check(frames or not clouds, "reprojection: no cloud shares a stamp with an image and a camera_info")
                if conf["max_frames"] and len(frames) > conf["max_frames"]:
                    step = len(frames) / conf["max_frames"]
                    frames = [frames[int(i * step)] for i in range(conf["max_frames"])]
                reproject(frames, conf, c)
            elif "reprojection" in expect:
                c.check(False, "reprojection requested but topics %s are not all in the bag" % sorted(own))

    print("%s: %d checks passed, %d failed" % (bag_path, c.passed, len(c.failures)))
    return 1 if c.failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

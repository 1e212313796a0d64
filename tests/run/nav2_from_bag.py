#!/usr/bin/python3
"""nav2's VoxelLayer / ObstacleLayer update, written again from navigation2's source (nav2_costmap_2d voxel_layer.cpp,
obstacle_layer.cpp, observation_buffer.cpp, layered_costmap.cpp, costmap_2d.cpp; nav2_voxel_grid; nav2_util's
raytraceLine; main a3a97043 / jazzy f4108e5; the arithmetic is in nav2_layers.py), fed only a stvl-bench ROS 1 bag of
a run with map.layer_type nav2_voxel or nav2_obstacle: each cycle's gathered observations (the /stvl/.../filtered_points
clouds recorded at the cycle's time, header stamped with the reading's time, already in "map" and in the source's
height band) and the robot and camera poses from /tf and /tf_static. It replays every cycle (rolling updateOrigin,
raytraceFreespace of the clearing observations, marking of the marking ones, updateFootprint, and when
LayeredCostmap::updateMap's bounds are non-empty updateCosts' footprint clearing) and compares the layer's grid with the
bag's last /stvl/costmap cell for cell and, for the voxel layer, the marked voxels with the run's map.ply. It also
checks the bag's claims: the cycle count against metrics.json, the clouds inside their source's band, the stamps within
observation_persistence of their cycle, the cycles on the update_frequency ticks.

Usage: /usr/bin/python3 nav2_from_bag.py BAG METRICS.json MAP.ply [--min-agreement 1.0] [--sizes jazzy|main]
--sizes: Costmap2D::getSizeInMetersX/Y and VoxelLayer::getSizeInMetersZ (the rolling window's centring, the voxel
rays' clipping box) as jazzy computes them, (size - 1 + 0.5) * resolution (the default), or as main after #6028,
size * resolution.
Prints the costmap and voxel agreements (Jaccard over the cells that are not FREE_SPACE in either grid, equal values
agreeing; over the marked voxels) and exits 0 when both reach --min-agreement and the claims hold, 1 when not, 2 on
bad input. The ctest cases (check_nav2_from_bag.sh, which describes them): voxel_corridor, voxel_coarse,
voxel_cameras, voxel_ticks, voxel_receding, voxel_footprint, obstacle_corridor, obstacle_cameras,
obstacle_receding_pre_5697, obstacle_receding_5697, obstacle_receding_6092. voxel_corridor (16 levels of 0.05 m: rays
reach the map's top) fails while the bench's VoxelLayer clips its rays at main's getSizeInMetersZ
(size_z * z_resolution) but centres its window with jazzy's getSizeInMetersX/Y; --sizes takes one nav2 for all three.
"""
import json
import math
import os
import struct
import sys

import rosbag

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import nav2_layers as nl  # noqa: E402

BAG_TIME_OFFSET_NS = 1000000000  # recording::kBagTimeOffset_s: bag time = simulated time + 1 s


def quat_to_matrix(x, y, z, w):
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def compose(a, b):  # (R, t) pairs: a * b
    ra, ta = a
    rb, tb = b
    r = [[sum(ra[i][k] * rb[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    t = [sum(ra[i][k] * tb[k] for k in range(3)) + ta[i] for i in range(3)]
    return r, t


def transform_of(tr):
    q, p = tr.transform.rotation, tr.transform.translation
    return quat_to_matrix(q.x, q.y, q.z, q.w), [p.x, p.y, p.z]


class Frames:
    """/tf and /tf_static: the pose of a frame in map at a stamp."""

    def __init__(self):
        self.dynamic, self.static = {}, {}

    def add(self, msg, static):
        for tr in msg.transforms:
            if static:
                self.static[tr.child_frame_id] = (tr.header.frame_id, transform_of(tr))
            else:
                self.dynamic.setdefault(tr.child_frame_id, {})[tr.header.stamp.to_nsec()] = (
                    tr.header.frame_id, transform_of(tr))

    def pose(self, frame, stamp_ns):
        chain = ([[1, 0, 0], [0, 1, 0], [0, 0, 1]], [0.0, 0.0, 0.0])
        while frame != "map":
            if frame in self.static:
                parent, tf = self.static[frame]
            elif stamp_ns in self.dynamic.get(frame, {}):
                parent, tf = self.dynamic[frame][stamp_ns]
            else:
                raise KeyError("no transform to %s at %d ns" % (frame, stamp_ns))
            chain = compose(tf, chain)
            frame = parent
        return chain

    def robot(self, t_ns):
        """base_link in map at the latest frame time <= t_ns: (x, y, yaw as tf2::getYaw)."""
        stamps = [s for s in self.dynamic.get("base_link", {}) if s <= t_ns]
        if not stamps:
            return None
        r, t = self.pose("base_link", max(stamps))
        return t[0], t[1], math.atan2(r[1][0], r[0][0])


def read_ply_keys(path, voxel_size):
    with open(path, "rb") as f:
        header = b""
        while not header.endswith(b"end_header\n"):
            c = f.read(1)
            if not c:
                raise ValueError("no PLY header in %s" % path)
            header += c
        count = int(header.split(b"element vertex ")[1].split(b"\n")[0])
        keys = set()
        for _ in range(count):
            x, y, z, _ = struct.unpack("<fffd", f.read(20))
            keys.add((math.floor(x / voxel_size), math.floor(y / voxel_size), math.floor(z / voxel_size)))
    return keys


def bench_keys(layer, voxels, voxel_size):
    """Each marked nav2 voxel as the bench's cubic voxels: the cell centre's x, y key, every z key whose centre lies
    in the voxel's [z0, z1), or the one holding its centre when none does."""
    keys = set()
    for mx, my, mz in voxels:
        kx = math.floor((layer.origin_x + (mx + 0.5) * layer.res) / voxel_size)
        ky = math.floor((layer.origin_y + (my + 0.5) * layer.res) / voxel_size)
        z0, z1 = layer.origin_z + mz * layer.z_res, layer.origin_z + (mz + 1) * layer.z_res
        ks = [k for k in range(math.floor(z0 / voxel_size) - 1, math.floor(z1 / voxel_size) + 2)
              if z0 <= (k + 0.5) * voxel_size < z1]
        if not ks:
            ks = [math.floor((layer.origin_z + (mz + 0.5) * layer.z_res) / voxel_size)]
        keys.update((kx, ky, k) for k in ks)
    return keys


def jaccard(a, b):
    u = a | b
    return len(a & b) / len(u) if u else 1.0


def main():
    args = sys.argv[1:]
    min_agreement, sizes = 1.0, "jazzy"
    try:
        if "--min-agreement" in args:
            i = args.index("--min-agreement")
            min_agreement = float(args[i + 1])
            del args[i:i + 2]
        if "--sizes" in args:
            i = args.index("--sizes")
            sizes = args[i + 1]
            del args[i:i + 2]
            if sizes not in ("jazzy", "main"):
                raise ValueError(sizes)
    except (IndexError, ValueError):
        print(__doc__, file=sys.stderr)
        return 2
    nl.SIZE_IN_METERS_LESS = 0.5 if sizes == "jazzy" else 0.0
    if len(args) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    bag_path, metrics_path, ply_path = args
    try:
        metrics = json.load(open(metrics_path))
        params, cm = metrics["map"], metrics["nav2_costmap"]
        kind, n2 = params["layer_type"], params["nav2_layer"]
        sources = {s["topic"]: s for c in metrics["cameras"] for s in c["sources"]}
    except (OSError, ValueError, KeyError) as e:
        print("bad metrics %s: %s" % (metrics_path, e), file=sys.stderr)
        return 2
    if kind not in ("nav2_voxel", "nav2_obstacle"):
        print("map.layer_type is %s, not nav2_voxel or nav2_obstacle" % kind, file=sys.stderr)
        return 2
    rule = n2.get("nav2_marking_range", "6092")
    if rule not in ("pre_5697", "5697", "6092"):
        print("unknown nav2_marking_range %s" % rule, file=sys.stderr)
        return 2
    res = params["voxel_size"]
    voxel = None
    if kind == "nav2_voxel":
        voxel = {"size_z": n2["z_voxels"], "z_resolution": n2["z_resolution"], "origin_z": n2["origin_z"],
                 "unknown_threshold": n2["unknown_threshold"], "mark_threshold": n2["mark_threshold"]}
    default = nl.NO_INFORMATION if cm.get("track_unknown_space") else nl.FREE_SPACE
    layer = nl.Layer(cm["width_m"], cm["height_m"], res, default, voxel)
    footprint = [tuple(p) for p in params.get("footprint", [])]
    footprint_clearing = n2.get("footprint_clearing_enabled", True)

    frames = Frames()
    cycles = []  # [(t_ns, [(source, stamp_ns, points)])] in bag order
    costmaps = []
    try:
        with rosbag.Bag(bag_path) as bag:
            for topic, msg, t in bag.read_messages():
                if topic in ("/tf", "/tf_static"):
                    frames.add(msg, topic == "/tf_static")
                elif topic in sources:
                    n = msg.width * msg.height
                    data = bytes(msg.data)
                    off = {f.name: f.offset for f in msg.fields}
                    fmt = "<f" if not msg.is_bigendian else ">f"
                    points = [tuple(struct.unpack_from(fmt, data, i * msg.point_step + off[c])[0] for c in "xyz")
                              for i in range(n)]
                    if not cycles or cycles[-1][0] != t.to_nsec():
                        cycles.append((t.to_nsec(), []))
                    cycles[-1][1].append((sources[topic], msg.header.stamp.to_nsec(), points))
                elif topic == "/stvl/costmap":
                    costmaps.append(msg)
    except Exception as e:  # rosbag raises its own exception types for a broken bag
        print("cannot read %s: %s" % (bag_path, e), file=sys.stderr)
        return 2
    if not cycles or not costmaps:
        print("the bag has %d cycles and %d /stvl/costmap messages" % (len(cycles), len(costmaps)), file=sys.stderr)
        return 2

    # The bag's claims.
    problems = []
    if cm.get("updates") is not None and cm["updates"] != len(cycles):
        problems.append("metrics.json says %d updates, the bag has %d cycles" % (cm["updates"], len(cycles)))
    frequency = params.get("update_frequency", 0.0)
    frame_times = sorted(frames.dynamic.get("base_link", {}))
    if frequency > 0:
        ticks = [round((t_ns - BAG_TIME_OFFSET_NS) * 1e-9 * frequency) for t_ns, _ in cycles]
        off = sum(1 for (t_ns, _), k in zip(cycles, ticks)
                  if abs((t_ns - BAG_TIME_OFFSET_NS) * 1e-9 - k / frequency) > 1e-6)
        if off or ticks != list(range(ticks[0], ticks[-1] + 1)):
            problems.append("cycles not at every tick of %g Hz: %d off a tick, ticks %d .. %d for %d cycles" %
                            (frequency, off, ticks[0], ticks[-1], len(cycles)))
    else:
        reading_times = sorted({s for _, obs in cycles for _, s, _ in obs})
        if [t for t, _ in cycles] != reading_times:
            problems.append("with update_frequency 0 the cycles are not exactly the reading times")
    outside = late = repeated = 0
    for t_ns, obs in cycles:
        seen = set()
        for s, stamp, points in obs:
            keep_ns = round(s.get("observation_persistence", 0.0) * 1e9)
            late += stamp > t_ns or t_ns - stamp > keep_ns + 1000
            repeated += (s["topic"], stamp) in seen
            seen.add((s["topic"], stamp))
            low, high = s["min_obstacle_height"], s["max_obstacle_height"]
            outside += sum(1 for p in points if not low <= p[2] <= high)
    if outside:
        problems.append("%d points outside their source's [min_obstacle_height, max_obstacle_height]" % outside)
    if late:
        problems.append("%d clouds stamped after their cycle or older than observation_persistence" % late)
    if repeated:
        problems.append("%d clouds appear twice in one cycle" % repeated)
    print("cycles %d (update_frequency %g), layer %s, marking rule %s, sizes in metres %s" %
          (len(cycles), frequency, kind, rule, sizes))

    # The replay: LayeredCostmap::updateMap -> the layer's updateBounds -> updateCosts.
    last_updated = {}  # ObservationBuffer::last_updated_ per topic: reception = the reading's stamp
    min_h, max_h = n2["min_obstacle_height"], n2["max_obstacle_height"]
    footprint_clears = 0
    for t_ns, obs in cycles:
        robot = frames.robot(t_ns)
        if robot is None:
            print("no base_link pose at or before cycle %d ns" % t_ns, file=sys.stderr)
            return 2
        for s, stamp, _ in obs:
            last_updated[s["topic"]] = max(stamp, last_updated.get(s["topic"], stamp))
        layer.roll(robot[0], robot[1])
        bounds = nl.Bounds()
        marking = [o for o in obs if o[0].get("marking", True)]
        clearing = [o for o in obs if o[0].get("clearing", False)]
        if kind == "nav2_obstacle":
            # current = current && getMarkingObservations(...); current = current && getClearingObservations(...):
            # a marking buffer that is not current leaves the clearing observations ungathered.
            for s in sources.values():
                rate_ns = round(s.get("expected_update_rate", 0.0) * 1e9)
                if s.get("marking", True) and rate_ns > 0 and s["topic"] in last_updated and \
                        t_ns - last_updated[s["topic"]] > rate_ns:
                    clearing = []
        for s, stamp, points in clearing:
            origin = frames.pose(s["sensor_frame"], stamp)[1]
            if voxel:
                layer.voxel_raytrace(origin, points, s["raytrace_max_range"], s["raytrace_min_range"], bounds)
            else:
                layer.obstacle_raytrace(origin, points, s["raytrace_max_range"], s["raytrace_min_range"], bounds)
        for s, stamp, points in marking:
            origin = frames.pose(s["sensor_frame"], stamp)[1]
            if voxel:
                layer.voxel_mark(origin, points, s["obstacle_max_range"], s["obstacle_min_range"], min_h, max_h,
                                 bounds)
            else:
                layer.obstacle_mark(origin, points, s["obstacle_max_range"], s["obstacle_min_range"], min_h, max_h,
                                    rule, bounds)
        transformed = []
        if footprint_clearing:  # updateFootprint
            transformed = layer.transform_footprint(robot[0], robot[1], robot[2], footprint)
            for x, y in transformed:
                bounds.touch(x, y)
        if bounds.non_empty(layer) and footprint_clearing:  # updateCosts
            footprint_clears += layer.set_convex_polygon_cost(transformed, nl.FREE_SPACE) and len(transformed) >= 3

    # The final grid against the bag's last /stvl/costmap.
    m = costmaps[-1]
    ok = not problems
    for p in problems:
        print("FAIL: " + p)
    ox, oy = m.info.origin.position.x, m.info.origin.position.y
    if (m.info.width, m.info.height) != (layer.size_x, layer.size_y) or \
            abs(ox - layer.origin_x) > 1e-9 or abs(oy - layer.origin_y) > 1e-9:
        print("FAIL: the last costmap is %dx%d at (%.9f, %.9f), nav2's layer %dx%d at (%.9f, %.9f)" %
              (m.info.width, m.info.height, ox, oy, layer.size_x, layer.size_y, layer.origin_x, layer.origin_y))
        print("FAIL")
        return 1
    value = {0: nl.FREE_SPACE, 100: nl.LETHAL_OBSTACLE, -1: nl.NO_INFORMATION}
    theirs = {(i, value.get(v, 1000 + v)) for i, v in enumerate(m.data) if v != 0}
    ours = {(i, v) for i, v in enumerate(layer.cost) if v != nl.FREE_SPACE}
    cost_j = jaccard(ours, theirs)
    ours_v, theirs_v = dict(ours), dict(theirs)
    differing = sum(1 for i in set(ours_v) | set(theirs_v) if ours_v.get(i) != theirs_v.get(i))
    count = lambda cells, v: sum(1 for _, c in cells if c == v)  # noqa: E731
    print("costmap cells: nav2 lethal %d unknown %d, bench lethal %d unknown %d, differing %d, footprint clears %d, "
          "Jaccard %.6f" % (count(ours, 254), count(ours, 255), count(theirs, 254), count(theirs, 255), differing,
                            footprint_clears, cost_j))
    ok = ok and cost_j >= min_agreement
    if voxel:
        try:
            bench = read_ply_keys(ply_path, res)
        except (OSError, ValueError, IndexError, struct.error) as e:
            print("cannot read %s: %s" % (ply_path, e), file=sys.stderr)
            return 2
        mine = bench_keys(layer, layer.marked_voxels(), res)
        voxel_j = jaccard(mine, bench)
        print("marked voxels (as bench voxels): nav2 %d, bench %d, common %d, Jaccard %.6f" %
              (len(mine), len(bench), len(mine & bench), voxel_j))
        ok = ok and voxel_j >= min_agreement
    print("PASS" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())

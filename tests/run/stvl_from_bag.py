#!/usr/bin/python3
"""STVL's update, written again from STVL's source (ros2 403d9ed, noetic-devel 5e06daf), fed only a stvl-bench
ROS 1 bag: the readings each map update took (the /stvl/.../filtered_points clouds recorded at the update, header
stamped with the reading's time), the camera poses from /tf and /tf_static at those stamps. It rebuilds the voxel
grid as STVL's SpatioTemporalVoxelGrid would (ClearFrustums with DepthCameraFrustum, then Mark) and the costmap
STVL's layer publishes (built during ClearFrustums, before Mark), and compares them with the run's map.ply and the
bag's last /stvl/costmap. Independent of the bench's C++: a check that the bag says what the map took and that the
bench's map is STVL's.

Usage: /usr/bin/python3 stvl_from_bag.py BAG METRICS.json MAP.ply [--min-agreement 0.999]
METRICS.json is the run's: its "map" (voxel_size, voxel_decay, decay_model, mark_threshold) and each camera's
"sources" (topic, sensor_frame, marking, clearing, obstacle_range, min_z, max_z, horizontal_fov_angle,
vertical_fov_angle, decay_acceleration, min/max_obstacle_height, height_band, z_reference_frame) are STVL's
parameters as the run used them.
Prints the voxel and costmap agreement (Jaccard) and exits 0 when both reach --min-agreement and every voxel
time agrees within 1e-6 s, 1 when not, 2 on bad input.
"""
import json
import math
import struct
import sys

import rosbag


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


def normalize(v):
    n = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return v if n == 0 else [v[0] / n, v[1] / n, v[2] / n]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def depth_camera_frustum(pose, hfov, vfov, min_z, max_z):
    """DepthCameraFrustum::ComputePlaneNormals + TransformModel: six (normal, anchor) planes in the world."""
    def ray(sv, sh):  # Rx(sv * v/2) * Ry(sh * h/2) * Z
        a, b = sh * hfov / 2, sv * vfov / 2
        d = [math.sin(a), 0.0, math.cos(a)]                      # Ry(a) * Z
        return [d[0], d[1] * math.cos(b) - d[2] * math.sin(b), d[1] * math.sin(b) + d[2] * math.cos(b)]
    rays = [ray(1, 1), ray(-1, 1), ray(-1, -1), ray(1, -1)]
    pt = []
    for d in rays:
        pt.append([c * min_z for c in d])
        pt.append([c * max_z for c in d])
    planes = [(normalize(cross(sub(pt[3], pt[1]), sub(pt[1], pt[0]))), pt[0]),
              (normalize(cross(sub(pt[5], pt[3]), sub(pt[3], pt[2]))), pt[2]),
              (normalize(cross(sub(pt[7], pt[5]), sub(pt[5], pt[4]))), pt[4]),
              (normalize(cross(sub(pt[1], pt[7]), sub(pt[7], pt[6]))), pt[6])]
    far = normalize(cross(sub(pt[7], pt[5]), sub(pt[1], pt[7])))
    planes.append((far, pt[7]))
    planes.append(([-far[0], -far[1], -far[2]], pt[2]))
    r, t = pose
    world = []
    for n, anchor in planes:
        n_w = normalize([sum(r[i][k] * n[k] for k in range(3)) for i in range(3)])
        a_w = [sum(r[i][k] * anchor[k] for k in range(3)) + t[i] for i in range(3)]
        world.append((n_w, a_w))
    return world


def lidar_frustum(pose, hfov, vfov, min_z, max_z, padding):
    """ThreeDimensionalLidarFrustum (model_type 1): the constructor's members and TransformModel's pose."""
    return ("lidar", pose, hfov / 2.0, math.tan(vfov / 2.0) ** 2, min_z * min_z, max_z * max_z, padding, hfov > 6.27)


def lidar_inside(model, c):
    """ThreeDimensionalLidarFrustum::IsInside: horizontal range, padded vertical cone, bearing."""
    _, (r, t), half_h, tan_sq, min_sq, max_sq, padding, full = model
    d = sub(c, t)
    x, y, z = [sum(r[k][i] * d[k] for k in range(3)) for i in range(3)]  # R^T (c - t)
    r2 = x * x + y * y
    if r2 > max_sq or r2 < min_sq:
        return False
    v = abs(z) + padding
    if r2 == 0.0:
        if v > 0.0:
            return False  # +inf: outside; 0/0 is NaN, which compares false (inside)
    elif v * v / r2 > tan_sq:
        return False
    if full:
        return True
    if x > 0.0:
        return not abs(math.atan(y / x)) > half_h
    bearing = math.pi / 2 if y == 0.0 else abs(math.atan(x / y))  # atan(+-inf)
    return not bearing + math.pi / 2 > half_h


def inside(planes, c):
    if planes and planes[0] == "lidar":
        return lidar_inside(planes, c)
    for n, a in planes:
        d = normalize(sub(c, a))
        if n[0] * d[0] + n[1] * d[1] + n[2] * d[2] > 0.0:
            return False
    return True


def f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def main():
    args = sys.argv[1:]
    min_agreement = 0.999
    if "--min-agreement" in args:
        i = args.index("--min-agreement")
        min_agreement = float(args[i + 1])
        del args[i:i + 2]
    if len(args) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    bag_path, metrics_path, ply_path = args
    metrics = json.load(open(metrics_path))
    params = metrics["map"]
    stvl = {"clearing_mode": "frustum", "mark_rounding": "stvl", "frustum_geometry": "stvl",
            "update_grouping": "instant", "costmap_band": "every_voxel", "costmap_timing": "stvl"}
    ours = ["%s: %s" % (k, params.get(k)) for k, v in stvl.items() if params.get(k) != v]
    if ours:
        print("the run used options of ours, not STVL's behaviour: %s" % ", ".join(ours), file=sys.stderr)
        return 2
    vs = f32(params["voxel_size"])  # STVL's grid takes the voxel size as a float
    inv = 1.0 / vs
    decay, model = params["voxel_decay"], params["decay_model"]
    threshold = params.get("mark_threshold", 0)
    sources = {s["topic"]: s for c in metrics["cameras"] for s in c["sources"]}

    # tf: the robot's edges per stamp, the static chain per child.
    dynamic, static = {}, {}
    updates = []  # [(t_ns, [(topic, stamp_ns, points)])] in record order
    costmaps = []
    with rosbag.Bag(bag_path) as bag:
        for topic, msg, t in bag.read_messages():
            if topic == "/tf":
                for tr in msg.transforms:
                    dynamic.setdefault(tr.child_frame_id, {})[tr.header.stamp.to_nsec()] = (tr.header.frame_id,
                                                                                            transform_of(tr))
            elif topic == "/tf_static":
                for tr in msg.transforms:
                    static[tr.child_frame_id] = (tr.header.frame_id, transform_of(tr))
            elif topic in sources:
                n = msg.width * msg.height
                data = bytes(msg.data)
                points = [struct.unpack_from("<fff", data, i * msg.point_step) for i in range(n)]
                if not updates or updates[-1][0] != t.to_nsec():
                    updates.append((t.to_nsec(), []))
                updates[-1][1].append((topic, msg.header.stamp.to_nsec(), points))
            elif topic == "/stvl/costmap":
                costmaps.append(msg)

    def pose_of(frame, stamp_ns):  # map <- frame at stamp_ns
        chain = ([[1, 0, 0], [0, 1, 0], [0, 0, 1]], [0.0, 0.0, 0.0])
        while frame != "map":
            if frame in static:
                parent, tf = static[frame]
            elif frame in dynamic and stamp_ns in dynamic[frame]:
                parent, tf = dynamic[frame][stamp_ns]
            else:
                raise KeyError("no transform to %s at %d ns" % (frame, stamp_ns))
            chain = compose(tf, chain)
            frame = parent
        return chain

    # STVL's buffer hands Mark only the points inside the source's band, its z measured in z_reference_frame (the
    # ros2 branch's relative filters, PR #304; the global frame otherwise): every recorded point must lie in it.
    checked = outside = 0
    for _, readings in updates:
        for topic, stamp, points in readings:
            s = sources[topic]
            if not s.get("marking", True) or not s.get("height_band", True):
                continue
            r, t = pose_of(s.get("z_reference_frame", "map"), stamp)
            low, high = s["min_obstacle_height"] - 1e-5, s["max_obstacle_height"] + 1e-5
            for p in points:
                z = r[0][2] * (p[0] - t[0]) + r[1][2] * (p[1] - t[1]) + r[2][2] * (p[2] - t[2])
                checked += 1
                outside += not low <= z <= high
    if outside:
        print("FAIL: %d of %d marking points outside their source's band" % (outside, checked))
        return 1
    print("marking points inside their source's band: %d" % checked)

    # nav2's costmap calls STVL's updateBounds at every tick k / update_frequency, frames or not: the updates must
    # be exactly those ticks, none missing between the first and the last.
    frequency = params.get("update_frequency", 0.0)
    if frequency > 0 and updates:
        ticks = [round((t_ns * 1e-9 - 1.0) * frequency) for t_ns, _ in updates]
        off = [t_ns for (t_ns, _), k in zip(updates, ticks) if abs((t_ns * 1e-9 - 1.0) - k / frequency) > 1e-6]
        if off or ticks != list(range(ticks[0], ticks[-1] + 1)):
            print("FAIL: updates not at every tick of %g Hz: %d off a tick, ticks %s .. %s for %d updates" %
                  (frequency, len(off), ticks[0], ticks[-1], len(updates)))
            return 1
        print("updates at every tick of %g Hz: %d .. %d" % (frequency, ticks[0], ticks[-1]))

    grid = {}  # Coord -> time
    cost_columns = {}
    for t_ns, readings in updates:
        now = t_ns * 1e-9
        frustums = []
        for topic, stamp, _ in readings:
            s = sources[topic]
            if s.get("clearing", False):
                pose = pose_of(s["sensor_frame"], stamp)
                if s.get("model_type", 0) == 1:
                    shape = lidar_frustum(pose, s["horizontal_fov_angle"], s["vertical_fov_angle"], s["min_z"],
                                          s["max_z"], s.get("vertical_fov_padding", 0.0))
                else:
                    shape = depth_camera_frustum(pose, s["horizontal_fov_angle"], s["vertical_fov_angle"], s["min_z"],
                                                 s["max_z"])
                frustums.append((shape, s.get("decay_acceleration", 0.0)))
        # ClearFrustums -> TemporalClearAndGenerateCostmap
        cost_columns = {}
        for c in list(grid):
            v = grid[c]
            dt = now - v
            base = decay - dt if model == 0 else decay * math.exp(-dt) if model == 1 else decay
            centre = [c[0] * vs + vs / 2.0, c[1] * vs + vs / 2.0, c[2] * vs + vs / 2.0]
            cleared = False
            hit = False
            for planes, accel_factor in frustums:
                if inside(planes, centre):
                    accel = 1. / 6. * accel_factor * (dt * dt * dt)
                    if base - accel < 0.:
                        cleared = True
                    else:
                        grid[c] = v - accel
                    hit = True
                    break
            if not hit and base < 0.:
                cleared = True
            if cleared:
                del grid[c]
            else:
                key = (centre[0], centre[1])
                cost_columns[key] = cost_columns.get(key, 0) + 1
        # Mark
        for topic, stamp, points in readings:
            s = sources[topic]
            if not s.get("marking", True):
                continue
            origin = pose_of(s["sensor_frame"], stamp)[1]
            r2 = f32(s["obstacle_range"] * s["obstacle_range"])
            for px, py, pz in points:
                d2 = f32((px - origin[0]) ** 2 + (py - origin[1]) ** 2 + (pz - origin[2]) ** 2)
                if d2 > r2 or d2 < 0.0001:
                    continue
                x = px - vs if px < 0 else px
                y = py - vs if py < 0 else py
                z = pz - vs if py < 0 else pz
                grid[(int(x * inv), int(y * inv), int(z * inv))] = now

    # The bench's map.ply: float centres (k + 0.5) * s and double times.
    with open(ply_path, "rb") as f:
        header = b""
        while not header.endswith(b"end_header\n"):
            header += f.read(1)
        count = int(header.split(b"element vertex ")[1].split(b"\n")[0])
        bench = {}
        for _ in range(count):
            x, y, z, time = struct.unpack("<fffd", f.read(20))
            bench[(math.floor(x / params["voxel_size"]), math.floor(y / params["voxel_size"]),
                   math.floor(z / params["voxel_size"]))] = time
    ours, theirs = set(grid), set(bench)
    union = ours | theirs
    voxel_jaccard = len(ours & theirs) / len(union) if union else 1.0
    # The bench's bags carry simulated time plus 1 s (recording::kBagTimeOffset_s: ROS 1 time 0 is invalid).
    late = sum(1 for k in ours & theirs if abs(grid[k] - 1.0 - bench[k]) > 1e-6)
    print("updates %d, voxels: STVL %d, bench %d, Jaccard %.6f, times off by > 1 us: %d" %
          (len(updates), len(ours), len(theirs), voxel_jaccard, late))

    ok = voxel_jaccard >= min_agreement and late == 0
    if costmaps:
        m = costmaps[-1]
        res, ox, oy = m.info.resolution, m.info.origin.position.x, m.info.origin.position.y
        bench_cells = {(i % m.info.width, i // m.info.width) for i, v in enumerate(m.data) if v == 100}
        # nav2 frees the footprint's cells in the layer (update_footprint_enabled, convexFillCells): a costmap
        # matter, not the grid's; cells within the footprint's reach of the robot's last pose are left out.
        near_robot = lambda cell: False
        footprint = params.get("footprint", [])
        if params.get("update_footprint_enabled") and footprint:
            reach = max(math.hypot(x, y) for x, y in footprint) + 1.5 * res
            stamp = max(s for s in dynamic["base_link"] if s <= m.header.stamp.to_nsec())
            base = pose_of("base_link", stamp)[1]
            near_robot = lambda cell: math.hypot(ox + (cell[0] + 0.5) * res - base[0],
                                                 oy + (cell[1] + 0.5) * res - base[1]) <= reach
        bench_cells = {c for c in bench_cells if not near_robot(c)}
        stvl_cells = set()
        for (cx, cy), n in cost_columns.items():
            if n >= threshold:
                ix, iy = math.floor((cx - ox) / res), math.floor((cy - oy) / res)
                if 0 <= ix < m.info.width and 0 <= iy < m.info.height:
                    if not near_robot((ix, iy)):
                        stvl_cells.add((ix, iy))
        u = bench_cells | stvl_cells
        cost_jaccard = len(bench_cells & stvl_cells) / len(u) if u else 1.0
        print("costmap lethal cells: STVL %d, bench %d, Jaccard %.6f" % (len(stvl_cells), len(bench_cells),
                                                                         cost_jaccard))
        ok = ok and cost_jaccard >= min_agreement
    else:
        print("no /stvl/costmap in the bag")
        ok = False
    print("PASS" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())

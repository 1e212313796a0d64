"""nav2's VoxelLayer and ObstacleLayer arithmetic, written again in Python from navigation2's source (main a3a97043,
jazzy f4108e5) for nav2_from_bag.py. Every step follows the C++ named beside it, in doubles as nav2 computes them
(the clouds' floats promoted where nav2 promotes them), with C++'s std::min/std::max (NaN-keeping as there), IEEE
division and truncating casts.

Sizes in metres: Costmap2D::getSizeInMetersX/Y and VoxelLayer::getSizeInMetersZ are jazzy's (size - 1 + 0.5) * res
(main's #6028 made them size * res): SIZE_IN_METERS_CELLS gives the cells they count.
"""
import math

FREE_SPACE, LETHAL_OBSTACLE, NO_INFORMATION = 0, 254, 255
UINT_MAX = 4294967295
VOXEL_BITS = 16
SIZE_IN_METERS_LESS = 0.5  # jazzy: (size - 1 + 0.5) * res; main after #6028: 0.0


def cmin(a, b):  # std::min(a, b)
    return b if b < a else a


def cmax(a, b):  # std::max(a, b)
    return b if a < b else a


def fdiv(a, b):  # IEEE a / b
    if b != 0.0:
        return a / b
    if a == 0.0 or a != a:
        return math.nan
    return math.copysign(math.inf, a) * math.copysign(1.0, b)


def popcount(n):
    return bin(n).count("1")


def raytrace_line_2d(at, x0, y0, x1, y1, step_x, max_length=UINT_MAX, min_length=0):
    """nav2_util::raytraceLine (raytrace_line_2d.hpp) with bresenham2D."""
    dx_full, dy_full = x1 - x0, y1 - y0
    dist = math.sqrt(dx_full * dx_full + dy_full * dy_full)  # std::hypot of ints: exact squares, one rounding
    if dist < min_length:
        return
    if dist > 0.0:
        min_x0 = int(x0 + dx_full / dist * min_length)
        min_y0 = int(y0 + dy_full / dist * min_length)
    else:
        min_x0, min_y0 = x0, y0
    offset = min_y0 * step_x + min_x0
    dx, dy = x1 - min_x0, y1 - min_y0
    abs_dx, abs_dy = abs(dx), abs(dy)
    offset_dx = 1 if dx > 0 else -1
    offset_dy = (1 if dy > 0 else -1) * step_x
    scale = 1.0 if dist == 0.0 else cmin(1.0, max_length / dist)
    if abs_dx >= abs_dy:
        abs_da, abs_db, off_a, off_b = abs_dx, abs_dy, offset_dx, offset_dy
    else:
        abs_da, abs_db, off_a, off_b = abs_dy, abs_dx, offset_dy, offset_dx
    error_b = abs_da // 2
    end = min(int(scale * abs_da), abs_da)
    for _ in range(end):
        at(offset)
        offset += off_a
        error_b += abs_db
        if error_b >= abs_da:
            offset += off_b
            error_b -= abs_da
    at(offset)


class Layer:
    """The layer's Costmap2D (costmap_2d.cpp) and, for the voxel layer, its nav2_voxel_grid::VoxelGrid."""

    def __init__(self, width_m, height_m, resolution, default_value, voxel=None):
        self.res = resolution
        self.size_x = int(width_m / resolution)  # Costmap2DROS: (unsigned)(width / resolution)
        self.size_y = int(height_m / resolution)
        self.origin_x = self.origin_y = 0.0
        self.default = default_value
        self.cost = bytearray([default_value]) * (self.size_x * self.size_y)
        self.voxel = voxel  # dict: size_z, z_resolution, origin_z, unknown_threshold, mark_threshold
        if voxel is not None:
            self.size_z = voxel["size_z"]
            self.grid_z = min(self.size_z, 16)  # VoxelGrid clamps to 16
            self.z_res, self.origin_z = voxel["z_resolution"], voxel["origin_z"]
            self.unknown_threshold = voxel["unknown_threshold"] + (VOXEL_BITS - self.size_z)  # onInitialize
            self.mark_threshold = voxel["mark_threshold"]
            self.data = [0x0000ffff] * (self.size_x * self.size_y)

    # Costmap2D geometry
    def size_in_meters_x(self):
        return (self.size_x - SIZE_IN_METERS_LESS) * self.res

    def size_in_meters_y(self):
        return (self.size_y - SIZE_IN_METERS_LESS) * self.res

    def size_in_meters_z(self):
        return (self.size_z - SIZE_IN_METERS_LESS) * self.z_res

    def world_to_map(self, wx, wy):
        if wx < self.origin_x or wy < self.origin_y:
            return None
        mx, my = int((wx - self.origin_x) / self.res), int((wy - self.origin_y) / self.res)
        return (mx, my) if mx < self.size_x and my < self.size_y else None

    def world_to_map_enforce_bounds(self, wx, wy):
        if wx < self.origin_x:
            mx = 0
        elif wx > self.res * self.size_x + self.origin_x:
            mx = self.size_x - 1
        else:
            mx = int((wx - self.origin_x) / self.res)
        if wy < self.origin_y:
            my = 0
        elif wy > self.res * self.size_y + self.origin_y:
            my = self.size_y - 1
        else:
            my = int((wy - self.origin_y) / self.res)
        return mx, my

    def cell_distance(self, world_dist):
        return int(cmax(0.0, math.ceil(world_dist / self.res)))

    def update_origin(self, new_origin_x, new_origin_y):
        """Costmap2D::updateOrigin / VoxelLayer::updateOrigin: keep the overlap, reset the rest."""
        cell_ox = int((new_origin_x - self.origin_x) / self.res)
        cell_oy = int((new_origin_y - self.origin_y) / self.res)
        new_grid_ox = self.origin_x + cell_ox * self.res
        new_grid_oy = self.origin_y + cell_oy * self.res
        sx, sy = self.size_x, self.size_y
        llx, lly = min(max(cell_ox, 0), sx), min(max(cell_oy, 0), sy)
        urx, ury = min(max(cell_ox + sx, 0), sx), min(max(cell_oy + sy, 0), sy)
        csx, csy = urx - llx, ury - lly
        grids = [(self.cost, self.default)]
        if self.voxel is not None:
            grids.append((self.data, 0x0000ffff))
        start_x, start_y = llx - cell_ox, lly - cell_oy
        for i, (grid, reset) in enumerate(grids):
            local = [grid[(lly + j) * sx + llx:(lly + j) * sx + llx + csx] for j in range(csy)]
            fresh = bytearray([reset]) * (sx * sy) if i == 0 else [reset] * (sx * sy)
            for j, row in enumerate(local):
                o = (start_y + j) * sx + start_x
                fresh[o:o + csx] = row
            if i == 0:
                self.cost = fresh
            else:
                self.data = fresh
        self.origin_x, self.origin_y = new_grid_ox, new_grid_oy

    def roll(self, robot_x, robot_y):  # updateBounds' rolling window
        self.update_origin(robot_x - self.size_in_meters_x() / 2, robot_y - self.size_in_meters_y() / 2)

    # Footprint: footprint.cpp transformFootprint, Costmap2D::setConvexPolygonCost
    @staticmethod
    def transform_footprint(x, y, theta, footprint):
        c, s = math.cos(theta), math.sin(theta)
        return [(x + (px * c - py * s), y + (px * s + py * c)) for px, py in footprint]

    def set_convex_polygon_cost(self, polygon, value):
        cells = []
        for wx, wy in polygon:
            m = self.world_to_map(wx, wy)
            if m is None:
                return False
            cells.append(m)
        for x, y in self.convex_fill_cells(cells):
            self.cost[y * self.size_x + x] = value
        return True

    def convex_fill_cells(self, polygon):
        if len(polygon) < 3:
            return []
        cells = []
        sx = self.size_x

        def gather(offset):
            cells.append((offset % sx, offset // sx))
        for i in range(len(polygon)):  # polygonOutlineCells, closing edge last
            (ax, ay), (bx, by) = polygon[i], polygon[(i + 1) % len(polygon)]
            raytrace_line_2d(gather, ax, ay, bx, by, sx)
        i = 0
        while i < len(cells) - 1:  # the quick bubble sort by x
            if cells[i][0] > cells[i + 1][0]:
                cells[i], cells[i + 1] = cells[i + 1], cells[i]
                if i > 0:
                    i -= 1
            else:
                i += 1
        i = 0
        for x in range(cells[0][0], cells[-1][0] + 1):
            if i >= len(cells) - 1:
                break
            if cells[i][1] < cells[i + 1][1]:
                min_pt, max_pt = cells[i], cells[i + 1]
            else:
                min_pt, max_pt = cells[i + 1], cells[i]
            i += 2
            while i < len(cells) and cells[i][0] == x:
                if cells[i][1] < min_pt[1]:
                    min_pt = cells[i]
                elif cells[i][1] > max_pt[1]:
                    max_pt = cells[i]
                i += 1
            for y in range(min_pt[1], max_pt[1] + 1):
                cells.append((x, y))
        return cells

    # ObstacleLayer
    def obstacle_raytrace(self, origin, points, raytrace_max, raytrace_min, bounds):
        """ObstacleLayer::raytraceFreespace."""
        ox, oy = origin[0], origin[1]
        o = self.world_to_map(ox, oy)
        if o is None:
            return
        x0, y0 = o
        origin_x, origin_y = self.origin_x, self.origin_y
        map_end_x = origin_x + self.size_x * self.res
        map_end_y = origin_y + self.size_y * self.res
        bounds.touch(ox, oy)
        cost, sx = self.cost, self.size_x
        cell_max, cell_min = self.cell_distance(raytrace_max), self.cell_distance(raytrace_min)

        def mark(offset):
            cost[offset] = FREE_SPACE
        for wx, wy, _ in points:
            a, b = wx - ox, wy - oy
            if wx < origin_x:
                t = fdiv(origin_x - ox, a)
                wx, wy = origin_x, oy + b * t
            if wy < origin_y:
                t = fdiv(origin_y - oy, b)
                wx, wy = ox + a * t, origin_y
            if wx > map_end_x:
                t = fdiv(map_end_x - ox, a)
                wx, wy = map_end_x - .001, oy + b * t
            if wy > map_end_y:
                t = fdiv(map_end_y - oy, b)
                wx, wy = ox + a * t, map_end_y - .001
            m = self.world_to_map(wx, wy)
            if m is None:
                continue
            raytrace_line_2d(mark, x0, y0, m[0], m[1], sx, cell_max, cell_min)
            bounds.raytrace(ox, oy, wx, wy, raytrace_max, raytrace_min)

    def obstacle_mark(self, origin, points, max_range, min_range, min_h, max_h, rule, bounds):
        """ObstacleLayer::updateBounds' marking: rule pre_5697 (3D squared distance), 5697 (cell distance),
        6092 (#5697 with the 2D world pre-filter)."""
        if rule != "pre_5697":
            o = self.world_to_map(origin[0], origin[1])
            if o is None:
                return
            x0, y0 = o
            max_cells, min_cells = self.cell_distance(max_range), self.cell_distance(min_range)
        ox, oy, oz = origin
        for px, py, pz in points:
            if pz < min_h or pz > max_h:
                continue
            if rule == "pre_5697":
                sq = (px - ox) * (px - ox) + (py - oy) * (py - oy) + (pz - oz) * (pz - oz)
                if sq >= max_range * max_range or sq < min_range * min_range:
                    continue
                m = self.world_to_map(px, py)
                if m is None:
                    continue
            else:
                m = self.world_to_map(px, py)
                if m is None:
                    continue
                if rule == "6092":
                    wdx, wdy = px - ox, py - oy
                    sq = wdx * wdx + wdy * wdy
                    if sq > max_range * max_range or sq < min_range * min_range:
                        continue
                dx, dy = m[0] - x0, m[1] - y0
                dist = int(math.sqrt(dx * dx + dy * dy))
                if dist > max_cells or dist < min_cells:
                    continue
            self.cost[m[1] * self.size_x + m[0]] = LETHAL_OBSTACLE
            bounds.touch(px, py)

    # VoxelLayer
    def world_to_map_3d_float(self, wx, wy, wz):
        if wx < self.origin_x or wy < self.origin_y or wz < self.origin_z:
            return None
        mx, my = (wx - self.origin_x) / self.res, (wy - self.origin_y) / self.res
        mz = (wz - self.origin_z) / self.z_res
        return (mx, my, mz) if mx < self.size_x and my < self.size_y and mz < self.size_z else None

    def world_to_map_3d(self, wx, wy, wz):
        if wx < self.origin_x or wy < self.origin_y or wz < self.origin_z:
            return None
        mx, my = int((wx - self.origin_x) / self.res), int((wy - self.origin_y) / self.res)
        mz = int((wz - self.origin_z) / self.z_res)
        return (mx, my, mz) if mx < self.size_x and my < self.size_y and mz < self.size_z else None

    def voxel_raytrace(self, origin, points, raytrace_max, raytrace_min, bounds):
        """VoxelLayer::raytraceFreespace: each ray two cells short, clipped to the map box, cleared in 3D."""
        if not points:
            return
        ox, oy, oz = origin
        sensor = self.world_to_map_3d_float(ox, oy, oz)
        if sensor is None:
            return
        res = self.res
        map_end_x = self.origin_x + self.size_in_meters_x()
        map_end_y = self.origin_y + self.size_in_meters_y()
        map_end_z = self.origin_z + self.size_in_meters_z()
        origin_x, origin_y, origin_z = self.origin_x, self.origin_y, self.origin_z
        cell_max, cell_min = self.cell_distance(raytrace_max), self.cell_distance(raytrace_min)
        for wpx, wpy, wpz in points:
            distance = math.sqrt((wpx - ox) * (wpx - ox) + (wpy - oy) * (wpy - oy) + (wpz - oz) * (wpz - oz))
            scaling = cmax(cmin(1.0, fdiv(distance - 2 * res, distance)), 0.0)
            wpx = scaling * (wpx - ox) + ox
            wpy = scaling * (wpy - oy) + oy
            wpz = scaling * (wpz - oz) + oz
            a, b, c = wpx - ox, wpy - oy, wpz - oz
            t = 1.0
            outside = False
            if wpz > map_end_z:
                t = cmax(0.0, cmin(t, fdiv(map_end_z - 0.01 - oz, c)))
                outside = True
            elif wpz < origin_z:
                t = cmin(t, fdiv(origin_z - oz, c))
                outside = True
            if wpx < origin_x:
                t = cmin(t, fdiv(origin_x - ox, a))
                outside = True
            if wpy < origin_y:
                t = cmin(t, fdiv(origin_y - oy, b))
                outside = True
            if wpx > map_end_x:
                t = cmin(t, fdiv(map_end_x - ox, a))
                outside = True
            if wpy > map_end_y:
                t = cmin(t, fdiv(map_end_y - oy, b))
                outside = True
            if outside:
                if t > 0.0:
                    t -= 1e-5
                elif t < 0.0:
                    t += 1e-5
            wpx, wpy, wpz = ox + a * t, oy + b * t, oz + c * t
            end = self.world_to_map_3d_float(wpx, wpy, wpz)
            if end is None:
                continue
            self.clear_voxel_line_in_map(sensor, end, cell_max, cell_min)
            bounds.raytrace(ox, oy, wpx, wpy, raytrace_max, raytrace_min)

    def clear_voxel_line_in_map(self, p0, p1, max_length, min_length):
        """VoxelGrid::clearVoxelLineInMap: raytraceLine with bresenham3D and ClearVoxelInMap."""
        x0, y0, z0 = p0
        x1, y1, z1 = p1
        sx = self.size_x
        if x0 >= sx or y0 >= self.size_y or z0 >= self.grid_z or x1 >= sx or y1 >= self.size_y or z1 >= self.grid_z:
            return
        dist = math.sqrt((x0 - x1) * (x0 - x1) + (y0 - y1) * (y0 - y1) + (z0 - z1) * (z0 - z1))
        if int(dist) < min_length:
            return
        if dist > 0.0:
            scale = cmin(1.0, max_length / dist)
            min_x0 = x0 + (x1 - x0) / dist * min_length
            min_y0 = y0 + (y1 - y0) / dist * min_length
            min_z0 = z0 + (z1 - z0) / dist * min_length
        else:
            scale, min_x0, min_y0, min_z0 = 1.0, x0, y0, z0
        dx, dy, dz = int(x1) - int(min_x0), int(y1) - int(min_y0), int(z1) - int(min_z0)
        abs_dx, abs_dy, abs_dz = abs(dx), abs(dy), abs(dz)
        offset_dx = 1 if dx > 0 else -1
        offset_dy = (1 if dy > 0 else -1) * sx
        offset_dz = 1 if dz > 0 else -1
        z_mask = (((1 << 16) | 1) << int(min_z0)) & 0xffffffff
        offset = int(min_y0) * sx + int(min_x0)
        # (dominant, second, third) as (length, step, is_z) in raytraceLine's three calls
        if abs_dx >= max(abs_dy, abs_dz):
            axes = ((abs_dx, offset_dx, False), (abs_dy, offset_dy, False), (abs_dz, offset_dz, True))
        elif abs_dy >= abs_dz:
            axes = ((abs_dy, offset_dy, False), (abs_dx, offset_dx, False), (abs_dz, offset_dz, True))
        else:
            axes = ((abs_dz, offset_dz, True), (abs_dx, offset_dx, False), (abs_dy, offset_dy, False))
        (abs_da, off_a, a_z), (abs_db, off_b, b_z), (abs_dc, off_c, c_z) = axes
        error_b = error_c = abs_da // 2
        end = min(int(scale * abs_da), abs_da)
        data, cost = self.data, self.cost
        mark_t, unknown_t = self.mark_threshold, self.unknown_threshold

        def clear(offset, z_mask):  # ClearVoxelInMap
            col = data[offset] & ~z_mask & 0xffffffff
            data[offset] = col
            if popcount(col >> 16) <= mark_t:
                unknown = ((col >> 16) & 0xffff) ^ (col & 0xffff)
                cost[offset] = FREE_SPACE if popcount(unknown) <= unknown_t else NO_INFORMATION

        def step(offset, z_mask, off, is_z):
            if is_z:
                return offset, ((z_mask << 1) & 0xffffffff) if off > 0 else z_mask >> 1
            return offset + off, z_mask
        for _ in range(end):
            clear(offset, z_mask)
            offset, z_mask = step(offset, z_mask, off_a, a_z)
            error_b += abs_db
            error_c += abs_dc
            if error_b >= abs_da:
                offset, z_mask = step(offset, z_mask, off_b, b_z)
                error_b -= abs_da
            if error_c >= abs_da:
                offset, z_mask = step(offset, z_mask, off_c, c_z)
                error_c -= abs_da
        clear(offset, z_mask)

    def voxel_mark(self, origin, points, max_range, min_range, min_h, max_h, bounds):
        """VoxelLayer::updateBounds' marking: 3D squared distance, worldToMap3D, markVoxelInMap."""
        ox, oy, oz = origin
        sq_max, sq_min = max_range * max_range, min_range * min_range
        data, sx, mark_t = self.data, self.size_x, self.mark_threshold
        for px, py, pz in points:
            if pz < min_h or pz > max_h:
                continue
            sq = (px - ox) * (px - ox) + (py - oy) * (py - oy) + (pz - oz) * (pz - oz)
            if sq >= sq_max or sq < sq_min:
                continue
            m = self.world_to_map_3d(px, py, self.origin_z if pz < self.origin_z else pz)
            if m is None:
                continue
            mx, my, mz = m
            if mz >= self.grid_z:
                continue
            index = my * sx + mx
            data[index] |= ((1 << mz << 16) | (1 << mz)) & 0xffffffff
            if popcount(data[index] >> 16) > mark_t:
                self.cost[index] = LETHAL_OBSTACLE
                bounds.touch(px, py)

    def marked_voxels(self):
        """(mx, my, mz) of every MARKED voxel (VoxelGrid::getVoxel: both bits set)."""
        out = []
        for index, col in enumerate(self.data):
            if col >> 16:
                for z in range(self.grid_z):
                    if (col >> z) & 1 and (col >> (z + 16)) & 1:
                        out.append((index % self.size_x, index // self.size_x, z))
        return out


class Bounds:
    """LayeredCostmap::updateMap's bounds: CostmapLayer::touch and ObstacleLayer::updateRaytraceBounds."""

    def __init__(self):
        self.min_x = self.min_y = 1.7976931348623157e308
        self.max_x = self.max_y = -1.7976931348623157e308

    def touch(self, x, y):
        self.min_x, self.min_y = cmin(x, self.min_x), cmin(y, self.min_y)
        self.max_x, self.max_y = cmax(x, self.max_x), cmax(y, self.max_y)

    def raytrace(self, ox, oy, wx, wy, max_range, min_range):
        dx, dy = wx - ox, wy - oy
        full = math.hypot(dx, dy)
        if full < min_range:
            return
        scale = cmin(1.0, fdiv(max_range, full))
        self.touch(ox + dx * scale, oy + dy * scale)

    def non_empty(self, layer):
        """updateMap: worldToMapEnforceBounds, +1, clamp; updateCosts runs when xn >= x0 and yn >= y0."""
        x0, y0 = layer.world_to_map_enforce_bounds(self.min_x, self.min_y)
        xn, yn = layer.world_to_map_enforce_bounds(self.max_x, self.max_y)
        x0, y0 = max(0, x0), max(0, y0)
        xn, yn = min(layer.size_x, xn + 1), min(layer.size_y, yn + 1)
        return xn >= x0 and yn >= y0

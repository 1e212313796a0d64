#include "worldgen/office_layout.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace stvl::worldgen {
namespace {

constexpr double kDoorHeightM = 2.05;  // the leaf; the opening's lintel starts at 2.1 m
constexpr double kLintelM = 2.1;
const char* const kWallRgba = "0.85 0.85 0.8 1";
const char* const kDoorRgba = "0.55 0.35 0.2 1";

using Side = RectSide;
std::vector<Side> sides(const Rect& r) { return rect_sides(r); }

// Runs of a side (as [from, to] distances from its end a) whose outside, 0.3 m out, lies in a corridor.
std::vector<std::pair<double, double>> corridor_runs(const Side& s, const OfficeLayout& l) {
  std::vector<std::pair<double, double>> runs;
  const double length = (s.b - s.a).norm();
  const Eigen::Vector2d along = (s.b - s.a) / length;
  const double step = 0.05;
  double from = -1;
  for (double d = 0; d <= length + 1e-9; d += step) {
    const Eigen::Vector2d probe = s.a + along * d + s.out * 0.3;
    const bool in = l.main_corridor.contains(probe) || l.branch_corridor.contains(probe);
    if (in && from < 0) from = d;
    if (!in && from >= 0) runs.push_back({from, d - step}), from = -1;
  }
  if (from >= 0) runs.push_back({from, length});
  return runs;
}

// Rooms along one axis of a region (x: cuts at x, y: cuts at y), about 3.6 to 5 m wide, cut positions jittered.
void split_region(const Rect& region, bool along_x, const std::string& name, Rng& rng, std::vector<Room>& rooms) {
  const double lo = along_x ? region.x0 : region.y0, hi = along_x ? region.x1 : region.y1;
  const int n = std::max(1, static_cast<int>((hi - lo) / 3.6));
  double from = lo;
  for (int i = 1; i <= n; ++i) {
    double to = hi;
    if (i < n) to = std::round((lo + (hi - lo) * i / n + rng.uniform(-0.4, 0.4)) / 0.05) * 0.05;
    Room room;
    room.r = along_x ? Rect{from, region.y0, to, region.y1} : Rect{region.x0, from, region.x1, to};
    room.region = name;
    rooms.push_back(room);
    from = to;
  }
}

// Merges touching spans of one wall line.
std::vector<std::pair<double, double>> merged(std::vector<std::pair<double, double>> spans) {
  std::sort(spans.begin(), spans.end());
  std::vector<std::pair<double, double>> out;
  for (const auto& s : spans) {
    if (!out.empty() && s.first <= out.back().second + 1e-6) out.back().second = std::max(out.back().second, s.second);
    else out.push_back(s);
  }
  return out;
}

// Removes [a, b] from the spans.
void cut(std::vector<std::pair<double, double>>& spans, double a, double b) {
  std::vector<std::pair<double, double>> out;
  for (const auto& s : spans) {
    if (s.second <= a || s.first >= b) {
      out.push_back(s);
      continue;
    }
    if (s.first < a - 1e-6) out.push_back({s.first, a});
    if (s.second > b + 1e-6) out.push_back({b, s.second});
  }
  spans = out;
}

}  // namespace

std::vector<RectSide> rect_sides(const Rect& r) {
  return {{{r.x0, r.y0}, {r.x1, r.y0}, {0, -1}},
          {{r.x1, r.y0}, {r.x1, r.y1}, {1, 0}},
          {{r.x1, r.y1}, {r.x0, r.y1}, {0, 1}},
          {{r.x0, r.y1}, {r.x0, r.y0}, {-1, 0}}};
}

bool Shape::covers(const Eigen::Vector2d& p, double grow) const {
  const Eigen::Vector2d d = p - center;
  if (radius_m > 0) return d.norm() <= radius_m + grow;
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  return std::abs(c * d.x() + s * d.y()) <= half.x() + grow && std::abs(-s * d.x() + c * d.y()) <= half.y() + grow;
}

FloorRaster::FloorRaster(double width_m, double height_m, double resolution_m) {
  frame_.resolution_m = resolution_m;
  frame_.width = static_cast<int>(std::ceil(width_m / resolution_m - 1e-9));
  frame_.height = static_cast<int>(std::ceil(height_m / resolution_m - 1e-9));
  touched_.assign(static_cast<std::size_t>(frame_.width) * frame_.height, 0);
  walls_ = things_ = kept_ = touched_;
}

template <typename F>
void FloorRaster::for_cells(const Shape& s, double grow, F&& visit) const {
  const double res = frame_.resolution_m, reach = (s.radius_m > 0 ? s.radius_m : s.half.norm()) + grow + res;
  const int c0 = static_cast<int>(std::floor((s.center.x() - reach) / res)),
            c1 = static_cast<int>(std::floor((s.center.x() + reach) / res));
  const int r0 = static_cast<int>(std::floor((s.center.y() - reach) / res)),
            r1 = static_cast<int>(std::floor((s.center.y() + reach) / res));
  for (int row = r0; row <= r1; ++row)
    for (int col = c0; col <= c1; ++col)
      if (s.covers({(col + 0.5) * res, (row + 0.5) * res}, grow)) visit(CellIndex{col, row});
}

void FloorRaster::mark(const Shape& s, Solid kind) {
  std::vector<std::uint8_t>& solid = kind == Solid::kWall ? walls_ : things_;
  for_cells(s, 0.0, [&](CellIndex c) {
    if (frame_.contains(c)) solid[frame_.index(c)] = 1;
  });
  // A cell the shape touches at all: its centre lies within half a cell diagonal of the shape.
  for_cells(s, 0.5 * std::sqrt(2.0) * frame_.resolution_m, [&](CellIndex c) {
    if (frame_.contains(c)) touched_[frame_.index(c)] = 1;
  });
}

void FloorRaster::keep_free(const Shape& s) {
  for_cells(s, 0.0, [&](CellIndex c) {
    if (frame_.contains(c)) kept_[frame_.index(c)] = 1;
  });
}

bool FloorRaster::test(const Shape& s, double gap, bool kept_counts) const {
  bool ok = true;
  for_cells(s, 0.0, [&](CellIndex c) {
    if (!frame_.contains(c) || walls_[frame_.index(c)] || (kept_counts && kept_[frame_.index(c)])) ok = false;
  });
  for_cells(s, gap, [&](CellIndex c) {
    if (frame_.contains(c) && things_[frame_.index(c)]) ok = false;
  });
  return ok;
}

bool FloorRaster::fits(const Shape& s, double gap) const { return test(s, gap, true); }
bool FloorRaster::clear_of_obstacles(const Shape& s, double gap) const { return test(s, gap, false); }

OccupancyGrid FloorRaster::grid() const {
  OccupancyGrid g;
  g.frame = frame_;
  g.cells.resize(touched_.size());
  for (std::size_t i = 0; i < touched_.size(); ++i) g.cells[i] = touched_[i] ? Cell::kOccupied : Cell::kFree;
  return g;
}

OfficeLayout make_layout(double width_m, double height_m, double wall_height_m, Rng& rng) {
  OfficeLayout l;
  l.width_m = width_m, l.height_m = height_m, l.wall_height_m = wall_height_m;
  const double W = width_m, H = height_m;
  const double wc = rng.snapped(1.8, 2.4, 0.1), wb = rng.snapped(1.6, 2.2, 0.1);  // wall lines stay on the 0.05 m grid
  const double cy = rng.snapped(std::max(0.4 * H, wc / 2 + 2.8), std::min(0.6 * H, H - wc / 2 - 2.8), 0.05);
  const double yb = cy - wc / 2, yt = cy + wc / 2;
  l.t_junction = rng.chance(0.5);
  const double bx = l.t_junction
                        ? rng.snapped(std::max(0.35 * W, wb / 2 + 3.0), std::min(0.65 * W, W - wb / 2 - 3.0), 0.05)
                        : rng.snapped(std::max(0.55 * W, wb / 2 + 3.0), W - wb / 2 - 3.5, 0.05);
  const double xl = bx - wb / 2, xr = bx + wb / 2;
  l.main_corridor = {0, yb, l.t_junction ? W : xr, yt};
  l.branch_corridor = {xl, yt, xr, H};
  split_region({0, 0, l.main_corridor.x1, yb}, true, "south", rng, l.rooms);
  split_region({0, yt, xl, H}, true, "north-west", rng, l.rooms);
  if (l.t_junction) {
    split_region({xr, yt, W, H}, true, "north-east", rng, l.rooms);
  } else {  // east of an L: rooms stacked along the branch, the lowest reaching up past the corridor's floor
    const double first = rng.snapped(yt + 0.5, yt + 1.5, 0.05);
    l.rooms.push_back({Rect{xr, 0, W, first}, Door{}, "east"});
    split_region({xr, first, W, H}, false, "east", rng, l.rooms);
  }
  for (Room& room : l.rooms) {
    // The door on the longest stretch of the room's walls that faces a corridor.
    double best = 0;
    for (const Side& s : sides(room.r))
      for (const auto& [from, to] : corridor_runs(s, l)) {
        if (to - from <= best) continue;
        best = to - from;
        const Eigen::Vector2d along = (s.b - s.a).normalized();
        room.door.width_m = rng.chance(0.5) ? 0.9 : 1.0;
        const double lo = from + 0.35 + room.door.width_m / 2, hi = to - 0.35 - room.door.width_m / 2;
        const double at = lo <= hi ? std::round(rng.uniform(lo, hi) / 0.05) * 0.05 : 0.5 * (from + to);
        room.door.center_W = s.a + along * at;
        room.door.into_room = -s.out;
      }
    room.door.open = rng.chance(0.7);
  }
  // The corridor faces of every room wall, less the door openings and half a metre either side.
  for (const Room& room : l.rooms)
    for (const Side& s : sides(room.r)) {
      const Eigen::Vector2d along = (s.b - s.a).normalized();
      for (auto [from, to] : corridor_runs(s, l)) {
        std::vector<std::pair<double, double>> spans{{from, to}};
        if (room.door.into_room.dot(-s.out) > 0.5 && std::abs((room.door.center_W - s.a).dot(s.out)) < 1e-6) {
          const double at = (room.door.center_W - s.a).dot(along);
          cut(spans, at - room.door.width_m / 2 - 0.5, at + room.door.width_m / 2 + 0.5);
        }
        for (const auto& [a, b] : spans)
          if (b - a > 0.3) l.corridor_faces.push_back({s.a + along * a, s.a + along * b, s.out});
      }
    }
  return l;
}

namespace {

// Wall lines keyed by (vertical, coordinate in mm): their spans along the line.
using WallLines = std::map<std::pair<bool, long>, std::vector<std::pair<double, double>>>;

// The building's outline and every room's sides as wall lines.
WallLines wall_lines(const OfficeLayout& l) {
  WallLines lines;
  const auto add = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const bool vertical = std::abs(a.x() - b.x()) < 1e-9;
    const double coord = vertical ? a.x() : a.y();
    const double s0 = vertical ? std::min(a.y(), b.y()) : std::min(a.x(), b.x());
    const double s1 = vertical ? std::max(a.y(), b.y()) : std::max(a.x(), b.x());
    lines[{vertical, std::lround(coord * 1000)}].push_back({s0, s1});
  };
  for (const Side& s : sides({0, 0, l.width_m, l.height_m})) add(s.a, s.b);
  for (const Room& room : l.rooms)
    for (const Side& s : sides(room.r)) add(s.a, s.b);
  return lines;
}

// The walls' boxes along each line, merged, with the door openings cut out; each marked on the raster.
void add_wall_boxes(WallLines& lines, const OfficeLayout& l, Body& walls, FloorRaster& raster) {
  const double t = l.wall_thickness_m, h = l.wall_height_m;
  for (auto& [key, spans] : lines) {
    const bool vertical = key.first;
    const double coord = key.second / 1000.0;
    spans = merged(spans);
    for (const Room& room : l.rooms) {
      const Eigen::Vector2d c = room.door.center_W;
      const bool on_line = vertical ? std::abs(room.door.into_room.x()) > 0.5 && std::abs(c.x() - coord) < 1e-6
                                    : std::abs(room.door.into_room.y()) > 0.5 && std::abs(c.y() - coord) < 1e-6;
      if (!on_line) continue;
      const double at = vertical ? c.y() : c.x();
      cut(spans, at - room.door.width_m / 2 - t / 2, at + room.door.width_m / 2 + t / 2);
    }
    for (const auto& [a, b] : spans) {
      const double mid = 0.5 * (a + b), half = 0.5 * (b - a) + t / 2;
      Geom g{"box",
             "",
             vertical ? Eigen::Vector3d(coord, mid, h / 2) : Eigen::Vector3d(mid, coord, h / 2),
             vertical ? std::vector<double>{t / 2, half, h / 2} : std::vector<double>{half, t / 2, h / 2},
             {},
             0,
             kWallGroup,
             kWallRgba};
      walls.geoms.push_back(g);
      raster.mark(Shape::box(g.pos.head<2>(), {g.size[0], g.size[1]}), FloorRaster::Solid::kWall);
    }
  }
}

// A room's door `n`: the lintel above its opening (added to walls, when they stand higher than it) and the door's
// body, open (turned into the room at one jamb) or closed, marked on the raster.
Body door_body(const Room& room, int n, const OfficeLayout& l, Body& walls, FloorRaster& raster) {
  const double t = l.wall_thickness_m, h = l.wall_height_m;
  const Door& d = room.door;
  const Eigen::Vector2d along(-d.into_room.y(), d.into_room.x());
  const double yaw = std::atan2(along.y(), along.x());
  if (h > kLintelM + 0.05)
    walls.geoms.push_back(
        {"box",
         "",
         Eigen::Vector3d(d.center_W.x(), d.center_W.y(), 0.5 * (kLintelM + h)),
         {std::abs(along.x()) * (d.width_m / 2 + t / 2) + std::abs(along.y()) * t / 2,
          std::abs(along.y()) * (d.width_m / 2 + t / 2) + std::abs(along.x()) * t / 2, 0.5 * (h - kLintelM)},
         {},
         0,
         kWallGroup,
         kWallRgba});
  Body door;
  door.name = "door_" + std::to_string(n);
  door.comment =
      door.name + ": " + (d.open ? "open" : "closed") + ", " + fixed(d.width_m, 2) + " m, " + room.region + " room";
  door.yaw_rad = yaw;
  Eigen::Vector2d half;
  if (d.open) {  // turned into the room at one jamb
    door.pos.head<2>() = d.center_W - along * (d.width_m / 2 - 0.03) + d.into_room * (d.width_m / 2 + t / 2);
    half = {0.02, d.width_m / 2 - 0.005};
  } else {
    door.pos.head<2>() = d.center_W;
    half = {d.width_m / 2 - 0.005, 0.02};
  }
  door.geoms.push_back({"box",
                        "",
                        Eigen::Vector3d(0, 0, kDoorHeightM / 2),
                        {half.x(), half.y(), kDoorHeightM / 2},
                        {},
                        0,
                        kWallGroup,
                        kDoorRgba});
  raster.mark(Shape::box(door.pos.head<2>(), half, yaw), FloorRaster::Solid::kWall);
  return door;
}

}  // namespace

std::vector<Body> wall_bodies(const OfficeLayout& l, FloorRaster& raster) {
  WallLines lines = wall_lines(l);
  Body walls;
  walls.name = "walls";
  walls.comment =
      "walls 0.1 m thick and " + fixed(l.wall_height_m, 2) + " m high, with the door openings and lintels above them";
  add_wall_boxes(lines, l, walls, raster);
  std::vector<Body> bodies;
  int n = 0;
  for (const Room& room : l.rooms) bodies.push_back(door_body(room, ++n, l, walls, raster));
  bodies.insert(bodies.begin(), walls);
  return bodies;
}

}  // namespace stvl::worldgen

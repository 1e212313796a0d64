#pragma once
// The floor plan of a generated office: corridors (a main corridor and a branch meeting it in a T or an L), rooms
// along them with one door each, the walls with their door openings, and a raster of footprints on which the
// generator places things and the robot's path is planned.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "worldgen/mjcf_writer.hpp"
#include "worldgen/occupancy.hpp"
#include "worldgen/rng.hpp"

namespace stvl::worldgen {

// An axis-aligned rectangle in the world (m).
struct Rect {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool contains(const Eigen::Vector2d& p) const { return p.x() >= x0 && p.x() <= x1 && p.y() >= y0 && p.y() <= y1; }
  Eigen::Vector2d center() const { return {0.5 * (x0 + x1), 0.5 * (y0 + y1)}; }
};

// A footprint on the floor: a rectangle (half extents, turned by yaw) or a disc (radius).
struct Shape {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  Eigen::Vector2d half = Eigen::Vector2d::Zero();
  double yaw_rad = 0;
  double radius_m = 0;  // > 0: a disc
  static Shape box(const Eigen::Vector2d& c, const Eigen::Vector2d& half, double yaw = 0) { return {c, half, yaw, 0}; }
  static Shape disc(const Eigen::Vector2d& c, double r) { return {c, Eigen::Vector2d::Zero(), 0, r}; }
  // Whether p lies within `grow` of the shape (a rectangle grown on every side).
  bool covers(const Eigen::Vector2d& p, double grow) const;
};

// Cells of 0.05 m over the building, [0, width] x [0, height]: what is taken and what must stay free (door
// approaches, the robot's start and goal, a walker's lane). Placement tests cell centres inside a shape (walls and
// doors exactly, things with a gap between them); the planning grid marks every cell a shape touches.
class FloorRaster {
 public:
  enum class Solid { kWall, kThing };
  FloorRaster(double width_m, double height_m, double resolution_m = 0.05);
  void mark(const Shape& s, Solid kind = Solid::kThing);
  void keep_free(const Shape& s);  // nothing may be placed here
  // Whether s lies inside the building, off walls and kept-free cells, and `gap` away from every thing.
  bool fits(const Shape& s, double gap) const;
  // The same, kept-free cells allowed (people may walk through door approaches).
  bool clear_of_obstacles(const Shape& s, double gap) const;
  // Every cell a marked shape touches as occupied, the rest free.
  OccupancyGrid grid() const;

 private:
  template <typename F>
  void for_cells(const Shape& s, double grow, F&& visit) const;  // cells whose centre lies within s grown by `grow`
  bool test(const Shape& s, double gap, bool kept_counts) const;
  GridFrame frame_;
  std::vector<std::uint8_t> touched_, walls_, things_, kept_;
};

// A side of a rectangle: its ends (counter-clockwise around the rectangle) and its outward normal.
struct RectSide {
  Eigen::Vector2d a, b, out;
};
// Bottom, right, top, left.
std::vector<RectSide> rect_sides(const Rect& r);

// A door: its opening in a room's wall.
struct Door {
  Eigen::Vector2d center_W = Eigen::Vector2d::Zero();
  Eigen::Vector2d into_room = Eigen::Vector2d::Zero();  // unit normal from the wall into the room
  double width_m = 0.9;
  bool open = true;
};

struct Room {
  Rect r;  // wall centre lines
  Door door;
  std::string region;  // "south", "north-west", ...: for names and comments
};

// A stretch of corridor wall: the face along which things stand, seen from the corridor.
struct WallFace {
  Eigen::Vector2d a_W, b_W;       // the face's ends on the wall's centre line
  Eigen::Vector2d into_corridor;  // unit normal
};

struct OfficeLayout {
  double width_m = 20, height_m = 12, wall_thickness_m = 0.1, wall_height_m = 2.5;
  bool t_junction = true;
  Rect main_corridor, branch_corridor;  // wall centre lines
  std::vector<Room> rooms;
  std::vector<WallFace> corridor_faces;  // room walls facing a corridor, without the door openings
};

// Corridors and rooms for a building of width x height (m), every room with one door on a corridor, opened with
// probability 0.7 (0.9 or 1.0 m wide). Deterministic in rng.
OfficeLayout make_layout(double width_m, double height_m, double wall_height_m, Rng& rng);

// The walls (one body "walls": boxes, group 0; openings and lintels over the doors) and the door leaves (bodies
// door_1 ..., group 0: closed in the opening, or open, turned into the room at a jamb); their footprints are
// marked on `raster`.
std::vector<Body> wall_bodies(const OfficeLayout& layout, FloorRaster& raster);

}  // namespace stvl::worldgen

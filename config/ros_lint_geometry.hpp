#pragma once
// The geometry lint reasons with across the sources of one camera: STVL's depth-camera clearing frustum as
// DepthCameraFrustum builds it (ros2 403d9ed, noetic-devel 5e06daf: corners at radial distances min_z / max_z
// along rays turned by h/2 about y, then v/2 about x), and the heights a camera sees within a range.
#include <vector>

namespace stvl::config::lint_geometry {

// Where STVL's frustum puts its far (or near) plane along the optical axis for a radial max_z (min_z):
// max_z * cos(h/2) * cos(v/2), not max_z. Full angles in radians.
double stvl_plane_depth(double radial_m, double hfov_rad, double vfov_rad);
// The max_z whose far plane lies at `depth_m`: depth_m / (cos(h/2) * cos(v/2)).
double stvl_radial_for_depth(double depth_m, double hfov_rad, double vfov_rad);

// A camera's optical centre `height_m` above a flat floor (world z), turned as the bench mounts it:
// R = Rz(yaw) Ry(pitch) Rx(roll) on camera_link (x forward), positive pitch looking down; yaw does not change heights.
struct CameraHeight {
  double height_m = 0.0, pitch_rad = 0.0, roll_rad = 0.0;
};

struct HeightRange {
  double min_m = 0.0, max_m = 0.0;
};

// World z range of STVL's depth-camera frustum: the z of its eight corners (a convex solid's extremes lie on
// corners).
HeightRange stvl_frustum_heights(const CameraHeight& camera, double min_z_m, double max_z_m, double hfov_rad,
                                 double vfov_rad);

// World z range of the points within `range_m` of the optical centre inside the camera's view (the ideal
// pyramid of full angles hfov x vfov about the optical axis, principal point at the centre).
HeightRange view_heights(const CameraHeight& camera, double hfov_rad, double vfov_rad, double range_m);

// The parts of `range` (min < max) that none of `covers` overlaps, each longer than `tolerance_m`.
std::vector<HeightRange> uncovered(HeightRange range, std::vector<HeightRange> covers, double tolerance_m);

}  // namespace stvl::config::lint_geometry

// The one ray caster over posed shapes: the compiled mirror of
// uvms_pin/perception/caster.py (its docstring has the method).
//
// Each body is a shape (ray_shapes.hpp) in its own frame at a pose (R, p) in the world,
// replaced by set_pose whenever a sensor fires. A ray o + t d (world) is carried into a body's
// frame, o_b = R^T (o - p), d_b = R^T d, and its hit's normal back, n = R n_b. Every ray comes
// from one origin (a camera's, a sonar's): a body whose solid holds the origin is not seen; a
// plane is met by each ray's rate along its normal, t = -h / (d . n), h the origin's height
// above it; any other body is asked only for the rays that pass within its bounding sphere
// nearer than the nearest hit so far, and, when the rays come in cones (`Cones`), only for
// the cones that may meet that sphere. A triangle mesh (ray_mesh.hpp) is culled the same way,
// then each cone's rays try only the triangles the cone may meet, nearest first; rays given
// without cones are grouped in cones of consecutive rays when the caster holds a mesh (the
// hits are the same, the culling is conservative). Bodies are taken in order, a nearer hit
// (strictly) replacing the one found: the nearest hit, the first body's on a tie, as the
// reference; a cone's rays body by body (a body's constants held over its loop of rays).
//
// The rays are given in a frame (a camera's optical frame) at rotation R_f in the world,
// d = R_f d_f: the caller does not rotate them each time (R_f = I: world rays).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "ray_shapes.hpp"
#include "types.hpp"

namespace uvms::perception {

// Rays in cones: cone j holds the consecutive rays starts[j] .. starts[j + 1] - 1, all
// within half_angle_rad[j] of its unit axes row j (the rays' frame).
struct Cones {
  const double* axes = nullptr;  // (m, 3) row-major
  const double* half_angle_rad = nullptr;  // (m,)
  const std::int64_t* starts = nullptr;    // (m + 1,)
  Eigen::Index count = 0;                  // m
};

// What each of n rays met: range [m] (inf: none), the world normal (n, 3 row-major; zero for
// none) and the label (index + 1 of the body, 0: none). Filled by `RayCaster::cast`.
struct RayHits {
  double* range_m = nullptr;
  double* normal_world = nullptr;
  std::int32_t* label = nullptr;
};

class RayCaster {
 public:
  // Adds a body (its label: the returned index + 1) at the pose given.
  int add(RayShape shape, const Mat3& rotation, const Vec3& position_m);
  // Body `index` now at (R, p) in the world (InputError for no such body).
  void set_pose(int index, const Mat3& rotation, const Vec3& position_m);
  int size() const { return static_cast<int>(bodies_.size()); }
  const RayShape& shape(int index) const { return bodies_.at(index).shape; }

  // The nearest hit of each of n rays from `origin` (world) along R_f rays_f (rays_f
  // (n, 3) row-major unit rows), `cones` (or null) grouping them; `out` arrays of n.
  void cast(const Vec3& origin, const Mat3& frame_rotation, const double* rays_f,
            Eigen::Index n, const Cones* cones, RayHits out) const;

  // The rays (in order) that may meet body `index` nearer than range_m: within its bounding
  // sphere, in a cone that may meet it (all rays for an unbounded body); empty when the
  // origin is inside its solid. For the bodies cast outside the core (`external`).
  std::vector<std::int64_t> rays_toward(int index, const Vec3& origin,
                                        const Mat3& frame_rotation, const double* rays_f,
                                        Eigen::Index n, const Cones* cones,
                                        const double* range_m) const;

 private:
  struct Body {
    RayShape shape;
    Mat3 rotation;
    Vec3 position_m;
  };
  std::vector<Body> bodies_;

  // The cones that may meet the sphere of `radius` about `to_centre` (from the origin, the
  // rays' frame); false when the origin is inside it (every cone may).
  static bool cones_toward(const Cones& cones, const Vec3& to_centre_f, double radius,
                           std::vector<char>& seen);
  // Takes out of `seen` (`cones_toward`'s cones; every cone when `culled` is false) the
  // cones that cannot enter a convex body the origin is outside of: a face with the origin
  // outside its half-space (b - a . o < 0) and every ray of the cone moving away from its
  // plane or along it (a . d >= 0) keeps the whole ray outside that half-space. The body's
  // frame is at `body_to_frame` in the rays' frame. True when `seen` holds the cones.
  static bool cones_clear_of_faces(const Cones& cones, const Mat3& body_to_frame,
                                   const RayShape& shape, const Vec3& origin_local,
                                   bool culled, std::vector<char>& seen);
};

}  // namespace uvms::perception

// A triangle mesh cast in the core: the compiled counterpart of uvms_pin/perception/mesh.py
// (`TriangleMesh.hit`, Embree there), in double precision.
//
// Every ray of a cast leaves one origin o. Seen from it, triangle (p0, p1, p2) spans the
// three-sided cone of the directions o + t d, t > 0, through it: d is in it when it is on the
// inner side of the three planes through o and an edge, m_01 . d >= 0, m_12 . d >= 0,
// m_20 . d >= 0 with m_ij = s (p_i - o) x (p_j - o) (s the sign that turns them inward, that of
// the triple product). Those normals are computed once a cast, so a ray tries a triangle with
// three dot products, and a ray on an edge two triangles share is in one of them or both,
// never neither (the same vertices give the same products, of opposite signs): no ray slips
// between them. The range is that of its plane, t = (N . (p0 - o)) / (N . d), N = (p1 - p0) x
// (p2 - p0). The mesh's hit is the nearest crossing of either side; kept when it is on a
// triangle's front (its outward unit normal n . d < 0) and beyond kTMinM, else none (a ray
// from inside a closed mesh): TriangleMesh.hit's rule.
//
// What makes it fast for a camera: a cone of rays (a tile of pixels) may meet a triangle only
// if it is not wholly outside one of its three planes, a . m < -sin(half-angle) for its unit
// axis a and the unit m; and no ray meets a triangle nearer than its lower bound, the
// distance from o to the sphere about its centroid through its farthest vertex. For one cast
// the triangles are ordered by lower bound once (`MeshView`); for each cone the ones it may
// meet are kept in that order (`MeshView::candidates`), and each of its rays tries them
// nearest first, stopping at the first whose lower bound is beyond what the ray has met
// (ray_cone.hpp's `mesh_candidate`, all of a cone's rays at once).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "types.hpp"

namespace uvms::perception {

// The triangles of a mesh in its frame (f triangles), with what a cast needs of each.
struct TriangleSet {
  std::vector<Vec3> p0, p1, p2;  // the corners (a corner two triangles share: the same bits)
  std::vector<Vec3> normal;      // outward unit normal (zero for a degenerate triangle)
  std::vector<Vec3> centre;      // the centroid
  std::vector<double> radius_m;  // the farthest corner from the centroid (and a margin)

  // From vertices (v, 3) and triangles (f, 3) (row-major; InputError for an index out of
  // range or a non-finite vertex).
  static TriangleSet of(const double* vertices_m, Eigen::Index vertices,
                        const std::int64_t* triangles, Eigen::Index count);
  Eigen::Index size() const { return static_cast<Eigen::Index>(p0.size()); }
};

// A cone of rays (its unit axis in the mesh's frame, its half-angle).
struct MeshCone {
  Vec3 axis = Vec3::UnitZ();
  double half_angle_rad = 0.0;
};

// A mesh as one cast sees it from the origin `origin_local` (the mesh's frame).
class MeshView {
 public:
  MeshView(const TriangleSet& mesh, const Vec3& origin_local);

  // The triangles a ray of `cone` (null: any ray) may meet, nearest lower bound first.
  void candidates(const MeshCone* cone, std::vector<int>& out) const;

  // What a ray tries of triangle k, as plain numbers (for ray_cone.hpp's `mesh_candidate`,
  // a loop over many rays): its three inward edge normals (edge e: entries 3 e .. 3 e + 2),
  // its plane's normal N, N . (p0 - o) and its lower bound.
  struct FaceNumbers {
    double edge[9];
    double plane[3];
    double plane_offset;
    double lower_m;
  };
  FaceNumbers numbers(int k) const {
    const Face& face = faces_[k];
    FaceNumbers out;
    for (int e = 0; e < 3; ++e) {
      for (int a = 0; a < 3; ++a) out.edge[3 * e + a] = face.edge[e][a];
    }
    for (int a = 0; a < 3; ++a) out.plane[a] = face.plane[a];
    out.plane_offset = face.plane_offset;
    out.lower_m = face.lower_m;
    return out;
  }

 private:
  // what a ray tries of triangle k: its three inward edge normals (unit), its plane's normal
  // N and N . (p0 - o), its lower bound
  struct Face {
    Vec3 edge[3];
    Vec3 plane;
    double plane_offset;
    double lower_m;
    // its sphere seen from the origin: the unit direction to its centre, the sine and cosine
    // of the angle it subtends (sine 1: it holds the origin)
    Vec3 toward;
    double sin_seen, cos_seen;
  };
  std::vector<Face> faces_;  // by triangle
  std::vector<int> order_;   // the triangles seen (not edge-on to the origin) by lower bound
};

}  // namespace uvms::perception

// A triangle mesh cast in the core (ray_mesh.hpp).
#include "ray_mesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "ray_shapes.hpp"

namespace uvms::perception {

namespace {

constexpr double kPi = 3.14159265358979323846;
// what the culling tests leave to rounding: an angle [rad], a sine, a relative length
constexpr double kAngleMargin = 1e-9;
constexpr double kSineMargin = 1e-12;
constexpr double kLengthMargin = 1e-9;

}  // namespace

TriangleSet TriangleSet::of(const double* vertices_m, Eigen::Index vertices,
                            const std::int64_t* triangles, Eigen::Index count) {
  TriangleSet out;
  for (Eigen::Index i = 0; i < vertices; ++i) {
    if (!Eigen::Map<const Vec3>(vertices_m + 3 * i).allFinite()) {
      throw InputError("a mesh's vertices must be finite");
    }
  }
  for (Eigen::Index k = 0; k < count; ++k) {
    Vec3 corner[3];
    for (int c = 0; c < 3; ++c) {
      const std::int64_t index = triangles[3 * k + c];
      if (index < 0 || index >= vertices) {
        throw InputError("a mesh's triangle " + std::to_string(k) + " has no vertex " +
                         std::to_string(index));
      }
      corner[c] = Eigen::Map<const Vec3>(vertices_m + 3 * index);
    }
    out.p0.push_back(corner[0]);
    out.p1.push_back(corner[1]);
    out.p2.push_back(corner[2]);
    // as TriangleMesh.normals: (p1 - p0) x (p2 - p0), normalized
    const Vec3 normal = (corner[1] - corner[0]).cross(corner[2] - corner[0]);
    const double length = normal.norm();
    out.normal.push_back(length > 0.0 ? Vec3(normal / length) : Vec3::Zero());
    const Vec3 centre = (corner[0] + corner[1] + corner[2]) / 3.0;
    double radius = 0.0;
    for (const Vec3& p : corner) radius = std::max(radius, (p - centre).norm());
    out.centre.push_back(centre);
    out.radius_m.push_back(radius * (1.0 + kLengthMargin) + 1e-12);
  }
  return out;
}

MeshView::MeshView(const TriangleSet& mesh, const Vec3& origin_local) {
  const Eigen::Index n = mesh.size();
  faces_.resize(n);
  order_.clear();
  for (Eigen::Index k = 0; k < n; ++k) {
    Face& face = faces_[k];
    const Vec3 a = mesh.p0[k] - origin_local, b = mesh.p1[k] - origin_local,
               c = mesh.p2[k] - origin_local;
    const Vec3 ab = a.cross(b), bc = b.cross(c), ca = c.cross(a);
    const double volume = ab.dot(c);  // the triple product: 0 when o is in its plane
    if (volume == 0.0 || !std::isfinite(volume)) continue;  // edge-on: met by no ray
    const double inward = volume > 0.0 ? 1.0 : -1.0;
    const Vec3* edges[3] = {&ab, &bc, &ca};
    bool seen = true;
    for (int e = 0; e < 3; ++e) {
      const double length = edges[e]->norm();
      seen = seen && length > 0.0;
      face.edge[e] = *edges[e] * (inward / (length > 0.0 ? length : 1.0));
    }
    if (!seen) continue;
    face.plane = (mesh.p1[k] - mesh.p0[k]).cross(mesh.p2[k] - mesh.p0[k]);
    face.plane_offset = face.plane.dot(a);
    // a point of the triangle is within r of its centre: at least |centre - o| - r away
    const Vec3 to_centre = mesh.centre[k] - origin_local;
    const double distance = to_centre.norm();
    face.lower_m = distance - mesh.radius_m[k];
    face.sin_seen = distance > mesh.radius_m[k] ? mesh.radius_m[k] / distance : 1.0;
    face.cos_seen = std::sqrt(std::max(0.0, 1.0 - face.sin_seen * face.sin_seen));
    face.toward = distance > 0.0 ? Vec3(to_centre / distance) : Vec3::UnitZ();
    order_.push_back(static_cast<int>(k));
  }
  std::sort(order_.begin(), order_.end(),
            [this](int i, int j) { return faces_[i].lower_m < faces_[j].lower_m; });
}

void MeshView::candidates(const MeshCone* cone, std::vector<int>& out) const {
  out.clear();
  const double spread = cone == nullptr ? kPi : cone->half_angle_rad + kAngleMargin;
  if (spread >= 0.5 * kPi) {  // no plane through the origin holds it on one side
    out = order_;
    return;
  }
  // the cone is wholly outside an edge's plane when its axis is more than 90 degrees plus
  // its half-angle from the plane's inward normal
  const double sin_spread = std::sin(spread), cos_spread = std::cos(spread);
  const double outside = -sin_spread - kSineMargin;
  const Vec3& axis = cone->axis;
  for (const int k : order_) {
    const Face& face = faces_[k];
    // first its sphere (one dot product, which leaves out most): the cone meets it only if
    // its axis is within spread + g of the centre's direction (g the angle the sphere
    // subtends, below 90 degrees: the origin outside it), cos >= cos(spread + g)
    if (face.sin_seen < 1.0 &&
        axis.dot(face.toward) <
            cos_spread * face.cos_seen - sin_spread * face.sin_seen - kSineMargin) {
      continue;
    }
    if (axis.dot(face.edge[0]) >= outside && axis.dot(face.edge[1]) >= outside &&
        axis.dot(face.edge[2]) >= outside) {
      out.push_back(k);
    }
  }
}

}  // namespace uvms::perception

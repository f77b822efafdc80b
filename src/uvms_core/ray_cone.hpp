// The caster's loops over a cone's rays (ray_caster.cpp's `RayCaster::cast`): each kind of
// body tried against all of a cone's rays at once, the rays held by axis (`ConeRays`).
//
// The loops take plain arrays and numbers, no Eigen type: each is compiled for x86-64-v3 and
// v4 too (ray_cone.cpp, UVMS_VECTOR_CLONES), where a call into Eigen would not be inlined, and
// has no branch, so the compiler vectorizes it. They follow the shapes' formulas (ray_shapes.hpp's
// header; the Python reference's, uvms_pin/perception/shapes.py and mesh.py, which the tests
// hold them to) and compute each ray's values by the same operations in the same order
// whatever the loop's width, Eigen's Vec3 and Mat3 products' order included (noted where it
// matters): the same bits as a loop ray by ray.
// The unit is compiled with -ffp-contract=off and -fno-math-errno (CMakeLists.txt): no
// multiply-add fused in the x86-64-v3 and v4 clones (the same hits on every processor), and
// square roots that set no errno (a call that may would keep them out of the vector loops).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "ray_mesh.hpp"
#include "ray_shapes.hpp"

namespace uvms::perception {

// A cone's rays as the vectorized loops take them, one entry a ray: its world direction by
// axis, its direction in the body being cast (`local_directions`), and what it met nearest
// so far (its range is in the outputs): the body (-1: none) and the face (a convex body's,
// a cylinder's side 0 or cap +-1, a mesh's triangle).
struct ConeRays {
  std::vector<double> x, y, z, lx, ly, lz;
  std::vector<std::int64_t> body, face;
  // scratch: a convex body's slabs (a mesh's: each ray's bound, crossing and triangle)
  std::vector<double> enter, leave;
  std::vector<std::int64_t> entered;
  std::vector<double> gaps;  // a convex body's faces' gaps b_f - o . a_f (one a face)
  void resize(Eigen::Index n) {
    if (static_cast<Eigen::Index>(x.size()) >= n) return;
    for (auto* v : {&x, &y, &z, &lx, &ly, &lz, &enter, &leave}) v->resize(n);
    for (auto* v : {&body, &face, &entered}) v->resize(n);
  }
};

// A rotation's entries, row by row (r[3 i + j] = R(i, j)).
struct Rows {
  double r[9];
  explicit Rows(const Mat3& m) {
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) r[3 * i + j] = m(i, j);
    }
  }
};

// A body's bounding sphere as a cast sees it (ray_caster.cpp's `bound_around`): the centre
// from the origin, |that|^2, the radius with a margin and its square (unbounded: every ray
// may meet it).
struct Bound {
  double c0, c1, c2, centre2, reach, reach2;
  bool unbounded;
};

// Whether a ray (world d) may meet the sphere nearer than `best`: it passes within the
// radius, not all behind. Without a branch (a vector loop takes both sides).
[[gnu::always_inline]] inline bool may_reach(const Bound& b, double dx, double dy, double dz,
                                             double best) {
  const double along = (dx * b.c0 + dy * b.c1) + dz * b.c2;  // d.dot(to_centre)
  const double across2 = b.centre2 - along * along;
  return b.unbounded |
         ((across2 <= b.reach2) & (along + b.reach > 0.0) & (along - b.reach < best));
}

// The hits kept so far: range (the outputs'), body and face of each ray.
struct Nearest {
  double* __restrict range;
  std::int64_t* __restrict body;
  std::int64_t* __restrict face;
};

// Keeps body k's crossing t (face) of ray i where the ray may meet it and it is nearer.
[[gnu::always_inline]] inline void keep_nearer(const Nearest& out, Eigen::Index i, double t,
                                               std::int64_t face, bool may, std::int64_t k) {
  const bool take = may & (t < out.range[i]);
  out.range[i] = take ? t : out.range[i];
  out.body[i] = take ? k : out.body[i];
  out.face[i] = take ? face : out.face[i];
}

// A cone's rays' directions twice: in the world (x, y, z: for a body's bound) and in the
// body's frame (lx, ly, lz: `local_directions`).
struct Directions {
  const double* __restrict x;
  const double* __restrict y;
  const double* __restrict z;
  const double* __restrict lx;
  const double* __restrict ly;
  const double* __restrict lz;
};

// d = R_f d_f of n rays (row-major (n, 3)), by axis. Eigen's Mat3 * Vec3 sums the first two
// rows as (r0 f0 + r1 f1) + r2 f2 (one vector of two) and the third as r0 f0 + (r1 f1 +
// r2 f2) (a reduction of the row).
void world_directions(const Rows& rows, const double* __restrict rays_f, Eigen::Index n,
                      double* __restrict x, double* __restrict y, double* __restrict z);

// d_b = R^T d in a body's frame (R its rotation): Eigen's R.transpose() * d, each entry a
// reduction (a + b) + c of a column of R.
void local_directions(const Rows& rows, Eigen::Index n, const double* __restrict x,
                      const double* __restrict y, const double* __restrict z,
                      double* __restrict lx, double* __restrict ly, double* __restrict lz);

// A plane: t = -h / (d . n) when d . n < 0 < h (and t > kTMinM).
void nearer_on_plane(double n0, double n1, double n2, double height, std::int64_t k,
                     Eigen::Index n, const double* __restrict x, const double* __restrict y,
                     const double* __restrict z, Nearest out);

// A sphere of `radius` seen from o (its frame): the smaller root of |o + t d|^2 = r^2
// from outside; an ellipsoid of semi-axes s: the unit sphere's in x / s.
// A kernel keeps a body's crossing of a ray where the ray may meet its bound (`may_reach`)
// and it is nearer than what the ray met (`keep_nearer`).
void nearer_on_sphere(double o0, double o1, double o2, double c, const Bound& bound,
                      std::int64_t k, Eigen::Index n, Directions d, Nearest out);

void nearer_on_ellipsoid(const double* os, double oo, const double* semi_axes,
                         const Bound& bound, std::int64_t k, Eigen::Index n, Directions d,
                         Nearest out);

// A cylinder of `radius` and `length` along z: the slab |z| <= L / 2 and the infinite
// cylinder x^2 + y^2 <= r^2; the face: its side (0) or a cap (+-1). std::max(a, b) is
// (a < b) ? b : a, std::min(a, b) is (b < a) ? b : a.
void nearer_on_cylinder(double o0, double o1, double o2, double radius, double length,
                        const Bound& bound, std::int64_t k, Eigen::Index n, Directions d,
                        Nearest out);

// A convex body A x <= b: each face f (unit row a, its gap b_f - o . a) bounds t from below
// (a . d < 0: the face entered last) or above.
void nearer_on_convex(const double* faces_a, const double* gaps, Eigen::Index faces,
                      const Bound& bound, std::int64_t k, Eigen::Index n, Directions d,
                      double* __restrict enter, double* __restrict leave,
                      std::int64_t* __restrict entered, Nearest out);

// One candidate triangle of a mesh against a cone's rays (their directions in its frame), the
// candidates taken nearest lower bound first (`MeshView::candidates`). A ray still looks
// while the triangle's lower bound is below min(its crossing so far, its bound) (the
// candidates come by lower bound: once it stops, it stops for good); inside the triangle's
// three edges it crosses its plane at t = (N . (p0 - o)) / (N . d), kept if t > 0 and nearer.
// Returns how many rays still looked (0: none will for the later candidates).
Eigen::Index mesh_candidate(const MeshView::FaceNumbers& f, std::int64_t k, Eigen::Index n,
                            Directions d, const double* __restrict bound,
                            double* __restrict t_out, std::int64_t* __restrict k_out);

}  // namespace uvms::perception

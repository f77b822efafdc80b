// The caster's loops over a cone's rays (ray_cone.hpp documents each).
#include "ray_cone.hpp"

#include <cmath>

#include "vector_exp.hpp"

namespace uvms::perception {

UVMS_VECTOR_CLONES
void world_directions(const Rows& rows, const double* __restrict rays_f, Eigen::Index n,
                      double* __restrict x, double* __restrict y, double* __restrict z) {
  const double* r = rows.r;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double f0 = rays_f[3 * i], f1 = rays_f[3 * i + 1], f2 = rays_f[3 * i + 2];
    x[i] = (r[0] * f0 + r[1] * f1) + r[2] * f2;
    y[i] = (r[3] * f0 + r[4] * f1) + r[5] * f2;
    z[i] = r[6] * f0 + (r[7] * f1 + r[8] * f2);
  }
}

UVMS_VECTOR_CLONES
void local_directions(const Rows& rows, Eigen::Index n, const double* __restrict x,
                      const double* __restrict y, const double* __restrict z,
                      double* __restrict lx, double* __restrict ly, double* __restrict lz) {
  const double* r = rows.r;
  for (Eigen::Index i = 0; i < n; ++i) {
    lx[i] = (r[0] * x[i] + r[3] * y[i]) + r[6] * z[i];
    ly[i] = (r[1] * x[i] + r[4] * y[i]) + r[7] * z[i];
    lz[i] = (r[2] * x[i] + r[5] * y[i]) + r[8] * z[i];
  }
}

UVMS_VECTOR_CLONES
void nearer_on_plane(double n0, double n1, double n2, double height, std::int64_t k,
                     Eigen::Index n, const double* __restrict x, const double* __restrict y,
                     const double* __restrict z, Nearest out) {
  for (Eigen::Index i = 0; i < n; ++i) {
    const double rate = (x[i] * n0 + y[i] * n1) + z[i] * n2;
    const double along = -height / rate;
    const double t = ((rate < 0.0) & (height > 0.0) & (along > kTMinM)) ? along : kInf;
    keep_nearer(out, i, t, 0, true, k);
  }
}

UVMS_VECTOR_CLONES
void nearer_on_sphere(double o0, double o1, double o2, double c, const Bound& bound,
                      std::int64_t k, Eigen::Index n, Directions d, Nearest out) {
  for (Eigen::Index i = 0; i < n; ++i) {
    const double b = (o0 * d.lx[i] + o1 * d.ly[i]) + o2 * d.lz[i];
    const double disc = b * b - c;
    const double enter = -b - std::sqrt(disc);
    const double t = ((disc >= 0.0) & (enter > kTMinM) & (c > 0.0)) ? enter : kInf;
    keep_nearer(out, i, t, 0, may_reach(bound, d.x[i], d.y[i], d.z[i], out.range[i]), k);
  }
}

UVMS_VECTOR_CLONES
void nearer_on_ellipsoid(const double* os, double oo, const double* semi_axes,
                         const Bound& bound, std::int64_t k, Eigen::Index n, Directions d,
                         Nearest out) {
  const double s0 = semi_axes[0], s1 = semi_axes[1], s2 = semi_axes[2];
  const double os0 = os[0], os1 = os[1], os2 = os[2];
  for (Eigen::Index i = 0; i < n; ++i) {
    const double d0 = d.lx[i] / s0, d1 = d.ly[i] / s1, d2 = d.lz[i] / s2;
    const double a = (d0 * d0 + d1 * d1) + d2 * d2;
    const double b = ((os0 * d0 + os1 * d1) + os2 * d2) / a;
    const double c = (oo - 1.0) / a;
    const double disc = b * b - c;
    const double enter = -b - std::sqrt(disc);
    const double t = ((disc >= 0.0) & (enter > kTMinM) & (c > 0.0)) ? enter : kInf;
    keep_nearer(out, i, t, 0, may_reach(bound, d.x[i], d.y[i], d.z[i], out.range[i]), k);
  }
}

UVMS_VECTOR_CLONES
void nearer_on_cylinder(double o0, double o1, double o2, double radius, double length,
                        const Bound& bound, std::int64_t k, Eigen::Index n, Directions d,
                        Nearest out) {
  const double half = 0.5 * length;
  const double top_of_parallel = (half - o2) / 1e-300, bottom_of_parallel = (half + o2) / 1e-300;
  const double parallel_leave =
      bottom_of_parallel < top_of_parallel ? bottom_of_parallel : top_of_parallel;
  const double c_raw = o0 * o0 + o1 * o1 - radius * radius;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double dx = d.lx[i], dy = d.ly[i], dz = d.lz[i];
    const bool down = dz < 0.0, up = dz > 0.0;
    const double rate = (down | up) ? dz : 1.0;
    const double top = (half - o2) / rate, bottom = (half + o2) / -rate;
    const double cap_enter = down ? top : (up ? bottom : -kInf);
    const double cap_leave = up ? top : (down ? bottom : parallel_leave);
    const double cap_z = up ? -1.0 : 1.0;
    const double a = dx * dx + dy * dy;
    const bool flat = a < 1e-300;  // along the axis: inside the side's region or never
    const double safe = flat ? 1.0 : a;
    const double b = (o0 * dx + o1 * dy) / safe;
    const double disc = b * b - c_raw / safe;
    const double root = std::sqrt(disc);
    const double side_enter = flat ? (c_raw <= 0.0 ? -kInf : kInf)
                                   : (disc >= 0.0 ? -b - root : kInf);
    const double side_leave = flat ? (c_raw <= 0.0 ? kInf : -kInf)
                                   : (disc >= 0.0 ? -b + root : -kInf);
    const double enter = cap_enter < side_enter ? side_enter : cap_enter;
    const double leave = side_leave < cap_leave ? side_leave : cap_leave;
    const std::int64_t face = side_enter >= cap_enter ? 0 : static_cast<std::int64_t>(cap_z);
    const double t = ((enter > kTMinM) & (enter <= leave)) ? enter : kInf;
    keep_nearer(out, i, t, face, may_reach(bound, d.x[i], d.y[i], d.z[i], out.range[i]), k);
  }
}

UVMS_VECTOR_CLONES
void nearer_on_convex(const double* faces_a, const double* gaps, Eigen::Index faces,
                      const Bound& bound, std::int64_t k, Eigen::Index n, Directions d,
                      double* __restrict enter, double* __restrict leave,
                      std::int64_t* __restrict entered, Nearest out) {
  for (Eigen::Index i = 0; i < n; ++i) {
    enter[i] = -kInf;
    leave[i] = kInf;
    entered[i] = 0;
  }
  for (Eigen::Index f = 0; f < faces; ++f) {
    const double a0 = faces_a[3 * f], a1 = faces_a[3 * f + 1], a2 = faces_a[3 * f + 2];
    const double gap = gaps[f];
    for (Eigen::Index i = 0; i < n; ++i) {
      double rate = (d.lx[i] * a0 + d.ly[i] * a1) + d.lz[i] * a2;
      rate = rate == 0.0 ? 1e-300 : rate;  // parallel: a huge t of the gap's sign
      const double t = gap / rate;
      const bool facing = rate < 0.0;
      const bool further = facing & (t > enter[i]);
      enter[i] = further ? t : enter[i];
      entered[i] = further ? f : entered[i];
      leave[i] = (!facing & (t < leave[i])) ? t : leave[i];
    }
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = ((enter[i] > kTMinM) & (enter[i] <= leave[i])) ? enter[i] : kInf;
    keep_nearer(out, i, t, entered[i], may_reach(bound, d.x[i], d.y[i], d.z[i], out.range[i]),
                k);
  }
}

UVMS_VECTOR_CLONES
Eigen::Index mesh_candidate(const MeshView::FaceNumbers& f, std::int64_t k, Eigen::Index n,
                            Directions d, const double* __restrict bound,
                            double* __restrict t_out, std::int64_t* __restrict k_out) {
  const double e00 = f.edge[0], e01 = f.edge[1], e02 = f.edge[2];
  const double e10 = f.edge[3], e11 = f.edge[4], e12 = f.edge[5];
  const double e20 = f.edge[6], e21 = f.edge[7], e22 = f.edge[8];
  const double p0 = f.plane[0], p1 = f.plane[1], p2 = f.plane[2];
  const double offset = f.plane_offset, lower = f.lower_m;
  Eigen::Index looking = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double dx = d.lx[i], dy = d.ly[i], dz = d.lz[i];
    const double limit = bound[i] < t_out[i] ? bound[i] : t_out[i];  // std::min(t, bound)
    const bool active = lower < limit;
    looking += active;
    const double side0 = (dx * e00 + dy * e01) + dz * e02;  // d . edge
    const double side1 = (dx * e10 + dy * e11) + dz * e12;
    const double side2 = (dx * e20 + dy * e21) + dz * e22;
    const bool inside = (side0 >= 0.0) & (side1 >= 0.0) & (side2 >= 0.0);
    const double rate = (p0 * dx + p1 * dy) + p2 * dz;  // N . d
    const double t = offset / rate;
    const bool nearer =
        active & inside & (rate != 0.0) & (t > 0.0) & (t < t_out[i]);
    t_out[i] = nearer ? t : t_out[i];
    k_out[i] = nearer ? k : k_out[i];
  }
  return looking;
}

}  // namespace uvms::perception

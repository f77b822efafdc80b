// The perception's caster and camera shading in the nanobind module (ray_caster.hpp,
// camera_shading.hpp). The Python side is uvms_pin/perception/compiled_caster.py: it fills
// the caster with the scene's shapes (its triangle meshes too), casts the shapes the core does
// not know between the two calls, and passes the output arrays, which are written in place (no
// array is allocated here).
#include <nanobind/eigen/dense.h>
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "camera_shading.hpp"
#include "ray_caster.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

using uvms::InputError;
using uvms::Mat3;
using uvms::Vec3;
using namespace uvms::perception;

using In1 = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using In2 = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Out1 = nb::ndarray<double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Out2 = nb::ndarray<double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Labels = nb::ndarray<std::int32_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using InLabels = nb::ndarray<const std::int32_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using InIndex = nb::ndarray<const std::int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using OutIndex = nb::ndarray<std::int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using InTriangles = nb::ndarray<const std::int64_t, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Noise = nb::ndarray<const float, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using In1f = nb::ndarray<const float, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Rgb = nb::ndarray<std::uint8_t, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Out1f = nb::ndarray<float, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Labels16 = nb::ndarray<std::int16_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Codes = nb::ndarray<const std::uint16_t, nb::ndim<2>, nb::c_contig, nb::device::cpu>;

void require(bool ok, const std::string& what) {
  if (!ok) throw InputError(what);
}

Eigen::Index rows3(const In2& a, const char* name) {
  require(a.shape(1) == 3, std::string(name) + " must have shape (n, 3)");
  return static_cast<Eigen::Index>(a.shape(0));
}

void check_pose(const Mat3& rotation, const Vec3& position_m) {
  require(rotation.allFinite() && position_m.allFinite(), "a body's pose must be finite");
}

// The cones of the rays (all three or none): axes (m, 3), half-angles (m,), starts (m + 1,).
struct ConeArgs {
  std::optional<In2> axes;
  std::optional<In1> half_angle_rad;
  std::optional<InIndex> starts;

  std::optional<Cones> view() const {
    if (!axes && !half_angle_rad && !starts) return std::nullopt;
    require(axes && half_angle_rad && starts, "cones need their axes, half-angles and starts");
    const auto m = static_cast<Eigen::Index>(axes->shape(0));
    require(axes->shape(1) == 3 && half_angle_rad->shape(0) == static_cast<size_t>(m) &&
                starts->shape(0) == static_cast<size_t>(m + 1),
            "cones: axes (m, 3), half_angle_rad (m,), starts (m + 1,) expected");
    return Cones{axes->data(), half_angle_rad->data(), starts->data(), m};
  }
};

// A camera's reflectances (labels + 1, 3) and lights (L, 9) checked (`what`: the function).
void check_shading(const In2& reflectance, const In2& lights, const std::string& what) {
  require(reflectance.shape(1) == 3 && reflectance.shape(0) >= 1,
          what + ": reflectance (labels + 1, 3) expected");
  require(lights.shape(1) == 9, what + ": lights (L, 9) expected: source (3), unit axis (3), "
                                       "intensity, half_angle_rad, edge_rad");
}

// A cast's n hits, as shade_camera and record_camera take them: its rays (n, 3), the
// range_m (n,), normal_world (n, 3), label (n,) and pixel_of (n,) of each; n.
Eigen::Index hits_count(const In2& rays, const In1& range_m, const In2& normal_world,
                        const InLabels& label, const InIndex& pixel_of, const std::string& what) {
  const Eigen::Index n = rows3(rays, "rays");
  const auto sized = [n](size_t size) { return size == static_cast<size_t>(n); };
  require(sized(range_m.shape(0)) && sized(normal_world.shape(0)) &&
              normal_world.shape(1) == 3 && sized(label.shape(0)) && sized(pixel_of.shape(0)),
          what + ": range_m (n,), normal_world (n, 3), label (n,), pixel_of (n,)");
  return n;
}

// The lights' rows (source (3), unit axis (3), intensity, half_angle_rad, edge_rad).
std::vector<SpotLight> spots_of(const In2& lights) {
  std::vector<SpotLight> spots;
  for (size_t j = 0; j < lights.shape(0); ++j) {
    const double* row = lights.data() + 9 * j;
    spots.push_back({Vec3(row[0], row[1], row[2]), Vec3(row[3], row[4], row[5]), row[6], row[7],
                     row[8]});
  }
  return spots;
}

RayShape shape_of(ShapeKind kind, double bound_radius_m) {
  RayShape s;
  s.kind = kind;
  s.bound_radius_m = bound_radius_m;
  return s;
}

int add_checked(RayCaster& caster, RayShape shape, const Mat3& rotation, const Vec3& position) {
  check_pose(rotation, position);
  require(!(shape.bound_radius_m <= 0.0) && !std::isnan(shape.bound_radius_m),
          "a body's bound_radius_m must be > 0");
  return caster.add(std::move(shape), rotation, position);
}

}  // namespace

void bind_perception(nb::module_& m) {
  nb::class_<RayCaster>(m, "RayCaster",
                        "Bodies (analytic shapes, or external ones cast elsewhere) at poses; "
                        "cast finds each ray's nearest hit (uvms_pin.perception.caster's "
                        "mirror). Each add_* returns the body's index (its label - 1).")
      .def(nb::init<>())
      .def("__len__", &RayCaster::size)
      .def(
          "add_plane",
          [](RayCaster& c, const Mat3& rotation, const Vec3& position) {
            return add_checked(c, shape_of(ShapeKind::plane, kInf), rotation, position);
          },
          "rotation"_a, "position_m"_a, "The plane z = 0 of its frame, seen from z > 0.")
      .def(
          "add_sphere",
          [](RayCaster& c, double radius_m, const Mat3& rotation, const Vec3& position) {
            require(radius_m > 0.0, "a sphere's radius_m must be > 0");
            RayShape s = shape_of(ShapeKind::sphere, radius_m);
            s.radius_m = radius_m;
            return add_checked(c, std::move(s), rotation, position);
          },
          "radius_m"_a, "rotation"_a, "position_m"_a)
      .def(
          "add_ellipsoid",
          [](RayCaster& c, const Vec3& semi_axes_m, const Mat3& rotation, const Vec3& position) {
            require((semi_axes_m.array() > 0.0).all(), "an ellipsoid's semi-axes must be > 0");
            RayShape s = shape_of(ShapeKind::ellipsoid, semi_axes_m.maxCoeff());
            s.semi_axes_m = semi_axes_m;
            return add_checked(c, std::move(s), rotation, position);
          },
          "semi_axes_m"_a, "rotation"_a, "position_m"_a)
      .def(
          "add_convex",
          [](RayCaster& c, const FaceRows& normals, const Eigen::VectorXd& offsets,
             double bound_radius_m, const Mat3& rotation, const Vec3& position) {
            require(normals.rows() >= 1 && offsets.size() == normals.rows(),
                    "a convex body needs normals (f, 3) and offsets (f,), f >= 1");
            require(normals.allFinite() && offsets.allFinite(),
                    "a convex body's faces must be finite");
            RayShape s = shape_of(ShapeKind::convex, bound_radius_m);
            s.normals = normals;
            s.offsets = offsets;
            return add_checked(c, std::move(s), rotation, position);
          },
          "normals"_a, "offsets"_a, "bound_radius_m"_a, "rotation"_a, "position_m"_a,
          "The polytope A x <= b (outward unit rows of A).")
      .def(
          "add_cylinder",
          [](RayCaster& c, double radius_m, double length_m, const Mat3& rotation,
             const Vec3& position) {
            require(radius_m > 0.0 && length_m > 0.0, "a cylinder's radius and length must be > 0");
            RayShape s = shape_of(ShapeKind::cylinder, std::hypot(radius_m, 0.5 * length_m));
            s.radius_m = radius_m;
            s.length_m = length_m;
            return add_checked(c, std::move(s), rotation, position);
          },
          "radius_m"_a, "length_m"_a, "rotation"_a, "position_m"_a)
      .def(
          "add_mesh",
          [](RayCaster& c, const In2& vertices_m, const InTriangles& triangles,
             double bound_radius_m, const Mat3& rotation, const Vec3& position) {
            const Eigen::Index vertices = rows3(vertices_m, "vertices_m");
            require(triangles.shape(1) == 3 && triangles.shape(0) >= 1,
                    "a mesh needs triangles (f, 3) of vertex indices, f >= 1");
            RayShape s = shape_of(ShapeKind::mesh, bound_radius_m);
            s.triangles = std::make_shared<const TriangleSet>(
                TriangleSet::of(vertices_m.data(), vertices, triangles.data(),
                                static_cast<Eigen::Index>(triangles.shape(0))));
            return add_checked(c, std::move(s), rotation, position);
          },
          "vertices_m"_a, "triangles"_a, "bound_radius_m"_a, "rotation"_a, "position_m"_a,
          "The triangles vertices_m[triangles] seen from outside (ray_mesh.hpp): a ray's "
          "nearest crossing, none on a triangle's back (TriangleMesh.hit's rule); "
          "bound_radius_m: the farthest vertex from the mesh's origin.")
      .def(
          "add_external",
          [](RayCaster& c, double bound_radius_m, const Mat3& rotation, const Vec3& position) {
            return add_checked(c, shape_of(ShapeKind::external, bound_radius_m), rotation,
                               position);
          },
          "bound_radius_m"_a, "rotation"_a, "position_m"_a,
          "A body cast outside the core (a mesh): cast leaves it out; rays_toward gives "
          "its rays.")
      .def(
          "set_pose",
          [](RayCaster& c, int index, const Mat3& rotation, const Vec3& position) {
            check_pose(rotation, position);
            c.set_pose(index, rotation, position);
          },
          "index"_a, "rotation"_a, "position_m"_a)
      .def(
          "cast",
          [](const RayCaster& c, const Vec3& origin, const Mat3& frame_rotation, const In2& rays,
             Out1 range_m, Out2 normal_world, Labels label, std::optional<In2> cone_axes,
             std::optional<In1> cone_half_angle_rad, std::optional<InIndex> cone_starts) {
            const Eigen::Index n = rows3(rays, "rays");
            require(origin.allFinite() && frame_rotation.allFinite(),
                    "the rays' origin and frame must be finite");
            require(range_m.shape(0) == static_cast<size_t>(n) && normal_world.shape(0) ==
                        static_cast<size_t>(n) && normal_world.shape(1) == 3 &&
                        label.shape(0) == static_cast<size_t>(n),
                    "cast: range_m (n,), normal_world (n, 3), label (n,) expected");
            const auto cones = ConeArgs{cone_axes, cone_half_angle_rad, cone_starts}.view();
            c.cast(origin, frame_rotation, rays.data(), n, cones ? &*cones : nullptr,
                   {range_m.data(), normal_world.data(), label.data()});
          },
          "origin_world"_a, "frame_rotation"_a, "rays"_a, "range_m"_a.noconvert(),
          "normal_world"_a.noconvert(), "label"_a.noconvert(), "cone_axes"_a = nb::none(),
          "cone_half_angle_rad"_a = nb::none(), "cone_starts"_a = nb::none(),
          "The nearest hit of each ray from origin_world along frame_rotation @ rays[i] "
          "(unit rows), written into range_m (inf: none), normal_world and label (0: none); "
          "external bodies left out.")
      .def(
          "rays_toward",
          [](const RayCaster& c, int index, const Vec3& origin, const Mat3& frame_rotation,
             const In2& rays, const In1& range_m, OutIndex rows, std::optional<In2> cone_axes,
             std::optional<In1> cone_half_angle_rad, std::optional<InIndex> cone_starts) {
            const Eigen::Index n = rows3(rays, "rays");
            require(index >= 0 && index < c.size(), "rays_toward: no such body");
            require(range_m.shape(0) == static_cast<size_t>(n) &&
                        rows.shape(0) == static_cast<size_t>(n),
                    "rays_toward: range_m (n,) and rows (n,) expected");
            const auto cones = ConeArgs{cone_axes, cone_half_angle_rad, cone_starts}.view();
            const auto found = c.rays_toward(index, origin, frame_rotation, rays.data(), n,
                                             cones ? &*cones : nullptr, range_m.data());
            std::copy(found.begin(), found.end(), rows.data());
            return found.size();
          },
          "index"_a, "origin_world"_a, "frame_rotation"_a, "rays"_a, "range_m"_a,
          "rows"_a.noconvert(),
          "cone_axes"_a = nb::none(), "cone_half_angle_rad"_a = nb::none(),
          "cone_starts"_a = nb::none(),
          "The rays that may meet body index nearer than range_m, written into rows; "
          "their count.");

  m.def(
      "shade_camera",
      [](const Vec3& origin, const Mat3& frame_rotation, const In2& rays, const In1& range_m,
         const In2& normal_world, const InLabels& label, const InIndex& pixel_of,
         const In2& reflectance, const Vec3& kd_per_m, const Vec3& beta_d_per_m,
         const Vec3& beta_b_per_m, double surface_irradiance, const Vec3& veiling,
         const In2& lights, Out1 depth_m, Out2 normal_out, Labels label_out, Out2 radiance) {
        const Eigen::Index n =
            hits_count(rays, range_m, normal_world, label, pixel_of, "shade_camera");
        const auto sized = [n](size_t size) { return size == static_cast<size_t>(n); };
        require(sized(depth_m.shape(0)) && sized(normal_out.shape(0)) &&
                    normal_out.shape(1) == 3 && sized(label_out.shape(0)) &&
                    sized(radiance.shape(0)) && radiance.shape(1) == 3,
                "shade_camera: the outputs need n pixels");
        check_shading(reflectance, lights, "shade_camera");
        WaterColour water{kd_per_m, beta_d_per_m, beta_b_per_m, surface_irradiance, veiling};
        shade(origin, frame_rotation, rays.data(), n, range_m.data(), normal_world.data(),
              label.data(), pixel_of.data(), reflectance.data(),
              static_cast<Eigen::Index>(reflectance.shape(0)), water, spots_of(lights),
              {depth_m.data(), normal_out.data(), label_out.data(), radiance.data()});
      },
      "origin_world"_a, "frame_rotation"_a, "rays"_a, "range_m"_a, "normal_world"_a, "label"_a,
      "pixel_of"_a, "reflectance"_a, "kd_per_m"_a, "beta_d_per_m"_a, "beta_b_per_m"_a,
      "surface_irradiance"_a, "veiling"_a, "lights"_a, "depth_m"_a.noconvert(),
      "normal_out"_a.noconvert(), "label_out"_a.noconvert(), "radiance"_a.noconvert(),
      "A camera's pixels from its rays' hits (in the caster's order; ray i is pixel "
      "pixel_of[i]): z-depth (NaN: nothing met), normals, labels and the underwater image "
      "formation model's radiance, written into the outputs (pixel order).");

  m.def(
      "record_camera",
      [](const Vec3& origin, const Mat3& frame_rotation, const In2& rays, const In1& range_m,
         const In2& normal_world, const InLabels& label, const InIndex& pixel_of,
         const In2& reflectance, const Vec3& kd_per_m, const Vec3& beta_d_per_m,
         const Vec3& beta_b_per_m, double surface_irradiance, const Vec3& veiling,
         const In2& lights, std::optional<Codes> noise_codes, const In1f& noise_levels,
         double scale, double noise_counts, Out1f depth_m, Labels16 label_out, Rgb rgb) {
        const Eigen::Index n =
            hits_count(rays, range_m, normal_world, label, pixel_of, "record_camera");
        const auto sized = [n](size_t size) { return size == static_cast<size_t>(n); };
        require(sized(depth_m.shape(0)) && sized(label_out.shape(0)) && sized(rgb.shape(0)) &&
                    rgb.shape(1) == 3,
                "record_camera: depth_m (n,), label_out (n,) and rgb (n, 3) expected");
        require(!noise_codes || (sized(noise_codes->shape(0)) && noise_codes->shape(1) == 3),
                "record_camera: noise_codes (n, 3) expected");
        require(noise_levels.shape(0) == 65536, "record_camera: noise_levels (65536,) expected");
        check_shading(reflectance, lights, "record_camera");
        WaterColour water{kd_per_m, beta_d_per_m, beta_b_per_m, surface_irradiance, veiling};
        CameraRecord out{depth_m.data(), label_out.data(), rgb.data(),
                         noise_codes ? noise_codes->data() : nullptr, noise_levels.data(),
                         scale, noise_counts};
        shade_record(origin, frame_rotation, rays.data(), n, range_m.data(), normal_world.data(),
                     label.data(), pixel_of.data(), reflectance.data(),
                     static_cast<Eigen::Index>(reflectance.shape(0)), water, spots_of(lights),
                     out);
      },
      "origin_world"_a, "frame_rotation"_a, "rays"_a, "range_m"_a, "normal_world"_a, "label"_a,
      "pixel_of"_a, "reflectance"_a, "kd_per_m"_a, "beta_d_per_m"_a, "beta_b_per_m"_a,
      "surface_irradiance"_a, "veiling"_a, "lights"_a, "noise_codes"_a.none(),
      "noise_levels"_a, "scale"_a, "noise_counts"_a, "depth_m"_a.noconvert(),
      "label_out"_a.noconvert(), "rgb"_a.noconvert(),
      "shade_camera's image as a firing records it, written into the outputs (pixel order): "
      "the z-depth in float32 (NaN: nothing met), the labels in int16 and the 8-bit colour "
      "of eight_bit, its noise the values noise_levels[noise_codes] (None: none).");

  m.def(
      "eight_bit",
      [](const In2& radiance, double scale, double noise_counts, std::optional<Noise> noise,
         Rgb rgb) {
        const auto same = [&radiance](size_t rows, size_t cols) {
          return rows == radiance.shape(0) && cols == radiance.shape(1);
        };
        require(same(rgb.shape(0), rgb.shape(1)), "eight_bit: rgb must have radiance's shape");
        require(!noise || same(noise->shape(0), noise->shape(1)),
                "eight_bit: noise must have radiance's shape");
        eight_bit(radiance.data(), noise ? noise->data() : nullptr,
                  static_cast<Eigen::Index>(radiance.size()), scale, noise_counts, rgb.data());
      },
      "radiance"_a, "scale"_a, "noise_counts"_a, "noise"_a.none(), "rgb"_a.noconvert(),
      "The 8-bit counts of scale * radiance + noise_counts * noise (float32, or None), "
      "rounded (to even on a tie) and clipped to [0, 255], written into rgb.");
}

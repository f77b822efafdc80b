#include "object_contacts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include <coal/collision.h>
#include <coal/contact_patch.h>
#include <coal/distance.h>
#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <pinocchio/spatial/explog.hpp>

#include "joint_limits.hpp"
#include "world_touch.hpp"

namespace uvms {

namespace {

// |axis . n| beyond which a cylinder stands on an end face (gaps.py's _STANDING)
constexpr double kStanding = 1.0 - 1.0e-9;
// the Gauss-Seidel sweeps stop when no impulse changes its rows' velocity by more [m/s]
constexpr double kTolerance = 1.0e-10;
constexpr int kMaxSweeps = 20000;
// a stalled solve is kept with a residual of at most this fraction of its rows' largest speed
// |g|_inf, and at least kAcceptableResidual [m/s] (step.py's ACCEPTABLE_RELATIVE_RESIDUAL,
// ACCEPTABLE_RESIDUAL_M_S)
constexpr double kAcceptableRelative = 1.0e-4;
constexpr double kAcceptableResidual = 1.0e-5;
// a solve is taken as stalled, from sweep kFirstStallCheck, when its residual at a check every
// kStallCheck sweeps is more than kStallRatio of the last check's (and acceptable)
constexpr int kFirstStallCheck = 2000;
constexpr int kStallCheck = 1000;
constexpr double kStallRatio = 0.5;
// a solve that stops progressing within this residual [m/s] has converged (a tenth of the
// reference ADMM's 1e-8): it stops there without being counted as stalled
constexpr double kConverged = 1.0e-9;

// The candidates of a piece against a plane by points of its own (_plane_points of gaps.py).
void plane_points(const ContactShape& piece, const pinocchio::SE3& where, const Vec3& normal,
                  const Vec3& origin, int p, int o, std::vector<ContactCandidate>& out) {
  auto add = [&](int corner, const Vec3& point) {
    out.push_back({p, o, corner, point, normal, (point - origin).dot(normal)});
  };
  if (piece.kind == ContactKind::cylinder) {
    const Vec3 axis = where.rotation().col(2);
    const Vec3 across = normal - axis * axis.dot(normal);
    if (across.norm() > std::sqrt(1.0 - kStanding * kStanding)) {
      const Vec3 down = across.normalized();
      const auto& cylinder = static_cast<const coal::Cylinder&>(*piece.geometry);
      for (int rim = 0; rim < 2; ++rim) {
        const double side = rim == 0 ? -1.0 : 1.0;
        add(-2 - rim, where.translation() + side * cylinder.halfLength * axis -
                          cylinder.radius * down);
      }
      return;
    }
  }
  for (Eigen::Index c = 0; c < piece.corners_m.cols(); ++c) {
    add(static_cast<int>(c), where.translation() + where.rotation() * piece.corners_m.col(c));
  }
}

}  // namespace

// coal's signed distance and nearest point on the piece (_coal_candidate of gaps.py).
ContactCandidate coal_candidate(const ContactShape& piece, const pinocchio::SE3& where,
                                const ContactShape& object, const pinocchio::SE3& object_where,
                                int p, int o) {
  static const coal::DistanceRequest request;
  coal::DistanceResult result;
  const double gap = coal::distance(piece.geometry.get(), transform_of(where),
                                    object.geometry.get(), transform_of(object_where), request,
                                    result);
  // coal's normal points from the first shape (the piece) to the second (the object)
  return {p, o, -1, result.nearest_points[0], -result.normal, gap};
}

namespace {

// coal's contact patch of two shapes within reach_m [m] of each other, into `patches`: true
// when it has two vertices or more (a face or an edge) (_patch of gaps.py)
bool face_patch(const coal::CollisionGeometry* shape_1, const coal::Transform3s& transform_1,
                const coal::CollisionGeometry* shape_2, const coal::Transform3s& transform_2,
                double reach_m, coal::ContactPatchResult& patches) {
  // one patch, curved rims sampled at 12 points, features within 1 mm (coal's defaults)
  static const coal::ContactPatchRequest patch_request;
  coal::CollisionRequest request;
  request.security_margin = reach_m;  // a pair within the reach counts as touching
  coal::CollisionResult result;
  if (coal::collide(shape_1, transform_1, shape_2, transform_2, request, result) == 0) {
    return false;
  }
  patches.set(patch_request);
  coal::computeContactPatch(shape_1, transform_1, shape_2, transform_2, result, patch_request,
                            patches);
  return patches.numContactPatches() > 0 && patches.getContactPatch(0).size() >= 2;
}

}  // namespace

void patch_candidates(const ContactShape& piece, const pinocchio::SE3& where,
                      const ContactShape& object, const pinocchio::SE3& object_where, int p,
                      int o, double reach_m, std::vector<ContactCandidate>& out) {
  const ContactCandidate nearest = coal_candidate(piece, where, object, object_where, p, o);
  if (!(nearest.gap_m <= reach_m)) {
    out.push_back(nearest);
    return;
  }
  const coal::Transform3s transform = transform_of(where);
  const coal::Transform3s object_transform = transform_of(object_where);
  // coal 3.0's patch of a cylinder is one point when the cylinder's supporting disc is the
  // second shape's and the normal points away from it: the pair asked both ways
  coal::ContactPatchResult patches;
  bool first = true;
  if (!face_patch(piece.geometry.get(), transform, object.geometry.get(), object_transform,
                  reach_m, patches)) {
    first = false;
    if (!face_patch(object.geometry.get(), object_transform, piece.geometry.get(), transform,
                    reach_m, patches)) {
      out.push_back(nearest);
      return;
    }
  }
  const coal::ContactPatch& patch = patches.getContactPatch(0);
  // coal's normal points from the first shape to the second; ours out of the object
  const Vec3 normal = first ? Vec3(-patch.getNormal()) : Vec3(patch.getNormal());
  for (std::size_t k = 0; k < patch.size(); ++k) {
    const Vec3 on_piece = first ? patch.getPointShape1(k) : patch.getPointShape2(k);
    out.push_back({p, o, kPatchCorner - static_cast<int>(k), on_piece, normal,
                   patch.penetration_depth});
  }
}

// C = (t1, t2, n) with n its third column (contact_frame of contacts.py).
Eigen::Matrix3d contact_frame(const Vec3& normal) {
  const Vec3 helper = std::abs(normal.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 t1 = helper.cross(normal).normalized();
  Eigen::Matrix3d out;
  out << t1, normal.cross(t1), normal;
  return out;
}

// J_x (3 x 6): the world velocity of the material point at x for the LOCAL twist.
Eigen::Matrix<double, 3, 6> point_jacobian(const pinocchio::SE3& body, const Vec3& x) {
  Eigen::Matrix<double, 3, 6> out;
  out.leftCols<3>() = body.rotation();
  out.rightCols<3>() = -pinocchio::skew(Vec3(x - body.translation())) * body.rotation();
  return out;
}

void contact_candidates(const Data& data, const std::vector<ContactShape>& pieces,
                        const std::vector<ContactShape>& objects, double reach_m,
                        std::vector<ContactCandidate>& out) {
  out.clear();
  Placements where(pieces.size()), object_where(objects.size());
  for (std::size_t p = 0; p < pieces.size(); ++p) where[p] = placement_of(data, pieces[p]);
  for (std::size_t o = 0; o < objects.size(); ++o) object_where[o] = placement_of(data, objects[o]);
  // the broad phase of touch.py's Bounds.near with every piece's sphere grown by the reach:
  // planes first, then the others, each in (piece, object) order
  for (const bool planes : {true, false}) {
    for (std::size_t p = 0; p < pieces.size(); ++p) {
      const Vec3& center = where[p].translation();
      const double radius = pieces[p].bound_radius_m + reach_m;
      for (std::size_t o = 0; o < objects.size(); ++o) {
        const auto& object = objects[o];
        if (object.is_plane() != planes) continue;
        const auto& at = object_where[o];
        const int pi = static_cast<int>(p), oi = static_cast<int>(o);
        if (planes) {
          const Vec3 normal = at.rotation().col(2);
          if ((center - at.translation()).dot(normal) >= radius) continue;
          if (pieces[p].has_corners()) {
            plane_points(pieces[p], where[p], normal, at.translation(), pi, oi, out);
            continue;
          }
        } else if ((center - at.translation()).norm() >= radius + object.bound_radius_m) {
          continue;
        }
        patch_candidates(pieces[p], where[p], object, at, pi, oi, reach_m, out);
      }
    }
  }
}

int ObjectContactStep::select(const WorldContactModel& world, const FrictionMemory& memory,
                              const Data& data, const Vec6& speed, double h) {
  const pinocchio::SE3& body = data.oMi[1];
  double extent = 0.0;
  for (const auto& piece : world.pieces) {
    extent = std::max(extent, piece.bound_radius_m + piece.placement_in_joint.translation().norm());
  }
  const double reach = h * (speed.head<3>().sum() + speed.tail<3>().sum() * extent) + margin;
  contact_candidates(data, world.pieces, world.objects, reach, candidates_);
  selected_.clear();
  mu_.clear();
  const int n_objects = static_cast<int>(world.objects.size());
  for (const auto& candidate : candidates_) {
    const Eigen::Matrix<double, 1, 6> rate =
        candidate.normal.transpose() * point_jacobian(body, candidate.point);
    if (candidate.gap_m > h * rate.cwiseAbs().dot(speed.transpose()) + margin) continue;
    selected_.push_back(candidate);
    const auto& object = world.objects[static_cast<std::size_t>(candidate.obj)];
    const bool sliding = memory.slipping.count(candidate.piece * n_objects + candidate.obj) > 0;
    mu_.push_back(sliding ? object.friction_kinetic : object.friction_static);
  }
  const auto m = static_cast<Eigen::Index>(selected_.size());
  jacobian_.resize(3 * m, 6);
  drift_.resize(3 * m);
  frames_.resize(selected_.size());
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto& contact = selected_[static_cast<std::size_t>(i)];
    frames_[static_cast<std::size_t>(i)] = contact_frame(contact.normal);
    jacobian_.middleRows<3>(3 * i) =
        frames_[static_cast<std::size_t>(i)].transpose() * point_jacobian(body, contact.point);
    const double gap = contact.gap_m;
    drift_.segment<3>(3 * i) << 0.0, 0.0, (gap >= 0.0 ? gap : correction * gap) / h;
  }
  return static_cast<int>(m);
}

void coulomb_gauss_seidel(const Eigen::MatrixXd& delassus, const Eigen::VectorXd& g,
                          const std::vector<Eigen::Index>& cone_rows,
                          const std::vector<double>& mu,
                          const std::vector<Eigen::Index>& unilateral, Eigen::VectorXd& impulse,
                          const char* what, StalledSolves& stalled,
                          const std::vector<BoxRow>& boxes) {
  Eigen::VectorXd sigma = g + delassus * impulse;  // G lambda + g, kept up to date
  double last_change = 0.0;
  const double acceptable =
      std::max(kAcceptableResidual, kAcceptableRelative * g.cwiseAbs().maxCoeff());
  double checked = std::numeric_limits<double>::infinity();  // the last check's residual
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    double change = 0.0;
    for (const Eigen::Index j : unilateral) {  // lambda_j >= 0 _|_ sigma_j >= 0
      const double before = impulse[j];
      const double after = std::max(0.0, before - sigma[j] / delassus(j, j));
      sigma += delassus.col(j) * (after - before);
      impulse[j] = after;
      change = std::max(change, std::abs(delassus(j, j) * (after - before)));
    }
    for (const BoxRow& box : boxes) {  // |lambda_j| <= bound: stick inside, slip at it
      const Eigen::Index j = box.row;
      const double before = impulse[j];
      const double after = std::clamp(before - sigma[j] / delassus(j, j), -box.bound, box.bound);
      sigma += delassus.col(j) * (after - before);
      impulse[j] = after;
      change = std::max(change, std::abs(delassus(j, j) * (after - before)));
    }
    for (std::size_t c = 0; c < cone_rows.size(); ++c) {
      const Eigen::Index t = cone_rows[c], n = t + 2;
      const Eigen::Vector3d before = impulse.segment<3>(t);
      const double normal = std::max(0.0, before[2] - sigma[n] / delassus(n, n));
      sigma += delassus.col(n) * (normal - before[2]);
      impulse[n] = normal;
      const Eigen::Matrix2d g_tt = delassus.block<2, 2>(t, t);
      const double mean = 0.5 * g_tt.trace();
      const double spread = std::sqrt(0.25 * std::pow(g_tt(0, 0) - g_tt(1, 1), 2) +
                                      g_tt(0, 1) * g_tt(0, 1));
      Eigen::Vector2d tangential = before.head<2>() - sigma.segment<2>(t) / (mean + spread);
      const double limit = mu[c] * normal;
      if (tangential.norm() > limit) tangential *= limit / tangential.norm();
      sigma += delassus.middleCols<2>(t) * (tangential - before.head<2>());
      impulse.segment<2>(t) = tangential;
      const Eigen::Vector3d step = impulse.segment<3>(t) - before;
      change = std::max(change, (delassus.block<3, 3>(t, t) * step).cwiseAbs().maxCoeff());
    }
    last_change = change;
    if (change <= kTolerance) return;
    if ((sweep + 1) % kStallCheck == 0) {
      // stalled: no better than half the residual kStallCheck sweeps ago (a converging
      // solve gains orders of magnitude over as many), and acceptable
      const double residual =
          coulomb_residual(delassus, g, cone_rows, mu, unilateral, impulse, boxes);
      if (sweep + 1 >= kFirstStallCheck && residual <= acceptable &&
          residual > kStallRatio * checked) {
        if (residual > kConverged) stalled.add(residual);
        return;
      }
      checked = residual;
    }
  }
  const double residual = coulomb_residual(delassus, g, cone_rows, mu, unilateral, impulse, boxes);
  if (residual <= acceptable) {  // stalled (non-associated law, singular G), small enough
    if (residual > kConverged) stalled.add(residual);
    return;
  }
  char numbers[160];
  std::snprintf(numbers, sizeof numbers,
                " (a change of %.3g m/s at the last, residual %.3g m/s, above the %.3g m/s a "
                "stalled solve may keep)",
                last_change, residual, acceptable);
  throw SimulationFailure(std::string(what) + ": the Gauss-Seidel sweeps did not settle in " +
                          std::to_string(kMaxSweeps) + numbers);
}

double coulomb_residual(const Eigen::MatrixXd& delassus, const Eigen::VectorXd& g,
                        const std::vector<Eigen::Index>& cone_rows, const std::vector<double>& mu,
                        const std::vector<Eigen::Index>& unilateral,
                        const Eigen::VectorXd& impulse, const std::vector<BoxRow>& boxes) {
  const Eigen::VectorXd sigma = g + delassus * impulse;
  double out = 0.0;
  auto normal_row = [&](Eigen::Index j) {
    out = std::max({out, -std::min(sigma[j], 0.0),
                    std::min(std::max(sigma[j], 0.0), impulse[j] * delassus(j, j))});
  };
  for (const Eigen::Index j : unilateral) normal_row(j);
  for (const BoxRow& box : boxes) {
    const double lambda = impulse[box.row], rate = sigma[box.row];
    const bool at_bound = std::abs(lambda) >= box.bound * (1.0 - 1.0e-9) && box.bound > 0.0;
    // at its bound it may only slip against the impulse (rate lambda <= 0)
    out = std::max(out, at_bound ? std::max(rate * (lambda > 0.0 ? 1.0 : -1.0), 0.0)
                                 : (box.bound > 0.0 ? std::abs(rate) : 0.0));
  }
  for (std::size_t c = 0; c < cone_rows.size(); ++c) {
    const Eigen::Index t = cone_rows[c], n = t + 2;
    normal_row(n);
    if (impulse[n] <= 0.0) continue;
    const Eigen::Vector2d force = impulse.segment<2>(t), slip = sigma.segment<2>(t);
    if (force.norm() < mu[c] * impulse[n] * (1.0 - 1.0e-9)) {
      out = std::max(out, slip.norm());  // inside the cone: sticking
    } else {
      out = std::max(out, (slip + slip.norm() * force / std::max(force.norm(), 1e-300)).norm());
    }
  }
  return out;
}

void ObjectContactStep::solve(const Mat6& mass, const Vec6& v_free, Vec6& v) {
  const Eigen::LLT<Mat6> llt(mass);
  if (llt.info() != Eigen::Success) {
    throw SimulationFailure("object contacts: the mass matrix is not positive definite");
  }
  minv_jt_ = llt.solve(jacobian_.transpose());
  delassus_ = jacobian_ * minv_jt_;
  const Eigen::VectorXd g = jacobian_ * v_free + drift_;
  const auto m = static_cast<Eigen::Index>(selected_.size());
  impulse_ = Eigen::VectorXd::Zero(3 * m);
  cone_rows_.resize(selected_.size());
  for (Eigen::Index i = 0; i < m; ++i) cone_rows_[static_cast<std::size_t>(i)] = 3 * i;
  coulomb_gauss_seidel(delassus_, g, cone_rows_, mu_, {}, impulse_, "object contacts", stalled);
  v = v_free + minv_jt_ * impulse_;
}

void ObjectContactStep::forces(const Vec6& v, const Eigen::VectorXd& impulse, double h,
                               ContactForces& out) const {
  Touch& touch = out.touch;
  touch.clear();
  const std::size_t m = selected_.size();
  out.force_world_N.resize(m);
  out.normal_N.resize(static_cast<Eigen::Index>(m));
  out.sticking.resize(m);
  out.stretch_m.assign(m, Vec3::Zero());
  out.material_m.assign(m, Vec3::Zero());
  const Eigen::VectorXd rate = jacobian_ * v;
  for (std::size_t k = 0; k < m; ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    const auto& contact = selected_[k];
    touch.piece.push_back(contact.piece);
    touch.obj.push_back(contact.obj);
    touch.corner.push_back(contact.corner);
    touch.point_world_m.push_back(contact.point);
    touch.normal_world.push_back(contact.normal);
    touch.depth_m.push_back(std::max(-contact.gap_m, 0.0));
    touch.velocity_world_m_s.push_back(frames_[k] * rate.segment<3>(3 * i));
    out.force_world_N[k] = frames_[k] * impulse.segment<3>(3 * i) / h;
    out.normal_N[i] = impulse[3 * i + 2] / h;
    out.sticking[k] = rate.segment<2>(3 * i).norm() <= kSlipSpeed_m_s;
  }
}

bool ObjectContactStep::constrain(const WorldContactModel& world, const FrictionMemory& memory,
                                  const Data& data, const Mat6& mass, Vec6& v, double h,
                                  const Vec6& least_speed, ContactForces& out) {
  if (!(std::isfinite(h) && h > 0.0)) throw InputError("object contacts: the period must be > 0");
  const Vec6 v_free = v;
  Vec6 speed = v_free.cwiseAbs().cwiseMax(least_speed.cwiseAbs());
  int rows = select(world, memory, data, speed, h);
  if (rows > 0) {
    bool settled = false;
    for (int round = 0; round < kWideningRounds && !settled; ++round) {
      solve(mass, v_free, v);
      speed = speed.cwiseMax(v.cwiseAbs());
      // the same count: the same contacts (the selection only grows with the speed), so
      // the rows selected again are the ones solved
      const int wider = select(world, memory, data, speed, h);
      settled = wider == rows;
      rows = wider;
    }
    if (!settled) solve(mass, v_free, v);
  }
  if (rows == 0) impulse_.resize(0);
  forces(v, impulse_, h, out);
  return rows > 0;
}

Eigen::Matrix<double, 7, 1> free_body_configuration(const Eigen::Ref<const Eigen::VectorXd>& q,
                                                    const Vec6& v, double h) {
  const Eigen::Quaterniond start(q[6], q[3], q[4], q[5]);
  const Eigen::Matrix3d rotation = start.normalized().toRotationMatrix();
  const Eigen::Quaterniond turned(
      Eigen::Matrix3d(rotation * pinocchio::exp3(Vec3(h * v.tail<3>()))));
  Eigen::Matrix<double, 7, 1> out;
  out.head<3>() = q.head<3>() + h * rotation * v.head<3>();
  const Eigen::Quaterniond unit = turned.normalized();
  out.tail<4>() << unit.x(), unit.y(), unit.z(), unit.w();
  return out;
}

}  // namespace uvms

#include "moving_constraints.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Cholesky>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/spatial/explog.hpp>

#include "pinocchio_kinematics.hpp"
#include "world_touch.hpp"

namespace uvms {

Eigen::MatrixXd CoupledConstraintStep::side_twist_jacobian(const SystemAtStart& at, int side,
                                                           const ContactShape& piece,
                                                           const Vec3& x) const {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(6, nv_);
  if (side < 0) {
    Eigen::Matrix<double, 6, Eigen::Dynamic> joint(6, nv_robot_);
    joint.setZero();
    pinlib::get_joint_jacobian(*at.robot, *at.robot_data,
                                static_cast<pinocchio::JointIndex>(piece.joint_id),
                                pinocchio::LOCAL_WORLD_ALIGNED, joint);
    const Vec3 offset = x - at.robot_data->oMi[static_cast<std::size_t>(piece.joint_id)].translation();
    out.topLeftCorner(3, nv_robot_) = joint.topRows<3>() - pinocchio::skew(offset) * joint.bottomRows<3>();
    out.bottomLeftCorner(3, nv_robot_) = joint.bottomRows<3>();
  } else if (static_cast<std::size_t>(side) < at.objects.size()) {
    const auto k = static_cast<std::size_t>(side);
    const pinocchio::SE3& body = at.objects[k]->oMi[1];
    out.block<3, 6>(0, nv_robot_ + 6 * side) = point_jacobian(body, x);
    out.block<3, 3>(3, nv_robot_ + 6 * side + 3) = body.rotation();
  } else if (piece.joint_id > 0) {  // a fixture's link; its root link (joint 0) is fixed
    const FixtureAtStart& fixture = at.fixtures[static_cast<std::size_t>(side) - at.objects.size()];
    const auto n = static_cast<Eigen::Index>(fixture.model->nv);
    Eigen::Matrix<double, 6, Eigen::Dynamic> joint(6, n);
    joint.setZero();
    pinlib::get_joint_jacobian(*fixture.model, *fixture.data,
                                static_cast<pinocchio::JointIndex>(piece.joint_id),
                                pinocchio::LOCAL_WORLD_ALIGNED, joint);
    const Vec3 offset =
        x - fixture.data->oMi[static_cast<std::size_t>(piece.joint_id)].translation();
    out.block(0, fixture.offset, 3, n) = joint.topRows<3>() - pinocchio::skew(offset) * joint.bottomRows<3>();
    out.block(3, fixture.offset, 3, n) = joint.bottomRows<3>();
  }
  return out;
}

const Data& CoupledConstraintStep::side_data(const SystemAtStart& at, int side) const {
  if (side < 0) return *at.robot_data;
  const auto k = static_cast<std::size_t>(side);
  return k < at.objects.size() ? *at.objects[k] : *at.fixtures[k - at.objects.size()].data;
}

bool CoupledConstraintStep::free_object(const SystemAtStart& at, int side) {
  return side >= 0 && static_cast<std::size_t>(side) < at.objects.size();
}

Eigen::MatrixXd CoupledConstraintStep::side_jacobian(const SystemAtStart& at, int side,
                                                     const ContactShape& piece,
                                                     const Vec3& x) const {
  return side_twist_jacobian(at, side, piece, x).topRows(3);
}

double CoupledConstraintStep::piece_speed(const SystemAtStart& at, int side,
                                          const ContactShape& piece,
                                          const Eigen::VectorXd& speed) const {
  const Data& data = side_data(at, side);
  const Vec3 centre = placement_of(data, piece).translation();
  const Eigen::MatrixXd twist = side_twist_jacobian(at, side, piece, centre);
  const auto linear = twist.topRows(3);
  const auto angular = twist.bottomRows(3);
  return (linear.cwiseAbs() * speed).norm() +
         (angular.cwiseAbs() * speed).norm() * piece.bound_radius_m;
}

void CoupledConstraintStep::add_pair_rows(const SystemAtStart& at, const Eigen::VectorXd& speed,
                                          double h) {
  const auto& sets = *at.sets;
  // each piece's speed bound, computed once a selection (-1: not yet)
  std::vector<double> speed_a, speed_b;
  const auto cached = [&](std::vector<double>& held, int index, int side,
                          const ContactShape& piece) {
    double& value = held[static_cast<std::size_t>(index)];
    if (value < 0.0) value = piece_speed(at, side, piece, speed);
    return value;
  };
  for (std::size_t s = 0; s < sets.size(); ++s) {
    const PairSet& set = sets[s];
    const Data& data_a = side_data(at, set.a);
    const Data& data_b = side_data(at, set.b);
    speed_a.assign(set.pairs.pieces_a.size(), -1.0);
    speed_b.assign(set.pairs.pieces_b.size(), -1.0);
    for (std::size_t k = 0; k < set.pairs.pairs.size(); ++k) {
      const auto [ia, ib] = set.pairs.pairs[k];
      const ContactShape& piece_a = set.pairs.pieces_a[static_cast<std::size_t>(ia)];
      const ContactShape& piece_b = set.pairs.pieces_b[static_cast<std::size_t>(ib)];
      const pinocchio::SE3 where_a = placement_of(data_a, piece_a);
      const pinocchio::SE3 where_b = placement_of(data_b, piece_b);
      const double apart = (where_a.translation() - where_b.translation()).norm();
      const double closing =
          cached(speed_a, ia, set.a, piece_a) + cached(speed_b, ib, set.b, piece_b);
      if (apart >= piece_a.bound_radius_m + piece_b.bound_radius_m + h * closing + margin) {
        continue;
      }
      // the pair's candidates (moving_contacts.py's _candidates): between two free objects a
      // contact patch's vertices (a crate resting on a crate), else coal's one point; each
      // solved when its gap can close within the period
      patch_.clear();
      if (free_object(at, set.a) && free_object(at, set.b)) {
        patch_candidates(piece_a, where_a, piece_b, where_b, ia, ib, h * closing + margin, patch_);
      } else {
        patch_.push_back(coal_candidate(piece_a, where_a, piece_b, where_b, ia, ib));
      }
      for (const ContactCandidate& point : patch_) {
        const Eigen::MatrixXd relative = side_jacobian(at, set.a, piece_a, point.point) -
                                         side_jacobian(at, set.b, piece_b, point.point);
        const Eigen::RowVectorXd normal_rate = point.normal.transpose() * relative;
        if (point.gap_m > h * normal_rate.cwiseAbs().dot(speed) + margin) continue;
        const Eigen::Matrix3d frame = contact_frame(point.normal);
        const Eigen::MatrixXd rows = frame.transpose() * relative;
        cone_rows_.push_back(static_cast<Eigen::Index>(rows_.size()));
        for (int r = 0; r < 3; ++r) rows_.push_back(rows.row(r));
        const double gap = point.gap_m;
        drift_.insert(drift_.end(), {0.0, 0.0, (gap >= 0.0 ? gap : correction * gap) / h});
        const bool sliding = set.memory.slipping.count(static_cast<int>(k)) > 0;
        mu_.push_back(sliding ? set.pairs.friction_kinetic[k] : set.pairs.friction_static[k]);
        pair_rows_.push_back({static_cast<int>(s), static_cast<int>(k), point, frame});
      }
    }
  }
}

Eigen::Index CoupledConstraintStep::add_coordinate_row(Eigen::Index iv, double sign,
                                                      double drift) {
  Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(nv_);
  row[iv] = sign;
  rows_.push_back(row);
  drift_.push_back(drift);
  return static_cast<Eigen::Index>(rows_.size()) - 1;
}

void CoupledConstraintStep::add_attachment_rows(const SystemAtStart& at, double h) {
  for (const AttachmentAtStart& held : at.attachments) {
    const auto k = static_cast<std::size_t>(held.object);
    const pinocchio::SE3& object = at.objects[k]->oMi[1];
    const pinocchio::SE3 target =
        at.robot_data->oMi[static_cast<std::size_t>(held.link_joint)] * held.placement;
    // the rows in the target's frame c1: -(its link's chain) + (the object's body twist)
    Eigen::Matrix<double, 6, Eigen::Dynamic> link(6, nv_robot_);
    link.setZero();
    pinlib::get_joint_jacobian(*at.robot, *at.robot_data,
                                static_cast<pinocchio::JointIndex>(held.link_joint),
                                pinocchio::WORLD, link);
    const Eigen::Matrix<double, 6, 6> to_target = target.toActionMatrixInverse();
    Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(6, nv_);
    rows.leftCols(nv_robot_) = -to_target * link;
    // the free-flyer's WORLD Jacobian is Ad(oM_O) on its LOCAL body velocity
    rows.middleCols<6>(nv_robot_ + 6 * static_cast<Eigen::Index>(k)) =
        to_target * object.toActionMatrix();
    const Vec6 error = pinocchio::log6(target.actInv(object)).toVector();
    for (int r = 0; r < 6; ++r) {
      boxes_.push_back({static_cast<Eigen::Index>(rows_.size()),
                        std::numeric_limits<double>::infinity()});
      rows_.push_back(rows.row(r));
      drift_.push_back(correction * error[r] / h);
    }
  }
}

void CoupledConstraintStep::add_fixture_rows(const SystemAtStart& at, const Eigen::VectorXd& speed,
                                             double h) {
  // the limits (fixtures.constraints' JointLimits: lower rows first, then upper)
  for (const bool lower : {true, false}) {
    for (const FixtureAtStart& fixture : at.fixtures) {
      for (Eigen::Index j = 0; j < fixture.q0.size(); ++j) {
        const double bound = lower ? (*fixture.lower)[j] : (*fixture.upper)[j];
        if (!std::isfinite(bound)) continue;
        const Eigen::Index iv = fixture.offset + j;
        const double gap = lower ? fixture.q0[j] - bound : bound - fixture.q0[j];
        if (gap > h * speed[iv] + margin) continue;
        unilateral_.push_back(add_coordinate_row(iv, lower ? 1.0 : -1.0, phi(gap) / h));
      }
    }
  }
  // their Coulomb friction: a row per joint with c > 0, |lambda| <= c h, always
  for (const FixtureAtStart& fixture : at.fixtures) {
    for (Eigen::Index j = 0; j < fixture.q0.size(); ++j) {
      const double c = (*fixture.coulomb)[j];
      if (!(c > 0.0)) continue;
      boxes_.push_back({add_coordinate_row(fixture.offset + j, 1.0, 0.0), c * h});
    }
  }
}

int CoupledConstraintStep::select(const SystemAtStart& at, const Eigen::VectorXd& speed,
                                  double h) {
  rows_.clear();
  drift_.clear();
  mu_.clear();
  unilateral_.clear();
  boxes_.clear();
  cone_rows_.clear();
  pair_rows_.clear();
  if (at.limits != nullptr) {  // lower rows first, then upper (joint_limits.py's order)
    const auto& limits = *at.limits;
    for (const bool lower : {true, false}) {
      for (std::size_t i = 0; i < limits.q_index.size(); ++i) {
        const auto k = static_cast<Eigen::Index>(i);
        const int iq = limits.q_index[i], iv = limits.v_index[i];
        const double gap = lower ? at.q0_robot[iq] - limits.lower_rad[k]
                                 : limits.upper_rad[k] - at.q0_robot[iq];
        if (gap > h * speed[iv] + limits.margin) continue;
        unilateral_.push_back(add_coordinate_row(iv, lower ? 1.0 : -1.0, phi(gap) / h));
      }
    }
  }
  // the robot's joints' Coulomb friction: a box row per joint with c > 0, always
  for (Eigen::Index iv = 0; iv < at.joint_coulomb.size(); ++iv) {
    const double c = at.joint_coulomb[iv];
    if (!(c > 0.0)) continue;
    boxes_.push_back({add_coordinate_row(iv, 1.0, 0.0), c * h});
  }
  for (std::size_t i = 0; i < at.objects.size(); ++i) {
    object_rows_[i] = static_cast<Eigen::Index>(rows_.size());
    if (at.object_worlds[i] == nullptr) continue;
    const Eigen::Index offset = nv_robot_ + 6 * static_cast<Eigen::Index>(i);
    ObjectContactStep& step = object_steps_[i];
    const Vec6 own = speed.segment<6>(offset);
    const int n = step.select(*at.object_worlds[i], *at.object_memory[i], *at.objects[i], own, h);
    for (int c = 0; c < n; ++c) {
      cone_rows_.push_back(static_cast<Eigen::Index>(rows_.size()));
      for (int r = 0; r < 3; ++r) {
        Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(nv_);
        row.segment<6>(offset) = step.jacobian().row(3 * c + r);
        rows_.push_back(row);
        drift_.push_back(step.drift()[3 * c + r]);
      }
      mu_.push_back(step.mu()[static_cast<std::size_t>(c)]);
    }
  }
  first_pair_row_ = static_cast<Eigen::Index>(rows_.size());
  if (at.pair_rows) add_pair_rows(at, speed, h);
  add_attachment_rows(at, h);
  if (at.fixture_rows) add_fixture_rows(at, speed, h);
  const auto m = static_cast<Eigen::Index>(rows_.size());
  jacobian_.resize(m, nv_);
  for (Eigen::Index r = 0; r < m; ++r) jacobian_.row(r) = rows_[static_cast<std::size_t>(r)];
  // a body acted on: some row has a non-zero column of its coordinates (period.py's _end)
  acting_.assign(bodies_.size(), 0);
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    const auto [first, n] = bodies_[k];
    acting_[k] = m > 0 && n > 0 && (jacobian_.middleCols(first, n).array() != 0.0).any();
  }
  if (at.joint_coulomb.size() > 0) acting_[0] = 1;
  return static_cast<int>(m);
}

void CoupledConstraintStep::solve(const std::vector<Eigen::MatrixXd>& masses,
                                  const Eigen::VectorXd& v_free, Eigen::VectorXd& v) {
  // M^-1 J^T block by block: the bodies meet only through the rows
  minv_jt_.resize(nv_, jacobian_.rows());
  Eigen::Index offset = 0;
  for (const auto& mass : masses) {
    const Eigen::Index n = mass.rows();
    const Eigen::LLT<Eigen::MatrixXd> llt(mass);
    if (llt.info() != Eigen::Success) {
      throw SimulationFailure("coupled constraints: a mass matrix is not positive definite");
    }
    minv_jt_.middleRows(offset, n) = llt.solve(jacobian_.middleCols(offset, n).transpose());
    offset += n;
  }
  delassus_ = jacobian_ * minv_jt_;
  const Eigen::VectorXd g =
      jacobian_ * v_free + Eigen::Map<const Eigen::VectorXd>(drift_.data(), jacobian_.rows());
  impulse_ = Eigen::VectorXd::Zero(jacobian_.rows());
  coulomb_gauss_seidel(delassus_, g, cone_rows_, mu_, unilateral_, impulse_,
                       "coupled constraints", stalled, boxes_);
  v = v_free + minv_jt_ * impulse_;
}

void CoupledConstraintStep::forces(const SystemAtStart& at, const Eigen::VectorXd& v, double h) {
  object_found_.resize(at.objects.size());
  for (std::size_t i = 0; i < at.objects.size(); ++i) {
    object_found_[i] = ContactForces{};
    if (at.object_worlds[i] == nullptr) continue;
    const Eigen::Index offset = nv_robot_ + 6 * static_cast<Eigen::Index>(i);
    const Eigen::Index first = object_rows_[i];
    const Eigen::Index n = object_steps_[i].jacobian().rows();
    const Vec6 own = v.segment<6>(offset);
    object_steps_[i].forces(own, impulse_.segment(first, n), h, object_found_[i]);
  }
  const auto& sets = *at.sets;
  pair_found_.assign(sets.size(), PairContacts{});
  const Eigen::VectorXd rate = jacobian_ * v;
  for (std::size_t c = 0; c < pair_rows_.size(); ++c) {
    const PairRow& row = pair_rows_[c];
    const Eigen::Index r = first_pair_row_ + 3 * static_cast<Eigen::Index>(c);
    PairContacts& out = pair_found_[static_cast<std::size_t>(row.set)];
    ContactForces& found = out.forces;
    found.touch.piece.push_back(row.point.piece);
    found.touch.obj.push_back(row.point.obj);
    found.touch.corner.push_back(-1);
    found.touch.point_world_m.push_back(row.point.point);
    found.touch.normal_world.push_back(row.point.normal);
    found.touch.depth_m.push_back(std::max(-row.point.gap_m, 0.0));
    found.touch.velocity_world_m_s.push_back(row.frame * rate.segment<3>(r));
    found.force_world_N.push_back(row.frame * impulse_.segment<3>(r) / h);
    const Eigen::Index n = found.normal_N.size();
    found.normal_N.conservativeResize(n + 1);
    found.normal_N[n] = impulse_[r + 2] / h;
    found.sticking.push_back(rate.segment<2>(r).norm() <= kSlipSpeed_m_s);
    found.stretch_m.push_back(Vec3::Zero());
    found.material_m.push_back(Vec3::Zero());
    out.pair.push_back(row.pair);
  }
}

bool CoupledConstraintStep::constrain(const SystemAtStart& at,
                                      const std::vector<Eigen::MatrixXd>& masses,
                                      Eigen::VectorXd& v, double h,
                                      const Eigen::VectorXd& least_speed) {
  if (!(std::isfinite(h) && h > 0.0)) {
    throw InputError("coupled constraints: the period must be > 0");
  }
  nv_robot_ = static_cast<Eigen::Index>(at.robot->nv);
  nv_ = v.size();
  bodies_.assign(1, {0, nv_robot_});
  for (std::size_t i = 0; i < at.objects.size(); ++i) {
    bodies_.emplace_back(nv_robot_ + 6 * static_cast<Eigen::Index>(i), 6);
  }
  Eigen::Index expected = nv_robot_ + 6 * static_cast<Eigen::Index>(at.objects.size());
  for (const FixtureAtStart& fixture : at.fixtures) {
    const auto n = static_cast<Eigen::Index>(fixture.model->nv);
    if (fixture.offset != expected || fixture.q0.size() != n || fixture.lower->size() != n ||
        fixture.upper->size() != n || fixture.coulomb->size() != n) {
      throw InputError("coupled constraints: a fixture's coordinates, limits and friction");
    }
    bodies_.emplace_back(expected, n);
    expected += n;
  }
  if (nv_ != expected || least_speed.size() != nv_ || masses.size() != bodies_.size() ||
      (at.joint_coulomb.size() != 0 && at.joint_coulomb.size() != nv_robot_)) {
    throw InputError(
        "coupled constraints: the robot's, each object's and each fixture's velocity and mass");
  }
  for (const AttachmentAtStart& held : at.attachments) {
    if (held.link_joint < 1 || held.link_joint >= at.robot->njoints || held.object < 0 ||
        static_cast<std::size_t>(held.object) >= at.objects.size()) {
      throw InputError("coupled constraints: an attachment's link joint (" +
                       std::to_string(held.link_joint) + ") or object (" +
                       std::to_string(held.object) + ") is not the system's");
    }
  }
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    if (masses[k].rows() != bodies_[k].second || masses[k].cols() != bodies_[k].second) {
      throw InputError("coupled constraints: body " + std::to_string(k) + "'s mass matrix is " +
                       std::to_string(masses[k].rows()) + " x " +
                       std::to_string(masses[k].cols()) + ", its velocity " +
                       std::to_string(bodies_[k].second));
    }
  }
  object_steps_.resize(at.objects.size());
  object_rows_.assign(at.objects.size(), 0);
  for (auto& step : object_steps_) {
    step.margin = margin;
    step.correction = correction;
  }
  pinlib::compute_joint_jacobians(*at.robot, *at.robot_data, at.q0_robot);
  for (const FixtureAtStart& fixture : at.fixtures) {
    pinlib::compute_joint_jacobians(*fixture.model, *fixture.data, fixture.q0);
  }
  const Eigen::VectorXd v_free = v;
  Eigen::VectorXd speed = v_free.cwiseAbs().cwiseMax(least_speed.cwiseAbs());
  int rows = select(at, speed, h);
  if (rows > 0) {
    bool settled = false;
    for (int round = 0; round < kWideningRounds && !settled; ++round) {
      solve(masses, v_free, v);
      speed = speed.cwiseMax(v.cwiseAbs());
      // the same count: the same rows (the selection only grows with the speed)
      const int wider = select(at, speed, h);
      settled = wider == rows;
      rows = wider;
    }
    if (!settled) solve(masses, v_free, v);
  } else {
    impulse_.resize(0);
  }
  forces(at, v, h);
  return rows > 0;
}

}  // namespace uvms

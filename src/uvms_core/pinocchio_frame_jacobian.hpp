// Pinocchio's computeFrameJacobian(model, data, q, frame, LOCAL_WORLD_ALIGNED, J) as the PPC's
// task calls it (law_force_task.cpp): the instance the `pin` wheel's libpinocchio_default
// holds, reached from a unit that never sees the template's definition.
//
// Why a unit of its own: pinocchio/algorithm/frames.hxx defines computeFrameJacobian `inline`
// beside its `extern template` declaration, and GCC instantiates an inline template wherever
// its definition is visible, the joint visitor over every joint type of the collection
// included: 28 s of compiler CPU in the unit that called it (44.5 s -> 16.8 s without the
// call). It then did not inline the result: the object called the library's symbol all the
// same. pinocchio_frame_jacobian.cpp declares the template without its definition and calls
// it, compiled alone (CMakeLists.txt: no unity group) in under a second; the call is the same
// symbol, so the Jacobian is the same, bit for bit.
#pragma once

#include <Eigen/Core>
#include <pinocchio/multibody/fwd.hpp>

namespace uvms {

// J (6 x nv) of frame `frame` at q, in LOCAL_WORLD_ALIGNED (the frame's origin, world axes);
// data's joint placements, oMf[frame] and joint Jacobians are updated as Pinocchio's call does.
void frame_jacobian_local_world_aligned(const pinocchio::Model& model, pinocchio::Data& data,
                                        const Eigen::VectorXd& q, pinocchio::FrameIndex frame,
                                        Eigen::Matrix<double, 6, Eigen::Dynamic>& jacobian);

}  // namespace uvms

#include "pinocchio_frame_jacobian.hpp"

// Only the declaration of Pinocchio's template (pinocchio/algorithm/frames.hpp, the same
// parameters and signature): its definition must stay out of this unit (see the header). A
// declaration that no longer matches the library's leaves an undefined symbol, which the
// import of the core reports.
namespace pinocchio {

template <typename Scalar, int Options, template <typename, int> class JointCollectionTpl,
          typename ConfigVectorType, typename Matrix6xLike>
void computeFrameJacobian(const ModelTpl<Scalar, Options, JointCollectionTpl>& model,
                          DataTpl<Scalar, Options, JointCollectionTpl>& data,
                          const Eigen::MatrixBase<ConfigVectorType>& q, const FrameIndex frameId,
                          const ReferenceFrame reference_frame,
                          const Eigen::MatrixBase<Matrix6xLike>& J);

}  // namespace pinocchio

namespace uvms {

void frame_jacobian_local_world_aligned(const pinocchio::Model& model, pinocchio::Data& data,
                                        const Eigen::VectorXd& q, pinocchio::FrameIndex frame,
                                        Eigen::Matrix<double, 6, Eigen::Dynamic>& jacobian) {
  pinocchio::computeFrameJacobian(model, data, q, frame, pinocchio::LOCAL_WORLD_ALIGNED,
                                  jacobian);
}

}  // namespace uvms

#include "cvg_bench/core/model/model_term.h"

#include <algorithm>
#include <cmath>

namespace cvg_bench {

std::string ModelTerm::parameterMeaning(const std::string& parameter) const {
  for (const CandidateExtension& c : candidates())
    if (c.parameter == parameter) return c.cause;
  return description();
}

void ModelTerm::averagedJacobian(const Eigen::Vector4d& q, const SlowContext& ctx,
                                 const Eigen::Ref<const Eigen::VectorXd>& z_term,
                                 Eigen::Matrix4d& jacobian) const {
  averagedJacobianNumerical(q, ctx, z_term, jacobian);
}

void ModelTerm::averagedJacobianNumerical(const Eigen::Vector4d& q, const SlowContext& ctx,
                                          const Eigen::Ref<const Eigen::VectorXd>& z_term,
                                          Eigen::Matrix4d& jacobian) const {
  // Central differences with a step ~ eps^(1/3) relative to the state's scale: error ~ 1e-10.
  const double step = 6e-6 * std::max(q.cwiseAbs().maxCoeff(), 1e-3);
  Eigen::MatrixXd cols(4, z_term.size());
  for (int c = 0; c < 4; ++c) {
    Eigen::Vector4d qq = q;
    qq[c] = q[c] + step;
    averagedColumns(qq, ctx, cols);
    const Eigen::Vector4d up = cols * z_term;
    qq[c] = q[c] - step;
    averagedColumns(qq, ctx, cols);
    jacobian.col(c) = (up - cols * z_term) / (2.0 * step);
  }
}

}  // namespace cvg_bench

#include "cvg_bench/core/estimate/output_error_free_decay.h"

#include <ceres/dynamic_numeric_diff_cost_function.h>

namespace cvg_bench {

bool integrateSlowTrajectory(const ResonatorModel& model, const Eigen::VectorXd& z,
                             const Eigen::Vector4d& q0, const std::vector<double>& t_s,
                             int substeps, std::vector<Eigen::Vector4d>* trajectory) {
  trajectory->resize(t_s.size());
  if (t_s.empty()) return true;
  const double t0 = t_s.front();
  Eigen::Vector4d q = q0;
  (*trajectory)[0] = q;
  auto rate = [&](double t, const Eigen::Vector4d& x) {
    return model.slowDerivative(x, SlowContext{t - t0, 0.0}, z);
  };
  for (size_t i = 1; i < t_s.size(); ++i) {
    const double h = (t_s[i] - t_s[i - 1]) / substeps;
    double t = t_s[i - 1];
    for (int s = 0; s < substeps; ++s, t += h) {
      const Eigen::Vector4d k1 = rate(t, q);
      const Eigen::Vector4d k2 = rate(t + h / 2, q + h / 2 * k1);
      const Eigen::Vector4d k3 = rate(t + h / 2, q + h / 2 * k2);
      const Eigen::Vector4d k4 = rate(t + h, q + h * k3);
      q += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    if (!q.allFinite()) return false;
    (*trajectory)[i] = q;
  }
  return true;
}

FreeDecayOutputError::FreeDecayOutputError(const ResonatorModel& model, const SlowRecord& record,
                                           int substeps, const Eigen::VectorXd& z_scale,
                                           double q0_scale)
    : model_(model),
      record_(record),
      substeps_(substeps),
      z_scale_(z_scale.size() == 0 ? Eigen::VectorXd::Ones(model.numParameters()) : z_scale),
      q0_scale_(q0_scale) {}

bool FreeDecayOutputError::operator()(double const* const* parameters, double* residuals) const {
  const Eigen::VectorXd z = z_scale_.cwiseProduct(
      Eigen::Map<const Eigen::VectorXd>(parameters[0], model_.numParameters()));
  const Eigen::Vector4d q0 = q0_scale_ * Eigen::Map<const Eigen::Vector4d>(parameters[1]);
  thread_local std::vector<Eigen::Vector4d> trajectory;
  if (!integrateSlowTrajectory(model_, z, q0, record_.t_s, substeps_, &trajectory)) return false;
  for (size_t i = 0; i < record_.size(); ++i) {
    Eigen::Map<Eigen::Vector4d> r(residuals + 4 * i);
    r = trajectory[i] - record_.q[i];
  }
  return true;
}

namespace {

template <ceres::NumericDiffMethodType kMethod>
std::unique_ptr<ceres::CostFunction> makeCost(const ResonatorModel& model, const SlowRecord& record,
                                              int substeps, const Eigen::VectorXd& z_scale,
                                              double q0_scale) {
  auto* functor = new FreeDecayOutputError(model, record, substeps, z_scale, q0_scale);
  const int n_residuals = functor->numResiduals();
  auto cost =
      std::make_unique<ceres::DynamicNumericDiffCostFunction<FreeDecayOutputError, kMethod>>(
          functor);
  cost->AddParameterBlock(model.numParameters());
  cost->AddParameterBlock(4);
  cost->SetNumResiduals(n_residuals);
  return cost;
}

}  // namespace

std::unique_ptr<ceres::CostFunction> makeFreeDecayOutputErrorCost(
    const ResonatorModel& model, const SlowRecord& record, int substeps,
    NumericDerivative derivative, const Eigen::VectorXd& z_scale, double q0_scale) {
  if (derivative == NumericDerivative::kRidders)
    return makeCost<ceres::RIDDERS>(model, record, substeps, z_scale, q0_scale);
  return makeCost<ceres::CENTRAL>(model, record, substeps, z_scale, q0_scale);
}

}  // namespace cvg_bench

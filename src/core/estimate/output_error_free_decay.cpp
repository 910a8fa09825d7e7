#include "cvg_bench/core/estimate/output_error_free_decay.h"

#include <ceres/cost_function.h>
#include <ceres/dynamic_numeric_diff_cost_function.h>

#include <cmath>

#include "cvg_bench/core/estimate/least_squares_solver.h"

namespace cvg_bench {

namespace {

constexpr int kMaxUnknowns = kMaxModelParameters + 4;
using Sensitivity = Eigen::Matrix<double, 4, Eigen::Dynamic, 0, 4, kMaxUnknowns>;
using Regressor = Eigen::Matrix<double, 4, Eigen::Dynamic, 0, 4, kMaxModelParameters>;

/// One RK4 stage of the trajectory and its sensitivity: k = q'(q) = D(q) z / 2 and
/// K = A(q) S + [D(q) / 2, 0] with A = slowJacobian (2.6).
void stage(const ResonatorModel& model, const Eigen::VectorXd& z, double t,
           const Eigen::Vector4d& q, const Sensitivity& s, Regressor* d, Eigen::Vector4d* k,
           Sensitivity* ks) {
  const SlowContext ctx{t, 0.0};
  model.regressor(q, ctx, *d);
  const int p = model.numParameters();
  *k = 0.5 * d->lazyProduct(z);
  const Eigen::Matrix4d a = model.slowJacobian(q, ctx, z);
  // Column by column: fixed-size 4 x 4 times 4-vector products (vectorized, no GEMM dispatch).
  for (Eigen::Index j = 0; j < s.cols(); ++j) ks->col(j).noalias() = a * s.col(j);
  ks->leftCols(p) += 0.5 * *d;
}

/// RK4 of the trajectory with its sensitivities; visit(i, q_i, S_i) at every sample.
template <typename Visit>
bool integrateWithSensitivities(const ResonatorModel& model, const Eigen::VectorXd& z,
                                const Eigen::Vector4d& q0, const std::vector<double>& t_s,
                                int substeps, Visit&& visit) {
  if (t_s.empty()) return true;
  const int p = model.numParameters();
  const int m = p + 4;
  const double t0 = t_s.front();
  Eigen::Vector4d q = q0;
  Sensitivity s = Sensitivity::Zero(4, m);
  s.rightCols(4).setIdentity();
  visit(size_t{0}, q, s);
  Regressor d(4, p);
  Eigen::Vector4d k1, k2, k3, k4;
  Sensitivity s1(4, m), s2(4, m), s3(4, m), s4(4, m), tmp(4, m);
  for (size_t i = 1; i < t_s.size(); ++i) {
    const double h = (t_s[i] - t_s[i - 1]) / substeps;
    double t = t_s[i - 1] - t0;
    for (int sub = 0; sub < substeps; ++sub, t += h) {
      stage(model, z, t, q, s, &d, &k1, &s1);
      tmp = s + h / 2 * s1;
      stage(model, z, t + h / 2, q + h / 2 * k1, tmp, &d, &k2, &s2);
      tmp = s + h / 2 * s2;
      stage(model, z, t + h / 2, q + h / 2 * k2, tmp, &d, &k3, &s3);
      tmp = s + h * s3;
      stage(model, z, t + h, q + h * k3, tmp, &d, &k4, &s4);
      q += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      s += h / 6 * (s1 + 2 * s2 + 2 * s3 + s4);
    }
    if (!q.allFinite() || !s.allFinite()) return false;
    visit(i, q, s);
  }
  return true;
}

/// RK4 of the trajectory alone; visit(i, q_i) at every sample, nothing stored.
template <typename Visit>
bool forEachTrajectoryPoint(const ResonatorModel& model, const Eigen::VectorXd& z,
                            const Eigen::Vector4d& q0, const std::vector<double>& t_s, int substeps,
                            Visit&& visit) {
  if (t_s.empty()) return true;
  const double t0 = t_s.front();
  Eigen::Vector4d q = q0;
  visit(size_t{0}, q);
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
    visit(i, q);
  }
  return true;
}

/// Output-error residuals with the analytic (forward-sensitivity) Jacobian over the scaled blocks
/// (x_z, x_q) of FreeDecayOutputError.
class FreeDecaySensitivityCost : public ceres::CostFunction {
 public:
  FreeDecaySensitivityCost(const ResonatorModel& model, const SlowRecord& record, int substeps,
                           const Eigen::VectorXd& z_scale, double q0_scale)
      : model_(model),
        record_(record),
        substeps_(substeps),
        z_scale_(z_scale.size() == 0 ? Eigen::VectorXd::Ones(model.numParameters()) : z_scale),
        q0_scale_(q0_scale) {
    set_num_residuals(4 * static_cast<int>(record.size()));
    mutable_parameter_block_sizes()->push_back(model.numParameters());
    mutable_parameter_block_sizes()->push_back(4);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int p = model_.numParameters();
    const Eigen::VectorXd z =
        z_scale_.cwiseProduct(Eigen::Map<const Eigen::VectorXd>(parameters[0], p));
    const Eigen::Vector4d q0 = q0_scale_ * Eigen::Map<const Eigen::Vector4d>(parameters[1]);
    if (jacobians == nullptr || (jacobians[0] == nullptr && jacobians[1] == nullptr))
      return FreeDecayOutputError(model_, record_, substeps_, z_scale_, q0_scale_)(parameters,
                                                                                   residuals);
    return integrateWithSensitivities(
        model_, z, q0, record_.t_s, substeps_,
        [&](size_t i, const Eigen::Vector4d& q, const Sensitivity& s) {
          Eigen::Map<Eigen::Vector4d>(residuals + 4 * i) = q - record_.q[i];
          if (jacobians[0] != nullptr) {
            Eigen::Map<Eigen::Matrix<double, 4, Eigen::Dynamic, Eigen::RowMajor>> jz(
                jacobians[0] + 4 * i * p, 4, p);
            jz = s.leftCols(p) * z_scale_.asDiagonal();
          }
          if (jacobians[1] != nullptr) {
            Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> jq(jacobians[1] + 16 * i);
            jq = q0_scale_ * s.rightCols(4);
          }
        });
  }

 private:
  const ResonatorModel& model_;
  const SlowRecord& record_;
  int substeps_;
  Eigen::VectorXd z_scale_;
  double q0_scale_;
};

/// The same output-error problem in square-root form for the solver: the stacked residuals
/// r (4 (N + 1)) and Jacobian J are folded block by block into the triangular factor of [J | r]
/// (IncrementalQr, never stored): [J | r] = Q [R c; 0 rho], so |r + J d|^2 = |c + R d|^2 + rho^2
/// for every step d. The k + 5 residuals [c; rho] with Jacobian [R; 0] give Levenberg-Marquardt
/// the same cost, gradient J'r, Gauss-Newton matrix J'J and Jacobi column scaling as the full
/// problem, in O((k + 4)^2) memory. A cost-only evaluation returns |r| in the last residual.
class FreeDecaySquareRootCost : public ceres::CostFunction {
 public:
  FreeDecaySquareRootCost(const ResonatorModel& model, const SlowRecord& record, int substeps,
                          const Eigen::VectorXd& z_scale, double q0_scale, SquareRootPass* last)
      : model_(model),
        record_(record),
        substeps_(substeps),
        z_scale_(z_scale.size() == 0 ? Eigen::VectorXd::Ones(model.numParameters()) : z_scale),
        q0_scale_(q0_scale),
        last_(last) {
    set_num_residuals(model.numParameters() + 5);
    mutable_parameter_block_sizes()->push_back(model.numParameters());
    mutable_parameter_block_sizes()->push_back(4);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int p = model_.numParameters();
    const int m = p + 4;
    const Eigen::VectorXd z =
        z_scale_.cwiseProduct(Eigen::Map<const Eigen::VectorXd>(parameters[0], p));
    const Eigen::Vector4d q0 = q0_scale_ * Eigen::Map<const Eigen::Vector4d>(parameters[1]);
    Eigen::Map<Eigen::VectorXd> out(residuals, m + 1);
    // Every evaluation makes the factor (a cost-only pass would cost ~1/3 of it), kept for the
    // unknowns it was made at: Levenberg-Marquardt asks for the Jacobian of an accepted trial
    // point right after its cost, and gets it without a second pass.
    Eigen::VectorXd x(m);
    x << Eigen::Map<const Eigen::VectorXd>(parameters[0], p),
        Eigen::Map<const Eigen::Vector4d>(parameters[1]);
    if (cache_.x.size() != m || cache_.x != x) {
      cache_.x.resize(0);
      IncrementalQr qr(m);
      RegressionBlockMatrix block(4, m);
      Eigen::Vector4d previous = Eigen::Vector4d::Zero();
      double ss = 0.0, lag_one = 0.0;
      const bool ok =
          integrateWithSensitivities(model_, z, q0, record_.t_s, substeps_,
                                     [&](size_t i, const Eigen::Vector4d& q, const Sensitivity& s) {
                                       block.leftCols(p) = s.leftCols(p) * z_scale_.asDiagonal();
                                       block.rightCols(4) = q0_scale_ * s.rightCols(4);
                                       const Eigen::Vector4d r = q - record_.q[i];
                                       qr.addBlock(block, r);
                                       ss += r.squaredNorm();
                                       if (i > 0) lag_one += r.dot(previous);
                                       previous = r;
                                     });
      if (!ok) return false;
      cache_.r_aug = qr.rAug();
      cache_.ss = ss;
      cache_.lag_one = lag_one;
      cache_.x = x;
    }
    const Eigen::MatrixXd& r_aug = cache_.r_aug;
    out.head(m) = r_aug.col(m).head(m);
    out[m] = r_aug(m, m);
    if (jacobians == nullptr || (jacobians[0] == nullptr && jacobians[1] == nullptr))
      return out.allFinite();
    if (last_ != nullptr) *last_ = cache_;
    if (jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> jz(
          jacobians[0], m + 1, p);
      jz.setZero();
      jz.topRows(m) = r_aug.topLeftCorner(m, p);
    }
    if (jacobians[1] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>> jq(jacobians[1], m + 1,
                                                                               4);
      jq.setZero();
      jq.topRows(m) = r_aug.block(0, p, m, 4);
    }
    return out.allFinite();
  }

 private:
  const ResonatorModel& model_;
  const SlowRecord& record_;
  int substeps_;
  Eigen::VectorXd z_scale_;
  double q0_scale_;
  SquareRootPass* last_;
  mutable SquareRootPass cache_;  ///< the last pass (one solve evaluates from one thread)
};

}  // namespace

std::unique_ptr<ceres::CostFunction> makeFreeDecaySquareRootCost(
    const ResonatorModel& model, const SlowRecord& record, int substeps,
    const Eigen::VectorXd& z_scale, double q0_scale, SquareRootPass* last_pass) {
  return std::make_unique<FreeDecaySquareRootCost>(model, record, substeps, z_scale, q0_scale,
                                                   last_pass);
}

bool evaluateFreeDecayOutputError(const ResonatorModel& model, const SlowRecord& record,
                                  int substeps, const Eigen::VectorXd& z, const Eigen::Vector4d& q0,
                                  Eigen::MatrixXd* jacobian, Eigen::VectorXd* residuals) {
  const int m = model.numParameters() + 4;
  const size_t n = record.size();
  jacobian->resize(4 * static_cast<Eigen::Index>(n), m);
  residuals->resize(4 * static_cast<Eigen::Index>(n));
  return integrateWithSensitivities(model, z, q0, record.t_s, substeps,
                                    [&](size_t i, const Eigen::Vector4d& q, const Sensitivity& s) {
                                      residuals->segment<4>(4 * i) = q - record.q[i];
                                      jacobian->middleRows(4 * i, 4) = s;
                                    }) &&
         jacobian->allFinite() && residuals->allFinite();
}

bool integrateSlowInitialSensitivity(
    const ResonatorModel& model, const Eigen::VectorXd& z, const Eigen::Vector4d& q0,
    const std::vector<double>& t_s, int substeps,
    const std::function<void(size_t, const Eigen::Vector4d&, const Eigen::Matrix4d&)>& visit) {
  if (t_s.empty()) return true;
  const double t0 = t_s.front();
  Eigen::Vector4d q = q0;
  Eigen::Matrix4d s = Eigen::Matrix4d::Identity();
  visit(size_t{0}, q, s);
  // One RK4 stage: k = q'(q), K = A(q) S with A = slowJacobian (2.6).
  auto stage4 = [&](double t, const Eigen::Vector4d& x, const Eigen::Matrix4d& sx,
                    Eigen::Vector4d* k, Eigen::Matrix4d* ks) {
    const SlowContext ctx{t, 0.0};
    *k = model.slowDerivative(x, ctx, z);
    ks->noalias() = model.slowJacobian(x, ctx, z) * sx;
  };
  Eigen::Vector4d k1, k2, k3, k4;
  Eigen::Matrix4d s1, s2, s3, s4;
  for (size_t i = 1; i < t_s.size(); ++i) {
    const double h = (t_s[i] - t_s[i - 1]) / substeps;
    double t = t_s[i - 1] - t0;
    for (int sub = 0; sub < substeps; ++sub, t += h) {
      stage4(t, q, s, &k1, &s1);
      stage4(t + h / 2, q + h / 2 * k1, s + h / 2 * s1, &k2, &s2);
      stage4(t + h / 2, q + h / 2 * k2, s + h / 2 * s2, &k3, &s3);
      stage4(t + h, q + h * k3, s + h * s3, &k4, &s4);
      q += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      s += h / 6 * (s1 + 2 * s2 + 2 * s3 + s4);
    }
    if (!q.allFinite() || !s.allFinite()) return false;
    visit(i, q, s);
  }
  return true;
}

bool integrateSlowSensitivities(
    const ResonatorModel& model, const Eigen::VectorXd& z, const Eigen::Vector4d& q0,
    const std::vector<double>& t_s, int substeps, std::vector<Eigen::Vector4d>* trajectory,
    std::vector<Eigen::Matrix<double, 4, Eigen::Dynamic>>* sensitivity) {
  trajectory->resize(t_s.size());
  sensitivity->resize(t_s.size());
  return integrateWithSensitivities(model, z, q0, t_s, substeps,
                                    [&](size_t i, const Eigen::Vector4d& q, const Sensitivity& s) {
                                      (*trajectory)[i] = q;
                                      (*sensitivity)[i] = s;
                                    });
}

bool integrateSlowTrajectory(const ResonatorModel& model, const Eigen::VectorXd& z,
                             const Eigen::Vector4d& q0, const std::vector<double>& t_s,
                             int substeps, std::vector<Eigen::Vector4d>* trajectory) {
  trajectory->resize(t_s.size());
  return forEachTrajectoryPoint(model, z, q0, t_s, substeps,
                                [&](size_t i, const Eigen::Vector4d& q) { (*trajectory)[i] = q; });
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
    TrajectoryDerivative derivative, const Eigen::VectorXd& z_scale, double q0_scale) {
  if (derivative == TrajectoryDerivative::kSensitivity)
    return std::make_unique<FreeDecaySensitivityCost>(model, record, substeps, z_scale, q0_scale);
  if (derivative == TrajectoryDerivative::kRidders)
    return makeCost<ceres::RIDDERS>(model, record, substeps, z_scale, q0_scale);
  return makeCost<ceres::CENTRAL>(model, record, substeps, z_scale, q0_scale);
}

}  // namespace cvg_bench

// The analytic Jacobians d(D(q) z)/dq of every term (ModelTerm::averagedJacobian) equal
// finite differences of the term's own averaged columns (the one place its equation lives), like
// an "analytic vs automatic differentiation" check; the model's regressorJacobian/slowJacobian
// equal finite differences of regressor/slowDerivative.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cvg_bench/core/model/model_terms.h"
#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {
namespace {

/// Fourth-order central differences of f: R^4 -> R^4 (truncation ~ h^4, rounding ~ eps/h).
template <typename F>
Eigen::Matrix4d differences(const F& f, const Eigen::Vector4d& q, double h) {
  Eigen::Matrix4d j;
  for (int c = 0; c < 4; ++c) {
    auto at = [&](double s) {
      Eigen::Vector4d qq = q;
      qq[c] += s * h;
      return Eigen::Vector4d(f(qq));
    };
    j.col(c) = (-at(2) + 8.0 * at(1) - 8.0 * at(-1) + at(-2)) / (12.0 * h);
  }
  return j;
}

TEST(ModelTermJacobian, EveryAnalyticJacobianMatchesFiniteDifferences) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (const auto& name : knownModelTermNames()) {
    const auto term = makeModelTerm(name);
    const int k = term->numParameters();
    for (int trial = 0; trial < 25; ++trial) {
      const Eigen::Vector4d q(u(rng), u(rng), u(rng), u(rng));
      const SlowContext ctx{3.0 * std::fabs(u(rng)), 0.4 * u(rng)};
      Eigen::VectorXd z(k);
      for (int j = 0; j < k; ++j) z[j] = 10.0 * u(rng);
      Eigen::Matrix4d analytic;
      term->averagedJacobian(q, ctx, z, analytic);
      const Eigen::Matrix4d reference = differences(
          [&](const Eigen::Vector4d& x) {
            Eigen::MatrixXd cols(4, k);
            term->averagedColumns(x, ctx, cols);
            return Eigen::Vector4d(cols * z);
          },
          q, 1e-3);
      EXPECT_LT((analytic - reference).cwiseAbs().maxCoeff(), 1e-8 * (1.0 + reference.norm()))
          << "term " << name << " at q = " << q.transpose() << "\nanalytic\n"
          << analytic << "\nfinite differences\n"
          << reference;
      // The base class's central differences (the default for terms without an analytic form).
      Eigen::Matrix4d numerical;
      term->averagedJacobianNumerical(q, ctx, z, numerical);
      EXPECT_LT((numerical - reference).cwiseAbs().maxCoeff(), 1e-6 * (1.0 + reference.norm()))
          << "term " << name;
    }
  }
}

// A term without an analytic Jacobian gets the default (central differences): exact answer known.
class QuadraticTestTerm : public ModelTerm {
 public:
  std::string name() const override { return "quadratic_test"; }
  std::vector<std::string> parameterNames() const override { return {"c"}; }
  std::string description() const override {
    return "test term with column (q1^2, q1 p1, 0, p2^3)";
  }
  void averagedColumns(const Eigen::Vector4d& q, const SlowContext&,
                       Eigen::Ref<Eigen::MatrixXd> d) const override {
    d(0, 0) = q[0] * q[0];
    d(1, 0) = q[0] * q[1];
    d(2, 0) = 0.0;
    d(3, 0) = q[3] * q[3] * q[3];
  }
  void fastColumns(const FastState&, const FastContext&,
                   Eigen::Ref<Eigen::MatrixXd> cols) const override {
    cols.setZero();
  }
};

TEST(ModelTermJacobian, DefaultIsCentralDifferences) {
  const QuadraticTestTerm term;
  const Eigen::Vector4d q(0.7, -0.3, 0.2, 0.5);
  Eigen::VectorXd z(1);
  z << 2.5;
  Eigen::Matrix4d j;
  term.averagedJacobian(q, SlowContext{}, z, j);
  Eigen::Matrix4d exact = Eigen::Matrix4d::Zero();
  exact(0, 0) = 2.5 * 2 * q[0];
  exact(1, 0) = 2.5 * q[1];
  exact(1, 1) = 2.5 * q[0];
  exact(3, 3) = 2.5 * 3 * q[3] * q[3];
  EXPECT_LT((j - exact).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(ModelTermJacobian, ModelJacobiansMatchFiniteDifferences) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  const ResonatorModel free_decay("xi+kappa+gamma_nl+cm_rate+xi_diff+xi_k",
                                  ExperimentMode::kFreeDecay);
  const ResonatorModel forced("xi+kappa", ExperimentMode::kForced);
  for (const ResonatorModel* model : {&free_decay, &forced}) {
    for (int trial = 0; trial < 10; ++trial) {
      const Eigen::Vector4d q(u(rng), u(rng), u(rng), u(rng));
      const SlowContext ctx{2.0 * std::fabs(u(rng)), model == &forced ? 0.3 * u(rng) : 0.0};
      Eigen::VectorXd z(model->numParameters());
      for (int j = 0; j < z.size(); ++j) z[j] = 5.0 * u(rng);
      const double rate = model == &forced ? 7.0 * u(rng) : 0.0;
      Eigen::Matrix4d g;
      model->regressorJacobian(q, ctx, z, g);
      const Eigen::Matrix4d g_ref = differences(
          [&](const Eigen::Vector4d& x) { return Eigen::Vector4d(model->regressor(x, ctx) * z); },
          q, 1e-3);
      EXPECT_LT((g - g_ref).cwiseAbs().maxCoeff(), 1e-8 * (1.0 + g_ref.norm())) << model->spec();
      const Eigen::Matrix4d s = model->slowJacobian(q, ctx, z, rate);
      const Eigen::Matrix4d s_ref = differences(
          [&](const Eigen::Vector4d& x) { return model->slowDerivative(x, ctx, z, rate); }, q,
          1e-3);
      EXPECT_LT((s - s_ref).cwiseAbs().maxCoeff(), 1e-8 * (1.0 + s_ref.norm())) << model->spec();
    }
  }
  Eigen::Matrix4d g;
  EXPECT_THROW(free_decay.regressorJacobian(Eigen::Vector4d::Ones(), SlowContext{},
                                            Eigen::VectorXd::Zero(3), g),
               std::exception);
}

}  // namespace
}  // namespace cvg_bench

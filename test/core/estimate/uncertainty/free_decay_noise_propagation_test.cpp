// The errors-in-variables propagation of the free-decay regression against brute force: the
// sensitivity J = d(equation errors)/d(samples) by central differences through the block generator,
// then sum_m W_m W_m' = D' J J' D and the noise gain ||J||_F^2. Two records (the record ends carry
// the O(1) terms), uniform (Simpson) and irregular (trapezoid) times, the largest free-decay model.
#include "cvg_bench/core/estimate/uncertainty/free_decay_noise_propagation.h"

#include <gtest/gtest.h>

#include <random>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace {

const char* kModel = "xi+kappa+gamma_nl+cm_rate+xi_diff";

SlowRecord randomRecord(int n, bool uniform, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  SlowRecord r;
  double t = 0.3;
  for (int i = 0; i < n; ++i) {
    r.t_s.push_back(t);
    t += uniform ? 0.01 : 0.01 * (1.0 + 0.4 * u(gen));
    r.q.emplace_back(u(gen), u(gen), 0.5 * u(gen), 0.5 * u(gen));
  }
  return r;
}

/// Equation errors y_i - D-bar_i z of every block of the records, stacked.
Eigen::VectorXd equationErrors(const ResonatorModel& model, const std::vector<SlowRecord>& recs,
                               const std::vector<bool>& simpson, const Eigen::VectorXd& z) {
  std::vector<double> e;
  for (size_t r = 0; r < recs.size(); ++r) {
    forEachValidatedFreeDecayBlock(model, recs[r], simpson[r], [&](const RegressionBlock& b) {
      const Eigen::Vector4d ei = b.y - (*b.d) * z;
      e.insert(e.end(), ei.data(), ei.data() + 4);
    });
  }
  return Eigen::Map<Eigen::VectorXd>(e.data(), static_cast<long>(e.size()));
}

TEST(FreeDecayNoisePropagation, MatchesBruteForceSensitivities) {
  const ResonatorModel model(kModel, ExperimentMode::kFreeDecay);
  const int k = model.numParameters();
  std::mt19937_64 gen(7);
  std::normal_distribution<double> n01;
  Eigen::VectorXd z(k);
  for (int j = 0; j < k; ++j) z[j] = n01(gen);
  const std::vector<SlowRecord> recs = {randomRecord(9, true, 1), randomRecord(7, false, 2)};
  const std::vector<bool> simpson = {true, false};

  FreeDecayNoisePropagation propagation(model, z);
  std::vector<Eigen::MatrixXd> dbar;
  for (size_t r = 0; r < recs.size(); ++r) {
    forEachValidatedFreeDecayBlock(model, recs[r], simpson[r], [&](const RegressionBlock& b) {
      propagation.add(b);
      dbar.push_back(*b.d);
    });
  }
  Eigen::MatrixXd d(4 * dbar.size(), k);
  for (size_t i = 0; i < dbar.size(); ++i) d.middleRows(4 * i, 4) = dbar[i];

  // J by central differences over every coordinate of every sample.
  const Eigen::VectorXd e0 = equationErrors(model, recs, simpson, z);
  std::vector<Eigen::VectorXd> columns;
  const double h = 1e-6;
  for (size_t r = 0; r < recs.size(); ++r) {
    for (size_t m = 0; m < recs[r].size(); ++m) {
      for (int c = 0; c < 4; ++c) {
        std::vector<SlowRecord> plus = recs, minus = recs;
        plus[r].q[m][c] += h;
        minus[r].q[m][c] -= h;
        columns.push_back(
            (equationErrors(model, plus, simpson, z) - equationErrors(model, minus, simpson, z)) /
            (2.0 * h));
      }
    }
  }
  Eigen::MatrixXd jac(e0.size(), static_cast<long>(columns.size()));
  for (size_t c = 0; c < columns.size(); ++c) jac.col(static_cast<long>(c)) = columns[c];

  const Eigen::MatrixXd expected = d.transpose() * jac * jac.transpose() * d;
  const Eigen::MatrixXd gram = propagation.sensitivityGram();
  EXPECT_LT((gram - expected).norm(), 1e-7 * expected.norm());
  EXPECT_NEAR(propagation.noiseGain(), jac.squaredNorm(), 1e-7 * jac.squaredNorm());
}

TEST(FreeDecayNoisePropagation, RejectsAParameterVectorOfTheWrongSize) {
  const ResonatorModel model("xi", ExperimentMode::kFreeDecay);
  EXPECT_THROW(FreeDecayNoisePropagation(model, Eigen::VectorXd::Zero(3)), InputError);
}

}  // namespace
}  // namespace cvg_bench

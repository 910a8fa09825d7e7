// Speed of the identification: batch free decay over 10^6 slow samples with the 13-parameter
// free-decay model linear+xi+kappa+gamma_nl+cm_rate+xi_diff (every free-decay term: 13 is the
// largest free-decay model), the same with the forced 14-parameter model linear+controls+xi+kappa
// over 10^6 sweep points, and one block update of the RLS (2.12) with 13 parameters.
#include <benchmark/benchmark.h>

#include <random>

#include "cvg_bench/core/estimate/identification.h"
#include "cvg_bench/core/estimate/recursive_least_squares.h"

namespace cvg_bench {
namespace {

const char* kFreeDecayModel = "xi+kappa+gamma_nl+cm_rate+xi_diff";

// A decaying, precessing wave with noise (the regression cost does not depend on the physics).
SlowRecord syntheticFreeDecay(long n) {
  SlowRecord r;
  std::mt19937_64 gen(1);
  std::normal_distribution<double> noise(0.0, 1e-4);
  r.t_s.resize(n);
  r.q.resize(n);
  for (long i = 0; i < n; ++i) {
    const double t = i * 1e-3, a = std::exp(-0.05 * t);
    r.t_s[i] = t;
    r.q[i] = Eigen::Vector4d(a * std::cos(0.3 * t) + noise(gen), a * std::sin(0.3 * t) + noise(gen),
                             0.3 * a * std::cos(0.2 * t) + noise(gen),
                             0.3 * a * std::sin(0.25 * t) + noise(gen));
  }
  return r;
}

void BM_FreeDecayBatch13Params1e6Samples(benchmark::State& state) {
  const SlowRecord rec = syntheticFreeDecay(1000000);
  IdentificationOptions opt;
  opt.model = kFreeDecayModel;
  for (auto _ : state) benchmark::DoNotOptimize(identifyFreeDecay(rec, opt));
  state.SetItemsProcessed(state.iterations() * static_cast<long>(rec.size()));
}
BENCHMARK(BM_FreeDecayBatch13Params1e6Samples)->Unit(benchmark::kMillisecond);

// The NumPy reference (scripts/bench_numpy_identify.py) runs the same linear-model batch.
void BM_FreeDecayBatchLinear1e6Samples(benchmark::State& state) {
  const SlowRecord rec = syntheticFreeDecay(1000000);
  IdentificationOptions opt;
  for (auto _ : state) benchmark::DoNotOptimize(identifyFreeDecay(rec, opt));
  state.SetItemsProcessed(state.iterations() * static_cast<long>(rec.size()));
}
BENCHMARK(BM_FreeDecayBatchLinear1e6Samples)->Unit(benchmark::kMillisecond);

void BM_ForcedBatch14Params1e6Points(benchmark::State& state) {
  SweepRecord rec;
  rec.omega_rad_s = 85732.0;
  std::mt19937_64 gen(2);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (long j = 0; j < 1000000; ++j) {
    rec.omega0_rad_s.push_back(85732.0 - 80.0 + 160.0 * j / 1e6);
    rec.q.emplace_back(u(gen), u(gen), u(gen), u(gen));
  }
  IdentificationOptions opt;
  opt.model = "xi+kappa";
  for (auto _ : state) benchmark::DoNotOptimize(identifyForced(rec, opt));
  state.SetItemsProcessed(state.iterations() * static_cast<long>(rec.size()));
}
BENCHMARK(BM_ForcedBatch14Params1e6Points)->Unit(benchmark::kMillisecond);

// One evaluation of D(q) and of G = d(D(q) z)/dq (the per-sample work of the two passes).
void BM_Regressor13Params(benchmark::State& state) {
  const ResonatorModel model(kFreeDecayModel, ExperimentMode::kFreeDecay);
  RegressionBlockMatrix d(4, model.numParameters());
  Eigen::Vector4d q(0.8, -0.3, 0.2, 0.1);
  SlowContext ctx;
  for (auto _ : state) {
    q[0] += 1e-9;
    model.regressor(q, ctx, d);
    benchmark::DoNotOptimize(d.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Regressor13Params);

void BM_RegressorJacobian13Params(benchmark::State& state) {
  const ResonatorModel model(kFreeDecayModel, ExperimentMode::kFreeDecay);
  const Eigen::VectorXd z = Eigen::VectorXd::LinSpaced(model.numParameters(), -1.0, 1.0);
  Eigen::Vector4d q(0.8, -0.3, 0.2, 0.1);
  Eigen::Matrix4d g;
  SlowContext ctx;
  for (auto _ : state) {
    q[0] += 1e-9;
    model.regressorJacobian(q, ctx, z, g);
    benchmark::DoNotOptimize(g.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RegressorJacobian13Params);

// The streaming QR alone: 10^5 blocks of 4 rows, 13 parameters (+ right-hand side).
void BM_IncrementalQr13Params1e5Blocks(benchmark::State& state) {
  const int k = 13;
  std::mt19937_64 gen(4);
  std::normal_distribution<double> n01;
  std::vector<RegressionBlockMatrix> blocks(64, RegressionBlockMatrix(4, k));
  for (auto& d : blocks)
    for (int j = 0; j < k; ++j)
      for (int i = 0; i < 4; ++i) d(i, j) = n01(gen);
  const Eigen::Vector4d y(0.1, -0.2, 0.3, 0.05);
  for (auto _ : state) {
    IncrementalQr qr(k);
    for (long b = 0; b < 100000; ++b) qr.addBlock(blocks[b % 64], y);
    benchmark::DoNotOptimize(qr.rAug().data());
  }
  state.SetItemsProcessed(state.iterations() * 100000L);
}
BENCHMARK(BM_IncrementalQr13Params1e5Blocks)->Unit(benchmark::kMillisecond);

void BM_RlsBlockUpdate13Params(benchmark::State& state) {
  const int k = 13;
  std::mt19937_64 gen(3);
  std::normal_distribution<double> n01;
  Eigen::MatrixXd a(4 * 40, k);
  Eigen::VectorXd y(4 * 40);
  for (int i = 0; i < a.rows(); ++i) {
    for (int j = 0; j < k; ++j) a(i, j) = n01(gen);
    y[i] = n01(gen);
  }
  IncrementalQr qr(k);
  qr.addRows(a, y);
  BlockRecursiveLeastSquares rls(k);
  rls.initialize(qr.rAug(), qr.numRows());
  RegressionBlockMatrix d(4, k);
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < 4; ++i) d(i, j) = n01(gen);
  const Eigen::Vector4d yb(0.1, -0.2, 0.3, 0.05);
  for (auto _ : state) {
    rls.update(d, yb);
    benchmark::DoNotOptimize(rls.z().data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RlsBlockUpdate13Params);

}  // namespace
}  // namespace cvg_bench

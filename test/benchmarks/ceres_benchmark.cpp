// Time of the Ceres output-error refinement (--method ceres), started 5 % off the truth:
//  - a free-decay record of 2000 samples, model linear+xi (9 parameters + 4 initial values,
//    forward-sensitivity Jacobian of the RK4 trajectory), and one Jacobian evaluation by
//    sensitivities against central differences;
//  - a 61-point forced sweep with the paper's section-4 model (13 parameters, Newton stationary
//    points, implicit-function derivatives), and the same with mu estimated jointly.
#include <benchmark/benchmark.h>

#include <random>

#include "../core/paper_section4_estimate.h"
#include "cvg_bench/core/estimate/ceres_refinement.h"
#include "cvg_bench/core/estimate/output_error_free_decay.h"

namespace cvg_bench {
namespace {

const ParameterValues& kFreeTruth = testing_support::kFreeDecayTruth;
const ParameterValues& kForcedTruth = testing_support::kSection4Estimate;
constexpr double kOmega = testing_support::kSection4OmegaRadS;

void addNoise(std::vector<Eigen::Vector4d>* q, double sigma) {
  std::mt19937 rng(42);
  std::normal_distribution<double> n(0.0, sigma);
  for (auto& v : *q)
    for (int c = 0; c < 4; ++c) v[c] += n(rng);
}

Estimate perturbedStart(const ResonatorModel& model, const ParameterValues& truth) {
  Estimate e;
  e.mode = model.mode();
  e.model = model.spec();
  e.method = "ls";
  e.omega_rad_s = kOmega;
  e.names = model.parameterNames();
  e.values = model.parameterVector(truth) * 1.05;
  return e;
}

void BM_CeresFreeDecay2000Samples(benchmark::State& state) {
  const ResonatorModel model("xi", ExperimentMode::kFreeDecay);
  SlowRecord record;
  for (int i = 0; i < 2000; ++i) record.t_s.push_back(0.002 * i);
  integrateSlowTrajectory(model, model.parameterVector(kFreeTruth),
                          Eigen::Vector4d(0.8, 0.3, -0.2, 0.4), record.t_s, 1, &record.q);
  addNoise(&record.q, 1e-3);
  const Estimate start = perturbedStart(model, kFreeTruth);
  for (auto _ : state) benchmark::DoNotOptimize(refineWithCeres(record, start));
}
BENCHMARK(BM_CeresFreeDecay2000Samples)->Unit(benchmark::kMillisecond);

/// One residual + Jacobian evaluation of the free-decay output error (2000 samples, linear+xi):
/// forward sensitivities against central differences (the derivative used before), same run.
void jacobianBenchmark(benchmark::State& state, TrajectoryDerivative derivative) {
  const ResonatorModel model("xi", ExperimentMode::kFreeDecay);
  SlowRecord record;
  for (int i = 0; i < 2000; ++i) record.t_s.push_back(0.002 * i);
  const Eigen::VectorXd z = model.parameterVector(kFreeTruth);
  const Eigen::Vector4d q0(0.8, 0.3, -0.2, 0.4);
  integrateSlowTrajectory(model, z, q0, record.t_s, 1, &record.q);
  const auto cost = makeFreeDecayOutputErrorCost(model, record, 1, derivative);
  std::vector<double> r(cost->num_residuals()), jz(r.size() * z.size()), jq(r.size() * 4);
  const double* params[] = {z.data(), q0.data()};
  double* jac[] = {jz.data(), jq.data()};
  for (auto _ : state) benchmark::DoNotOptimize(cost->Evaluate(params, r.data(), jac));
}
void BM_FreeDecayJacobianSensitivities(benchmark::State& state) {
  jacobianBenchmark(state, TrajectoryDerivative::kSensitivity);
}
BENCHMARK(BM_FreeDecayJacobianSensitivities)->Unit(benchmark::kMillisecond);
void BM_FreeDecayJacobianCentralDifferences(benchmark::State& state) {
  jacobianBenchmark(state, TrajectoryDerivative::kCentral);
}
BENCHMARK(BM_FreeDecayJacobianCentralDifferences)->Unit(benchmark::kMillisecond);

void sweepBenchmark(benchmark::State& state, const std::string& spec) {
  const ResonatorModel truth_model("xi", ExperimentMode::kForced);
  const ResonatorModel model(spec, ExperimentMode::kForced);
  const Eigen::VectorXd z = truth_model.parameterVector(kForcedTruth);
  SweepRecord record;
  record.omega_rad_s = kOmega;
  Eigen::Vector4d q = Eigen::Vector4d::Zero();
  for (int j = 0; j < 61; ++j) {
    const double omega0 = kOmega - 150.0 + 5.0 * j;
    q = solveStationaryPoint(truth_model, z, SlowContext{}, detuningRate(kOmega, omega0), q).q;
    record.omega0_rad_s.push_back(omega0);
    record.q.push_back(q);
  }
  addNoise(&record.q, 1e-2);
  const Estimate start = perturbedStart(model, kForcedTruth);
  for (auto _ : state) benchmark::DoNotOptimize(refineWithCeres(record, start));
}

void BM_CeresForcedSweep61Points(benchmark::State& state) {
  sweepBenchmark(state, "xi");
}
BENCHMARK(BM_CeresForcedSweep61Points)->Unit(benchmark::kMillisecond);

void BM_CeresForcedSweep61PointsWithMu(benchmark::State& state) {
  sweepBenchmark(state, "xi+mu");
}
BENCHMARK(BM_CeresForcedSweep61PointsWithMu)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cvg_bench

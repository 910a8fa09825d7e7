// Simulator speed as a multiple of real time (counter x_real_time):
//  - full equations (FullEquationSimulator) of the mems_ring preset's forced truth model at 20 RK4
//  steps
//    per period (target >= 20x real time);
//  - the averaged model (AveragedModelSimulator) over an hour-long ring-down of the
//  hrg_hemispherical preset.
#include <benchmark/benchmark.h>

#include "cvg_bench/core/model/resonator_preset.h"
#include "cvg_bench/core/simulate/averaged_model_simulator.h"
#include "cvg_bench/core/simulate/full_equation_simulator.h"

namespace cvg_bench {
namespace {

/// state.range(0): 1 = forced (controls at omega0 = omega + 5 rad/s), 0 = free decay.
void BM_FullEquationsMemsRing(benchmark::State& state) {
  const ResonatorPreset p = loadShippedPreset("mems_ring");
  const ExperimentMode mode = state.range(0) ? ExperimentMode::kForced : ExperimentMode::kFreeDecay;
  const ResonatorModel model(p.truthModelSpec(mode), mode);
  FullEquationSimulatorOptions fo;
  fo.steps_per_period = 20;
  const double w = p.omega_rad_s + (state.range(0) ? 5.0 : 0.0);
  FullEquationSimulator sim(model, p.truthParameters(model), p.omega_rad_s, w, p.mu, {}, fo);
  state.SetLabel(state.range(0) ? "forced, 20 steps/period" : "free decay, 20 steps/period");
  const double simulated_s = 0.01;  // 2729 RK4 steps
  double sim_total = 0.0;
  for (auto _ : state) {
    sim.reset(Eigen::Vector4d(0.5, 0.5, 0.01, 0.0), 0.0);
    sim.advanceTo(simulated_s);
    benchmark::DoNotOptimize(sim.osculating());
    sim_total += simulated_s;
  }
  state.counters["x_real_time"] = benchmark::Counter(sim_total, benchmark::Counter::kIsRate);
  state.counters["steps_per_s"] =
      benchmark::Counter(sim_total / sim.maxStep(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FullEquationsMemsRing)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_AveragedModelHrgHourRingDown(benchmark::State& state) {
  const ResonatorPreset p = loadShippedPreset("hrg_hemispherical");
  const ResonatorModel model(p.truthModelSpec(ExperimentMode::kFreeDecay),
                             ExperimentMode::kFreeDecay);
  AveragedModelSimulator sim(model, p.truthParameters(model));
  const double simulated_s = 3600.0;
  double sim_total = 0.0;
  for (auto _ : state) {
    sim.reset(Eigen::Vector4d(1.0, 0.0, 0.1, 0.0), 0.0);
    SlowRecord rec;
    sim.sample(p.decay_sample_rate_hz, static_cast<size_t>(simulated_s * p.decay_sample_rate_hz),
               rec);
    benchmark::DoNotOptimize(rec.q.back());
    sim_total += simulated_s;
  }
  state.counters["x_real_time"] = benchmark::Counter(sim_total, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_AveragedModelHrgHourRingDown)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cvg_bench

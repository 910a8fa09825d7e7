// Demodulator throughput: (f, g) sample pairs per second on one core, with the real filter chain
// (default 120 dB, 100 Hz output) at the MEMS ring's 13.6 kHz reference. items_per_second =
// sample pairs/s. The same sizes are timed in NumPy by scripts/bench_numpy_demod.py (names match).
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "cvg_bench/core/demod/demodulator.h"
#include "cvg_bench/core/demod/fir_lowpass.h"

namespace {

struct Signal {
  std::vector<double> t, f, g;
};

Signal makeSignal(size_t n, double fs, double w) {
  Signal s;
  s.t.resize(n);
  s.f.resize(n);
  s.g.resize(n);
  for (size_t i = 0; i < n; ++i) {
    s.t[i] = double(i) / fs;
    s.f[i] = 0.8 * std::cos(w * s.t[i]) - 0.3 * std::sin(w * s.t[i]);
    s.g[i] = 0.1 * std::cos(w * s.t[i]) + 0.05 * std::sin(w * s.t[i]);
  }
  return s;
}

/// Streaming demodulation of batches of `range(0)` pairs at 100 kHz input.
void BM_DemodUniform(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  cvg_bench::DemodulatorOptions o;
  o.omega_rad_s = 85732.0;
  o.sample_rate_hz = 100000.0;
  o.output_rate_hz = 100.0;
  cvg_bench::Demodulator demod(o);
  const Signal s = makeSignal(n, o.sample_rate_hz, o.omega_rad_s);
  std::vector<cvg_bench::SlowSample> out;
  double offset = 0.0;
  std::vector<double> t = s.t;
  for (auto _ : state) {
    for (size_t i = 0; i < n; ++i) t[i] = s.t[i] + offset;  // continuous time across iterations
    offset += double(n) / o.sample_rate_hz;
    out.clear();
    demod.push(t.data(), s.f.data(), s.g.data(), n, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
  state.counters["taps_stage1"] = static_cast<double>(demod.stages().front().n_taps);
  state.counters["stages"] = static_cast<double>(demod.stages().size());
}
BENCHMARK(BM_DemodUniform)
    ->Name("demod_uniform")
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond);

/// Filter design cost (start-up of a node), for reference.
void BM_DesignLowpass(benchmark::State& state) {
  for (auto _ : state) {
    auto h = cvg_bench::designKaiserLowpass({100000.0, 20.0, 1950.0, 126.0});
    benchmark::DoNotOptimize(h.data());
  }
}
BENCHMARK(BM_DesignLowpass)->Name("demod_design_lowpass")->Unit(benchmark::kMillisecond);

}  // namespace

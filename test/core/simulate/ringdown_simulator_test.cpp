// The ring-down generator against closed forms (ringdown_models.h).
#include "cvg_bench/core/simulate/ringdown_simulator.h"

#include <gtest/gtest.h>

#include <cmath>

namespace cvg_bench {
namespace {

RingdownSimulationOptions noiseless() {
  RingdownSimulationOptions o;
  o.frequency_hz = 1000.0;
  o.q = 5000.0;  // g0 = pi f / Q = 0.628 1/s
  o.noise_db = 0.0;
  o.floor_db = -400.0;
  o.duration_s = 10.0;
  o.plateau_s = 1.0;
  o.n_samples = 1001;
  return o;
}

TEST(RingdownSimulator, LinearDecayIsExponentialWithQ) {
  const RingdownRecord r = simulateRingdown(noiseless());
  const double g0 = M_PI * 1000.0 / 5000.0;
  for (size_t i = 0; i < r.size(); ++i) {
    const double td = std::max(0.0, r.t_s[i] - 1.0);
    EXPECT_NEAR(std::log(r.value[i]), -g0 * td, 1e-9) << i;
  }
}

TEST(RingdownSimulator, AmplitudeSquaredLawMatchesClosedForm) {
  RingdownSimulationOptions o = noiseless();
  o.gamma_nl = 2.0;  // rate at A = 1: g0 + 2
  o.amplitude = 1.0;
  const RingdownRecord r = simulateRingdown(o);
  const double g0 = M_PI * 1000.0 / 5000.0;
  for (size_t i = 0; i < r.size(); i += 50) {
    const double td = std::max(0.0, r.t_s[i] - 1.0);
    const double a2 = std::exp(-2 * g0 * td) / (1.0 + 2.0 * (1 - std::exp(-2 * g0 * td)) / g0);
    EXPECT_NEAR(r.value[i], std::sqrt(a2), 1e-8 * std::sqrt(a2) + 1e-12) << i;
  }
}

TEST(RingdownSimulator, DbOutputAndBeatDepth) {
  RingdownSimulationOptions o = noiseless();
  o.output_db = true;
  o.db_offset = 13.0;
  o.split_hz = 1.0;
  o.second_amplitude = 0.2;
  const RingdownRecord r = simulateRingdown(o);
  EXPECT_EQ(r.kind, RingdownValueKind::kPowerDb);
  // On the plateau both modes add in phase: 20 log10(1.2) + 13 dB.
  EXPECT_NEAR(r.value[0], 20 * std::log10(1.2) + 13.0, 1e-9);
  // Half a beat period after switch-off they are in antiphase (equal Q): 20 log10(0.8 e^{-g t}).
  const double g0 = M_PI * 1000.0 / 5000.0;
  const size_t i = 150;  // t = 1.5 s: 0.5 s after switch-off
  EXPECT_NEAR(r.value[i], 20 * std::log10(0.8 * std::exp(-g0 * 0.5)) + 13.0, 1e-6);
}

}  // namespace
}  // namespace cvg_bench

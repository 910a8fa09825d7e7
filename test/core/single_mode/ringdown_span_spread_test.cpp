// The span part of Q's interval (ringdown_span_spread.h): its quantile follows the fit's
// confidence, its spread does not depend on it.
#include "cvg_bench/core/single_mode/ringdown_span_spread.h"

#include <gtest/gtest.h>

#include <cmath>

#include "cvg_bench/core/simulate/ringdown_simulator.h"
#include "cvg_bench/core/single_mode/ringdown_envelope.h"

namespace cvg_bench {
namespace {

struct SpreadCase {
  RingdownEnvelope env;
  RingdownSegment seg;
};

// A decay whose damping grows with amplitude (A^2 law), read with the single exponential: the
// neighbouring spans see different mean rates, so the span part is not small beside the noise part.
SpreadCase curvedDecay() {
  RingdownSimulationOptions o;
  o.frequency_hz = 1.0e4;
  o.q = 2.0e5;
  o.gamma_nl = 0.5;  // 1/(s unit^2): at A = 1 three times the linear rate 1 / 6.37 s
  o.noise_db = 0.02;
  o.floor_db = -70.0;
  o.seed = 11;
  SpreadCase c;
  c.env = ringdownEnvelope(simulateRingdown(o));
  c.seg = segmentRingdown(c.env);
  return c;
}

RingdownValue spreadQ(const SpreadCase& c, double confidence) {
  RingdownFitOptions o;
  o.confidence = confidence;
  RingdownFit f = fitRingdown(c.env, c.seg, "linear", o);
  addSpanSpread(c.env, c.seg, o, &f);
  return f.derived.at("Q");
}

TEST(RingdownSpanSpread, TheTotalIntervalFollowsTheConfidence) {
  const SpreadCase c = curvedDecay();
  const RingdownValue q95 = spreadQ(c, 0.95), q90 = spreadQ(c, 0.90);
  ASSERT_TRUE(std::isfinite(q95.std_span));
  EXPECT_GT(q95.std_span, 0.3 * q95.std);  // the neighbouring spans see different rates
  EXPECT_DOUBLE_EQ(q90.std_span, q95.std_span);
  EXPECT_DOUBLE_EQ(q90.std_total, q95.std_total);
  ASSERT_GT(q95.ci_total_high, q95.ci_high);
  ASSERT_GT(q90.ci_total_high, q90.ci_high);
  // Q exp(+-z std_total / Q): the log half-widths scale as the normal quantiles 1.6449 / 1.9600.
  const double ratio =
      std::log(q90.ci_total_high / q90.value) / std::log(q95.ci_total_high / q95.value);
  EXPECT_NEAR(ratio, 1.6448536269514722 / 1.959963984540054, 1e-9);
  EXPECT_NEAR(std::log(q95.value / q95.ci_total_low), std::log(q95.ci_total_high / q95.value),
              1e-9);
  EXPECT_GT(q95.ci_total_low, 0.0);
}

}  // namespace
}  // namespace cvg_bench

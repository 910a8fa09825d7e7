// The demodulator after a corrupted sample: |f| or |g| above max_abs_signal (a finite 1e300 that
// would overflow the filter) is dropped and counted, the filter state is cleared, and the outputs
// that follow equal the envelope of (2.4) again; a NaN in between changes nothing of that.
#include <gtest/gtest.h>

#include <cmath>

#include "cvg_bench/core/demod/demodulator.h"

namespace cvg_bench {
namespace {

const Eigen::Vector4d kEnvelope(0.6, 0.4, -0.1, 0.2);

void tone(double w, const std::vector<double>& t, std::vector<double>& f, std::vector<double>& g) {
  f.resize(t.size());
  g.resize(t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    const long double ph = static_cast<long double>(w) * t[i];
    const double c = static_cast<double>(std::cos(ph)), s = static_cast<double>(std::sin(ph));
    f[i] = kEnvelope[1] * s + kEnvelope[0] * c;
    g[i] = kEnvelope[3] * s + kEnvelope[2] * c;
  }
}

TEST(DemodulatorRecovery, HugeSampleIsDroppedAndTheFilterRestarts) {
  DemodulatorOptions o;
  o.omega_rad_s = 85732.0;  // the paper's MEMS ring (section 4)
  o.sample_rate_hz = 100000.0;
  o.output_rate_hz = 1000.0;
  std::vector<double> t(20000), f, g;
  for (size_t i = 0; i < t.size(); ++i) t[i] = 10.0 + double(i) / o.sample_rate_hz;
  tone(o.omega_rad_s, t, f, g);
  f[8000] = 1e300;
  g[8001] = -1e300;
  g[17000] = std::nan("");
  Demodulator d(o);
  std::vector<SlowSample> out;
  // In batches, the corrupted one in the middle of a batch.
  for (size_t b = 0; b < t.size(); b += 1000)
    d.push(t.data() + b, f.data() + b, g.data() + b, 1000, out);
  EXPECT_EQ(d.counters().out_of_range, 2u);
  EXPECT_EQ(d.counters().non_finite, 1u);
  EXPECT_EQ(d.counters().restarts, 1u);  // one restart after the two adjacent bad samples
  EXPECT_EQ(d.segment(), 1u);
  ASSERT_FALSE(out.empty());
  double last_t = 0.0;
  for (const SlowSample& s : out) {
    ASSERT_TRUE(s.q.allFinite()) << s.t_s;
    EXPECT_LT((s.q - kEnvelope).cwiseAbs().maxCoeff(), 1e-5) << s.t_s;
    last_t = s.t_s;
  }
  // Good data after the restart reach the output up to the end (minus the group delay).
  EXPECT_GT(last_t, t.back() - 2.0 * d.latencyS());
}

TEST(DemodulatorRecovery, LimitIsAnOption) {
  DemodulatorOptions o;
  o.omega_rad_s = 85732.0;
  o.sample_rate_hz = 100000.0;
  o.output_rate_hz = 1000.0;
  SampleValidatorOptions v;
  v.sample_rate_hz = o.sample_rate_hz;
  v.max_abs_signal = 0.5;  // below the tone's peak 0.72: most samples are out of range
  SampleValidator validator(v);
  std::vector<double> t(200), f, g;
  for (size_t i = 0; i < t.size(); ++i) t[i] = double(i) / o.sample_rate_hz;
  tone(o.omega_rad_s, t, f, g);
  validator.screen(t.data(), f.data(), g.data(), t.size());
  size_t expected = 0;
  for (size_t i = 0; i < t.size(); ++i) expected += std::fabs(f[i]) > 0.5 || std::fabs(g[i]) > 0.5;
  EXPECT_EQ(validator.counters().out_of_range, expected);
  EXPECT_GT(expected, 10u);
  v.max_abs_signal = 0.0;
  EXPECT_FALSE(v.validate().empty());
}

}  // namespace
}  // namespace cvg_bench

// The demodulator's noise colour: the predicted correlation of slow samples l apart against white
// noise pushed through the real chain, and its round trip through a record's metadata.
#include "cvg_bench/core/demod/demodulator_noise.h"

#include <gtest/gtest.h>

#include <random>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace {

TEST(DemodulatorNoise, PredictedCorrelationMatchesWhiteNoiseThroughTheChain) {
  DemodulatorOptions o;
  o.omega_rad_s = 85732.0;
  o.sample_rate_hz = 100000.0;
  o.output_rate_hz = 1000.0;
  Demodulator demod(o);
  const std::vector<double> rho = outputNoiseCorrelation(demod.stages());
  ASSERT_GE(rho.size(), 3u);
  EXPECT_GT(rho[0], 0.3);  // passband 0.2, stopband 0.5 of the output rate: neighbours correlate
  EXPECT_LT(rho[1], 0.0);

  std::mt19937_64 gen(21);
  std::normal_distribution<double> n01;
  const size_t n = 3000000;  // ~30000 slow samples
  std::vector<double> t(n), f(n), g(n);
  for (size_t i = 0; i < n; ++i) {
    t[i] = static_cast<double>(i) / o.sample_rate_hz;
    f[i] = n01(gen);
    g[i] = n01(gen);
  }
  std::vector<SlowSample> out;
  demod.push(t, f, g, out);
  ASSERT_GT(out.size(), 25000u);
  double var = 0.0, cross = 0.0, lag[3] = {0.0, 0.0, 0.0};
  for (size_t i = 0; i < out.size(); ++i) {
    var += out[i].q.squaredNorm();
    cross += out[i].q[0] * out[i].q[1] + out[i].q[2] * out[i].q[3];
    for (size_t l = 1; l <= 3; ++l)
      if (i + l < out.size()) lag[l - 1] += out[i].q.dot(out[i + l].q);
  }
  // Standard error of an empirical correlation from ~1.2e5 products: ~0.006 (x2 for colour).
  for (int l = 0; l < 3; ++l) EXPECT_NEAR(lag[l] / var, rho[l], 0.025) << "lag " << l + 1;
  EXPECT_NEAR(2.0 * cross / var, 0.0, 0.025);  // in-phase and quadrature stay uncorrelated
}

TEST(DemodulatorNoise, DemodulatedRecordCarriesItsNoiseCorrelation) {
  RawRecord raw;
  raw.omega_rad_s = 85732.0;
  const double fs = 100000.0;
  for (int i = 0; i < 200000; ++i) {
    const double ti = i / fs;
    raw.t_s.push_back(ti);
    raw.f.push_back(std::cos(raw.omega_rad_s * ti));
    raw.g.push_back(0.5 * std::sin(raw.omega_rad_s * ti));
  }
  DemodulatorOptions o;
  o.output_rate_hz = 100.0;
  const SlowRecord rec = demodulateUniform(raw, o);
  const std::vector<double> rho = noiseCorrelationFromMetadata(rec.metadata);
  o.omega_rad_s = raw.omega_rad_s;
  o.sample_rate_hz = fs;
  const std::vector<double> expected = outputNoiseCorrelation(Demodulator(o).stages());
  ASSERT_EQ(rho.size(), expected.size());
  for (size_t l = 0; l < rho.size(); ++l) EXPECT_NEAR(rho[l], expected[l], 1e-5);
}

TEST(DemodulatorNoise, MalformedMetadataIsAnInputError) {
  RecordMetadata m;
  EXPECT_TRUE(noiseCorrelationFromMetadata(m).empty());
  m[kNoiseCorrelationKey] = "0.4 abc";
  EXPECT_THROW(noiseCorrelationFromMetadata(m), InputError);
  m[kNoiseCorrelationKey] = "0.4 1.5";
  EXPECT_THROW(noiseCorrelationFromMetadata(m), InputError);
  m[kNoiseCorrelationKey] = "0.4 -0.2";
  EXPECT_EQ(noiseCorrelationFromMetadata(m).size(), 2u);
}

}  // namespace
}  // namespace cvg_bench

// The Kaiser low-pass meets its stated passband ripple and stopband attenuation (checked by an
// independent brute-force response), and the polyphase decimator equals direct convolution.
#include "cvg_bench/core/demod/fir_lowpass.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace {

/// Brute-force zero-phase response (direct cos per tap), independent of lowpassResponse.
double bruteResponse(const std::vector<double>& h, double f, double fs) {
  const double c = 0.5 * double(h.size() - 1);
  long double sum = 0.0L;
  for (size_t k = 0; k < h.size(); ++k)
    sum += h[k] * std::cos(2.0L * M_PI * f / fs * (double(k) - c));
  return double(sum);
}

TEST(FirLowpass, MeetsSpecOnDenseGrid) {
  const std::vector<LowpassSpec> specs = {{1000.0, 20.0, 50.0, 120.0},
                                          {1000.0, 100.0, 130.0, 60.0},
                                          {48000.0, 20.0, 4700.0, 126.0},
                                          {500.0, 10.0, 25.0, 190.0}};
  for (const LowpassSpec& s : specs) {
    const std::vector<double> h = designKaiserLowpass(s);
    ASSERT_EQ(h.size() % 2, 1u);
    double sum = 0.0;
    for (size_t k = 0; k < h.size(); ++k) {
      sum += h[k];
      EXPECT_EQ(h[k], h[h.size() - 1 - k]);
    }
    EXPECT_NEAR(sum, 1.0, 1e-14);
    const double delta = std::pow(10.0, -s.attenuation_db / 20.0);
    // 20 points per side lobe over both bands, brute force (slack: float rounding of the sum).
    const double step = s.sample_rate_hz / h.size() / 20.0;
    double worst_pass = 0.0, worst_stop = 0.0;
    for (double f = 0.0; f <= s.passband_hz; f += step)
      worst_pass = std::max(worst_pass, std::abs(bruteResponse(h, f, s.sample_rate_hz) - 1.0));
    for (double f = s.stopband_hz; f <= 0.5 * s.sample_rate_hz; f += step)
      worst_stop = std::max(worst_stop, std::abs(bruteResponse(h, f, s.sample_rate_hz)));
    EXPECT_LE(worst_pass, delta * 1.001 + 1e-15) << s.attenuation_db << " dB";
    EXPECT_LE(worst_stop, delta * 1.001 + 1e-15) << s.attenuation_db << " dB";
    // Not over-designed: the bound is approached (within 12 dB) somewhere.
    EXPECT_GT(std::max(worst_pass, worst_stop), delta / 4.0);
    // The transition band is real: half-way it is neither passband nor stopband.
    const double mid = bruteResponse(h, 0.5 * (s.passband_hz + s.stopband_hz), s.sample_rate_hz);
    EXPECT_NEAR(mid, 0.5, 0.05);
  }
}

TEST(FirLowpass, BadSpecIsInputError) {
  EXPECT_THROW(designKaiserLowpass({1000.0, 50.0, 20.0, 100.0}), InputError);
  EXPECT_THROW(designKaiserLowpass({1000.0, 20.0, 600.0, 100.0}), InputError);
  EXPECT_THROW(designKaiserLowpass({0.0, 20.0, 50.0, 100.0}), InputError);
  LowpassSpec too_long{1e6, 10.0, 10.01, 120.0};
  too_long.max_taps = 1001;
  EXPECT_THROW(designKaiserLowpass(too_long), InputError);
  EXPECT_EQ(LowpassSpec{}.validate().size(), 2u);  // rate and stopband, all reported at once
}

TEST(PolyphaseDecimator4, EqualsDirectConvolutionInAnyChunking) {
  const std::vector<double> h = designKaiserLowpass({1000.0, 20.0, 80.0, 80.0});
  const int m = 7;
  const size_t n = 20000;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise;
  std::vector<double> x(4 * n), t(n);
  for (size_t i = 0; i < n; ++i) {
    t[i] = 5.0 + 1e-3 * i;
    for (int c = 0; c < 4; ++c) x[4 * i + c] = noise(rng);
  }
  PolyphaseDecimator4 one(h, m), chunked(h, m);
  std::vector<double> v1, t1, v2, t2;
  one.push(x.data(), t.data(), n, v1, t1);
  std::uniform_int_distribution<size_t> len(0, 9000);
  for (size_t i = 0; i < n;) {
    const size_t k = std::min(n - i, len(rng));
    chunked.push(x.data() + 4 * i, t.data() + i, k, v2, t2);
    i += k;
  }
  const size_t nt = h.size();
  const size_t expected = (n - nt) / m + 1;
  ASSERT_EQ(t1.size(), expected);
  ASSERT_EQ(t2.size(), expected);
  for (size_t k = 0; k < expected; ++k) {
    const size_t end = nt - 1 + k * m;
    EXPECT_EQ(t1[k], t[end - nt / 2]);  // centre sample: group delay exactly corrected
    EXPECT_EQ(t2[k], t1[k]);
    for (int c = 0; c < 4; ++c) {
      double ref = 0.0;
      for (size_t j = 0; j < nt; ++j) ref += h[j] * x[4 * (end - j) + c];
      EXPECT_NEAR(v1[4 * k + c], ref, 1e-13);
      EXPECT_NEAR(v2[4 * k + c], v1[4 * k + c], 1e-13);
    }
  }
}

}  // namespace
}  // namespace cvg_bench

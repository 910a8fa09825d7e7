// Uniform demodulator: the convention of (2.4), accuracy against the stated filter bounds, exact
// timestamps, streaming independence, and every bad-input case counted without a phase error.
#include "cvg_bench/core/demod/demodulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <functional>
#include <random>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace {

using Envelope = std::function<Eigen::Vector4d(double)>;

/// f = p1 sin(W t) + q1 cos(W t), g likewise (2.4); the phase in long double, independently of
/// the demodulator's reference.
void synthesize(const Envelope& env, double w, const std::vector<double>& t, std::vector<double>& f,
                std::vector<double>& g) {
  f.resize(t.size());
  g.resize(t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    const long double ph = static_cast<long double>(w) * t[i];
    const double c = static_cast<double>(std::cos(ph)), s = static_cast<double>(std::sin(ph));
    const Eigen::Vector4d q = env(t[i]);
    f[i] = q[1] * s + q[0] * c;
    g[i] = q[3] * s + q[2] * c;
  }
}

std::vector<double> grid(double t0, double fs, size_t n) {
  std::vector<double> t(n);
  for (size_t i = 0; i < n; ++i) t[i] = t0 + double(i) / fs;
  return t;
}

DemodulatorOptions memsOptions() {
  DemodulatorOptions o;
  o.omega_rad_s = 85732.0;  // the paper's MEMS ring (section 4)
  o.sample_rate_hz = 100000.0;
  o.output_rate_hz = 100.0;
  return o;
}

double maxError(const std::vector<SlowSample>& out, const Envelope& env) {
  double e = 0.0;
  for (const SlowSample& s : out) e = std::max(e, (s.q - env(s.t_s)).cwiseAbs().maxCoeff());
  return e;
}

TEST(Demodulator, ExactToneGivesItsEnvelopeAfterHours) {
  const Eigen::Vector4d q(0.8, -0.35, 0.12, 0.05);
  const Envelope env = [&](double) { return q; };
  DemodulatorOptions o = memsOptions();
  o.attenuation_db = 190.0;     // image at 2W below 3e-10
  o.sample_rate_hz = 131072.0;  // 2^17 Hz: timestamps exactly representable after 10 h
  o.output_rate_hz = 128.0;
  Demodulator demod(o);
  // Ten hours into a run: the reference phase must not lose precision. (With timestamps that are
  // not representable, the phase is limited by their rounding: W x 3.6e-12 s = 3e-7 rad here.)
  const std::vector<double> t = grid(36000.0, o.sample_rate_hz, 140000);
  std::vector<double> f, g;
  synthesize(env, o.omega_rad_s, t, f, g);
  std::vector<SlowSample> out;
  demod.push(t, f, g, out);
  ASSERT_GE(out.size(), 40u);
  EXPECT_LT(maxError(out, env), 1e-9);
  // Output grid: exactly the input timestamps, at the output rate.
  for (size_t k = 1; k < out.size(); ++k)
    EXPECT_NEAR(out[k].t_s - out[k - 1].t_s, 1.0 / demod.outputRateHz(), 1e-9);
  EXPECT_EQ(demod.counters().accepted, t.size());
  EXPECT_EQ(demod.counters().rejected(), 0u);
}

TEST(Demodulator, DefaultFilterErrorWithinStatedBound) {
  const Eigen::Vector4d q(0.8, -0.35, 0.12, 0.05);
  const Envelope env = [&](double) { return q; };
  const DemodulatorOptions o = memsOptions();
  Demodulator demod(o);
  const std::vector<double> t = grid(0.0, o.sample_rate_hz, 60000);
  std::vector<double> f, g;
  synthesize(env, o.omega_rad_s, t, f, g);
  std::vector<SlowSample> out;
  demod.push(t, f, g, out);
  ASSERT_FALSE(out.empty());
  // The only error is the 2W image, attenuated by at least attenuation_db.
  const double delta = std::pow(10.0, -o.attenuation_db / 20.0);
  EXPECT_LT(maxError(out, env), delta * q.head<2>().norm());
  EXPECT_NEAR(demod.outputRateHz(), 100.0, 1e-12);
  EXPECT_NEAR(demod.passbandHz(), 20.0, 1e-12);
  EXPECT_NEAR(demod.stopbandHz(), 50.0, 1e-12);
  EXPECT_NEAR(out.front().t_s, demod.groupDelayS(), 1e-12);
}

TEST(Demodulator, RotatingEnvelopeTrackedWithinPassbandError) {
  // Envelope made of lines inside the passband (|nu| <= 20 Hz): each is passed with |gain - 1|
  // <= delta, its 2W image attenuated below delta: error <= 2 delta sum |A|.
  const std::complex<double> a0(0.7, 0.2), a1(0.3, -0.1), b0(0.1, 0.05), b1(-0.2, 0.15);
  const double nu1 = 13.0, nu2 = -19.5;  // Hz
  const Envelope env = [&](double t) {
    const std::complex<double> a = a0 + a1 * std::polar(1.0, 2 * M_PI * nu1 * t);
    const std::complex<double> b = b0 + b1 * std::polar(1.0, 2 * M_PI * nu2 * t);
    return Eigen::Vector4d(a.real(), a.imag(), b.real(), b.imag());
  };
  const DemodulatorOptions o = memsOptions();
  Demodulator demod(o);
  const std::vector<double> t = grid(100.0, o.sample_rate_hz, 100000);
  std::vector<double> f, g;
  synthesize(env, o.omega_rad_s, t, f, g);
  std::vector<SlowSample> out;
  demod.push(t, f, g, out);
  ASSERT_GE(out.size(), 50u);
  const double delta = std::pow(10.0, -o.attenuation_db / 20.0);
  const double bound = 2.0 * delta * (std::abs(a0) + std::abs(a1) + std::abs(b0) + std::abs(b1));
  EXPECT_LT(maxError(out, env), bound);
  // A line in the stopband (nu = 60 Hz) is suppressed below delta.
  const Envelope stop = [&](double t) {
    const std::complex<double> a = std::polar(1.0, 2 * M_PI * 60.0 * t);
    return Eigen::Vector4d(a.real(), a.imag(), 0.0, 0.0);
  };
  synthesize(stop, o.omega_rad_s, t, f, g);
  Demodulator demod2(o);
  out.clear();
  demod2.push(t, f, g, out);
  ASSERT_FALSE(out.empty());
  for (const SlowSample& s : out) EXPECT_LT(s.q.head<2>().norm(), delta);
}

TEST(Demodulator, DecayingEnvelopeTrackedWithinMomentBound) {
  // a(t) = A exp(-t / tau): a symmetric filter gives a(t) (1 + m2 / (2 tau^2) + ...), m2 the
  // filter's second moment <= group_delay^2 x sum|h| (sum|h| < 1.5 for these windows).
  const double tau = 0.5;
  const Envelope env = [&](double t) -> Eigen::Vector4d {
    return Eigen::Vector4d(0.9, 0.3, -0.2, 0.1) * std::exp(-t / tau);
  };
  const DemodulatorOptions o = memsOptions();
  Demodulator demod(o);
  const std::vector<double> t = grid(0.0, o.sample_rate_hz, 100000);
  std::vector<double> f, g;
  synthesize(env, o.omega_rad_s, t, f, g);
  std::vector<SlowSample> out;
  demod.push(t, f, g, out);
  ASSERT_FALSE(out.empty());
  const double gd = demod.groupDelayS();
  const double rel = 1.5 * gd * gd / (2.0 * tau * tau) + 2e-6;
  for (const SlowSample& s : out)
    EXPECT_LT((s.q - env(s.t_s)).norm(), rel * env(s.t_s).norm()) << s.t_s;
}

TEST(Demodulator, BatchSplittingDoesNotChangeTheResult) {
  const Envelope env = [](double t) { return Eigen::Vector4d(1.0, 0.2 * t, -0.3, 0.1); };
  const DemodulatorOptions o = memsOptions();
  const std::vector<double> t = grid(3.0, o.sample_rate_hz, 50000);
  std::vector<double> f, g;
  synthesize(env, o.omega_rad_s, t, f, g);
  Demodulator whole(o), pieces(o);
  std::vector<SlowSample> a, b;
  whole.push(t, f, g, a);
  std::mt19937 rng(5);
  std::uniform_int_distribution<size_t> len(1, 3000);
  for (size_t i = 0; i < t.size();) {
    const size_t k = std::min(t.size() - i, len(rng));
    pieces.push(t.data() + i, f.data() + i, g.data() + i, k, b);
    i += k;
  }
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].t_s, b[k].t_s);
    // Anchors fall elsewhere: the difference is W x timestamp rounding (85732 x 4e-16 s).
    EXPECT_LT((a[k].q - b[k].q).cwiseAbs().maxCoeff(), 1e-10);
  }
  pieces.push(t.data(), f.data(), g.data(), 0, b);
  EXPECT_EQ(pieces.counters().empty_batches, 1u);
}

class DemodulatorBadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    o_ = memsOptions();
    o_.output_rate_hz = 1000.0;  // short filters: short records
    env_ = [](double) { return Eigen::Vector4d(0.6, 0.4, -0.1, 0.2); };
    t_ = grid(10.0, o_.sample_rate_hz, 20000);
    synthesize(env_, o_.omega_rad_s, t_, f_, g_);
  }
  /// Every output finite and equal to the envelope (no phase shift anywhere).
  void expectClean(const std::vector<SlowSample>& out) {
    ASSERT_FALSE(out.empty());
    for (const SlowSample& s : out) {
      ASSERT_TRUE(s.q.allFinite());
      EXPECT_LT((s.q - env_(s.t_s)).cwiseAbs().maxCoeff(), 1e-5) << s.t_s;
    }
  }
  DemodulatorOptions o_;
  Envelope env_;
  std::vector<double> t_, f_, g_;
};

TEST_F(DemodulatorBadInput, NonFiniteValueIsCountedAndFilled) {
  Demodulator d(o_);
  f_[15000] = std::nan("");
  g_[15001] = INFINITY;
  t_[15003] = std::nan("");
  std::vector<SlowSample> out;
  d.push(t_, f_, g_, out);
  EXPECT_EQ(d.counters().non_finite, 3u);
  EXPECT_EQ(d.counters().missing_filled, 3u);
  EXPECT_EQ(d.counters().restarts, 0u);
  EXPECT_EQ(d.segment(), 0u);
  expectClean(out);
}

TEST_F(DemodulatorBadInput, DuplicateNonMonotonicAndOffGridAreDropped) {
  Demodulator d(o_);
  std::vector<double> t = t_, f = f_, g = g_;
  t[12000] = t[11999];                  // duplicate
  t[13000] = t[12990];                  // out of order (small step back)
  t[14000] += 0.4 / o_.sample_rate_hz;  // off the sampling grid
  std::vector<SlowSample> out;
  d.push(t, f, g, out);
  EXPECT_EQ(d.counters().duplicate_timestamp, 1u);
  EXPECT_EQ(d.counters().non_monotonic, 1u);
  EXPECT_EQ(d.counters().off_grid, 1u);
  EXPECT_EQ(d.counters().missing_filled, 3u);  // each dropped slot is filled
  EXPECT_EQ(d.counters().accepted, t.size() - 3);
  expectClean(out);
}

TEST_F(DemodulatorBadInput, GapRestartsCleanlyAndSaysSo) {
  Demodulator d(o_);
  std::vector<double> t = t_;
  for (size_t i = 10000; i < t.size(); ++i) t[i] += 0.25;  // 25000 periods missing
  synthesize(env_, o_.omega_rad_s, t, f_, g_);
  std::vector<SlowSample> out;
  d.push(t, f_, g_, out);
  EXPECT_EQ(d.counters().gaps, 1u);
  EXPECT_EQ(d.counters().restarts, 1u);
  EXPECT_EQ(d.segment(), 1u);
  EXPECT_NE(d.lastEvent().find("gap"), std::string::npos);
  expectClean(out);
  EXPECT_EQ(out.front().segment, 0u);
  EXPECT_EQ(out.back().segment, 1u);
  // No output straddles the gap.
  for (const SlowSample& s : out) EXPECT_TRUE(s.t_s < t[9999] || s.t_s > t[10000]);
}

TEST_F(DemodulatorBadInput, BackwardJumpResets) {
  Demodulator d(o_);
  std::vector<SlowSample> out;
  d.push(t_, f_, g_, out);
  const size_t first = out.size();
  d.push(t_, f_, g_, out);  // the bag loops: the same data again
  EXPECT_EQ(d.counters().backward_resets, 1u);
  EXPECT_EQ(d.counters().restarts, 1u);
  EXPECT_NE(d.lastEvent().find("back"), std::string::npos);
  ASSERT_EQ(out.size(), 2 * first);
  for (size_t k = 0; k < first; ++k) {
    EXPECT_EQ(out[first + k].t_s, out[k].t_s);
    EXPECT_EQ(out[first + k].segment, 1u);
    EXPECT_LT((out[first + k].q - out[k].q).cwiseAbs().maxCoeff(), 1e-13);
  }
}

TEST_F(DemodulatorBadInput, RateMismatchAndEmptyBatchesCounted) {
  Demodulator d(o_);
  std::vector<SlowSample> out;
  d.push(nullptr, nullptr, nullptr, 0, out);
  EXPECT_EQ(d.counters().empty_batches, 1u);
  // Data at half the configured rate: every interval is two periods.
  std::vector<double> t = grid(10.0, 0.5 * o_.sample_rate_hz, 1000), f, g;
  synthesize(env_, o_.omega_rad_s, t, f, g);
  d.push(t, f, g, out);
  EXPECT_EQ(d.counters().rate_mismatch_batches, 1u);
  EXPECT_EQ(d.counters().rate_mismatch_samples, 1000u);
  EXPECT_EQ(d.counters().accepted, 0u);
  EXPECT_TRUE(out.empty());
}

TEST_F(DemodulatorBadInput, MissingSamplesBeforeFirstOutputRestart) {
  Demodulator d(o_);
  std::vector<double> t, f, g;
  for (size_t i = 0; i < t_.size(); ++i) {
    if (i >= 100 && i < 103) continue;  // three samples dropped during start-up
    t.push_back(t_[i]);
    f.push_back(f_[i]);
    g.push_back(g_[i]);
  }
  std::vector<SlowSample> out;
  d.push(t, f, g, out);
  EXPECT_EQ(d.counters().restarts, 1u);
  EXPECT_EQ(d.counters().missing_filled, 0u);
  expectClean(out);
}

TEST(DemodulatorOptionsTest, ValidateReportsEveryProblem) {
  DemodulatorOptions o;
  o.output_rate_hz = -1.0;
  o.attenuation_db = 5.0;
  const auto p = o.validate();
  EXPECT_EQ(p.size(), 4u);  // omega, sample rate, output rate, attenuation
  EXPECT_THROW(Demodulator{o}, InputError);
  DemodulatorOptions nyq = memsOptions();
  nyq.sample_rate_hz = 20000.0;  // 13.6 kHz reference above Nyquist
  EXPECT_FALSE(nyq.validate().empty());
}

TEST(Demodulator, WholeRecordAndSamplingSummary) {
  RawRecord raw;
  const DemodulatorOptions o = memsOptions();
  raw.t_s = grid(0.0, o.sample_rate_hz, 50000);
  const Envelope env = [](double) { return Eigen::Vector4d(0.5, 0.1, 0.0, -0.2); };
  synthesize(env, o.omega_rad_s, raw.t_s, raw.f, raw.g);
  raw.omega_rad_s = o.omega_rad_s;
  const SamplingSummary s = summarizeSampling(raw.t_s);
  EXPECT_TRUE(s.uniform);
  EXPECT_NEAR(s.median_interval_s, 1e-5, 1e-15);
  DemodulatorOptions auto_rate;
  auto_rate.output_rate_hz = 100.0;
  const SlowRecord rec = demodulateUniform(raw, auto_rate);
  EXPECT_EQ(rec.omega_rad_s, o.omega_rad_s);
  EXPECT_EQ(rec.metadata.at("mode"), "free_decay");
  ASSERT_FALSE(rec.q.empty());
  for (const auto& q : rec.q) EXPECT_LT((q - env(0.0)).cwiseAbs().maxCoeff(), 1e-6);
  raw.t_s.resize(1000);
  raw.f.resize(1000);
  raw.g.resize(1000);
  EXPECT_THROW(demodulateUniform(raw, auto_rate), InputError);  // shorter than the filter
  std::vector<double> jitter = grid(0.0, 1000.0, 500);
  std::mt19937 rng(1);
  std::normal_distribution<double> n(0.0, 1e-4);
  for (double& x : jitter) x += n(rng);
  EXPECT_FALSE(summarizeSampling(jitter).uniform);
}

}  // namespace
}  // namespace cvg_bench

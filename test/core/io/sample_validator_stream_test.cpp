// SampleValidator on a clean 300 kHz stream formed as the demodulator node forms it: each batch's
// first timestamp rounded to whole nanoseconds (header.stamp), then t_i = t0 + i / rate. Every
// sample must be accepted through the vectorised fast path (countIrregular, x86-64-v3 clone where
// the CPU has it), including the non-inlined build used by the -O0 check of make test-asan.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "cvg_bench/core/io/sample_validator.h"

namespace cvg_bench {
namespace {

TEST(SampleValidatorStream, Clean300kHzBatchesAllAccepted) {
  const double rate_hz = 300000.0, dt_s = 1.0 / rate_hz;
  SampleValidatorOptions o;
  o.sample_rate_hz = rate_hz;
  SampleValidator v(o);
  const size_t batch = 3000, total = 60000;  // 100 batches a second of stream, 0.2 s
  for (size_t begin = 0; begin < total; begin += batch) {
    const int64_t stamp_ns = std::llround(static_cast<double>(begin) / rate_hz * 1e9);
    const double t0_s = static_cast<double>(stamp_ns) * 1e-9;
    std::vector<double> t(batch), f(batch), g(batch);
    for (size_t i = 0; i < batch; ++i) {
      t[i] = t0_s + static_cast<double>(i) * dt_s;
      f[i] = 0.8 * std::cos(2.0 * M_PI * 14000.0 * t[i]);
      g[i] = 0.1 * std::sin(2.0 * M_PI * 14000.0 * t[i]);
    }
    const auto runs = v.screen(t.data(), f.data(), g.data(), batch);
    ASSERT_EQ(runs.size(), 1u) << "batch starting at sample " << begin;
    EXPECT_EQ(runs[0].begin, 0u);
    EXPECT_EQ(runs[0].end, batch);
    EXPECT_EQ(runs[0].start, begin == 0 ? RunStart::kRestartFirst : RunStart::kContinue);
  }
  const SampleCounters& c = v.counters();
  EXPECT_EQ(c.accepted, total);
  EXPECT_EQ(c.rejected(), 0u);
  EXPECT_EQ(c.off_grid + c.gaps + c.restarts + c.rate_mismatch_batches, 0u);
}

// One bad sample in the middle of a clean batch: the vector path must see it (it falls back to
// the per-sample path), at every position modulo the vector width.
TEST(SampleValidatorStream, OneNonFiniteSampleFoundAtEveryLane) {
  for (size_t bad = 1; bad < 9; ++bad) {
    SampleValidatorOptions o;
    o.sample_rate_hz = 300000.0;
    SampleValidator v(o);
    std::vector<double> t(13), f(13, 0.5), g(13, -0.5);
    for (size_t i = 0; i < t.size(); ++i) t[i] = 2.0 + static_cast<double>(i) / 300000.0;
    f[bad] = NAN;
    const auto runs = v.screen(t.data(), f.data(), g.data(), t.size());
    EXPECT_EQ(v.counters().non_finite, 1u) << "bad sample " << bad;
    EXPECT_EQ(v.counters().accepted, 12u) << "bad sample " << bad;
    ASSERT_EQ(runs.size(), 2u) << "bad sample " << bad;
    EXPECT_EQ(runs[1].start, RunStart::kFillMissing);
  }
}

}  // namespace
}  // namespace cvg_bench

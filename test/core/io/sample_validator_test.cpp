// SampleValidator on its own: each interval class of the header maps to its counter and run start.
#include "cvg_bench/core/io/sample_validator.h"

#include <gtest/gtest.h>

#include <cmath>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace {

SampleValidator makeValidator() {
  SampleValidatorOptions o;
  o.sample_rate_hz = 1000.0;
  return SampleValidator(o);
}

TEST(SampleValidator, ClassifiesEveryInterval) {
  SampleValidator v = makeValidator();
  // 20 samples on the grid up to 1.000, then: on grid; duplicate; out of order; 3 periods (2
  // missing); 0.4 periods (off grid); on grid after the previous accepted; gap; back jump.
  std::vector<double> t;
  for (int i = 20; i > 0; --i) t.push_back(1.0 - 1e-3 * i);
  for (double x : {1.000, 1.001, 1.001, 1.0005, 1.004, 1.0044, 1.005, 1.100, 0.5}) t.push_back(x);
  const std::vector<double> f(t.size(), 0.0), g(t.size(), 0.0);
  const auto runs = v.screen(t.data(), f.data(), g.data(), t.size());
  ASSERT_EQ(runs.size(), 5u);
  EXPECT_EQ(runs[0].start, RunStart::kRestartFirst);
  EXPECT_EQ(runs[0].begin, 0u);
  EXPECT_EQ(runs[0].end, 22u);
  EXPECT_EQ(runs[1].start, RunStart::kFillMissing);
  EXPECT_EQ(runs[1].missing, 2);
  EXPECT_EQ(runs[1].previous_t, 1.001);
  EXPECT_EQ(runs[2].start, RunStart::kContinue);  // 1.005 is one period after 1.004
  EXPECT_EQ(runs[2].begin, 26u);
  EXPECT_EQ(runs[3].start, RunStart::kRestartGap);
  EXPECT_EQ(runs[4].start, RunStart::kResetBackward);
  const SampleCounters& c = v.counters();
  EXPECT_EQ(c.accepted, 26u);
  EXPECT_EQ(c.duplicate_timestamp, 1u);
  EXPECT_EQ(c.non_monotonic, 1u);
  EXPECT_EQ(c.off_grid, 1u);
  EXPECT_EQ(c.gaps, 1u);
  EXPECT_EQ(c.backward_resets, 1u);
  EXPECT_EQ(c.rejected(), 3u);
}

TEST(SampleValidator, FastPathAndNonFiniteAndRateMismatch) {
  SampleValidator v = makeValidator();
  std::vector<double> t(100), f(100, 1.0), g(100, 2.0);
  for (size_t i = 0; i < t.size(); ++i) t[i] = 3.0 + 1e-3 * i;
  auto runs = v.screen(t.data(), f.data(), g.data(), t.size());
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].end, 100u);
  for (double& x : t) x += 0.1;  // the next batch continues the stream
  g[50] = INFINITY;
  runs = v.screen(t.data(), f.data(), g.data(), t.size());
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[0].start, RunStart::kContinue);
  EXPECT_EQ(runs[1].start, RunStart::kFillMissing);
  EXPECT_EQ(runs[1].missing, 1);
  EXPECT_EQ(v.counters().non_finite, 1u);
  std::vector<double> slow(20);
  for (size_t i = 0; i < slow.size(); ++i) slow[i] = 4.0 + 3e-3 * i;  // a third of the rate
  runs = v.screen(slow.data(), f.data(), g.data(), slow.size());
  EXPECT_TRUE(runs.empty());
  EXPECT_EQ(v.counters().rate_mismatch_batches, 1u);
  EXPECT_EQ(v.counters().rate_mismatch_samples, 20u);
  EXPECT_TRUE(v.screen(nullptr, nullptr, nullptr, 0).empty());
  EXPECT_EQ(v.counters().empty_batches, 1u);
  EXPECT_EQ(v.counters().asMap().size(), 13u);  // incl. out_of_range
}

TEST(SampleValidator, OptionsValidated) {
  SampleValidatorOptions o;
  o.interval_tolerance = 0.7;
  o.gap_periods = 1.0;
  EXPECT_EQ(o.validate().size(), 3u);
  EXPECT_THROW(SampleValidator{o}, InputError);
}

}  // namespace
}  // namespace cvg_bench

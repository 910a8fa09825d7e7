// The ring-down law registry (ringdown_laws.h): every law carries the fields its consumers read
// (the fit, the explain stage, the CLI), and the explain stage's default candidates are the
// registry's non-baseline laws in its order. A law added without them fails here.
#include "cvg_bench/core/single_mode/ringdown_laws.h"

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/single_mode/ringdown_causes.h"
#include "cvg_bench/core/single_mode/ringdown_models.h"

namespace cvg_bench {
namespace {

/// The keys a cause_text template names ({KEY} and {KEY.value}); false when a brace is unmatched
/// or a key is empty.
bool templateKeys(const std::string& text, std::vector<std::string>* keys) {
  size_t at = 0;
  while (true) {
    const size_t open = text.find('{', at);
    const size_t close_any = text.find('}', at);
    if (open == std::string::npos) return close_any == std::string::npos;
    const size_t close = text.find('}', open);
    if (close == std::string::npos || close_any < open) return false;
    std::string key = text.substr(open + 1, close - open - 1);
    if (key.find('{') != std::string::npos) return false;
    const std::string suffix = ".value";
    if (key.size() > suffix.size() &&
        key.compare(key.size() - suffix.size(), suffix.size(), suffix) == 0)
      key.resize(key.size() - suffix.size());
    if (key.empty()) return false;
    keys->push_back(key);
    at = close + 1;
  }
}

TEST(RingdownLaws, EveryLawHasTheFieldsItsConsumersRead) {
  const std::vector<RingdownLaw>& laws = ringdownLaws();
  ASSERT_FALSE(laws.empty());
  EXPECT_EQ(laws.front().kind, RingdownLawKind::kBaseline) << "the baseline comes first";
  int baselines = 0;
  std::set<std::string> names;
  std::set<int> amplitude_powers;
  for (const RingdownLaw& law : laws) {
    ASSERT_NE(law.name, nullptr);
    SCOPED_TRACE(law.name);
    EXPECT_STRNE(law.name, "");
    EXPECT_TRUE(names.insert(law.name).second) << "duplicate name";
    EXPECT_EQ(findRingdownLaw(law.name), &law);
    EXPECT_EQ(&ringdownLaw(law.name), &law);
    EXPECT_FALSE(law.parameters.empty());
    EXPECT_NE(law.log_amplitude, nullptr);
    EXPECT_NE(law.starts, nullptr);
    EXPECT_NE(law.canonical_order, nullptr);
    EXPECT_NE(law.readout, nullptr);
    EXPECT_NE(law.physical_check, nullptr);
    ASSERT_NE(law.cause_text, nullptr);
    EXPECT_EQ(law.is_extension, law.kind != RingdownLawKind::kBaseline);
    const std::string text = law.cause_text;
    switch (law.kind) {
      case RingdownLawKind::kBaseline:
        ++baselines;
        EXPECT_TRUE(text.empty());
        EXPECT_EQ(law.amplitude_power, 0);
        EXPECT_FALSE(law.searched_frequency);
        EXPECT_FALSE(law.q_checked_against_baseline);
        break;
      case RingdownLawKind::kAmplitudeLaw:
        // The explain stage reads the amplitude coefficient at index 2 ({a, g0, g}); the CLI maps
        // the power to the generator's coefficient, so no two amplitude laws share one.
        EXPECT_EQ(law.parameters.size(), 3u);
        EXPECT_GT(law.amplitude_power, 0);
        EXPECT_TRUE(amplitude_powers.insert(law.amplitude_power).second);
        EXPECT_FALSE(law.q_checked_against_baseline) << "Q0 differs from the line's by design";
        break;
      case RingdownLawKind::kShapeAlternative:
        EXPECT_EQ(law.amplitude_power, 0);
        break;
    }
    if (law.kind == RingdownLawKind::kBaseline) continue;
    EXPECT_FALSE(text.empty()) << "a candidate needs the sentence the explanation prints";
    EXPECT_EQ(text.back(), ' ') << "sentences are joined with a space";
    std::vector<std::string> keys;
    EXPECT_TRUE(templateKeys(text, &keys)) << text;
  }
  EXPECT_EQ(baselines, 1);
}

TEST(RingdownLaws, CauseTextNamesOnlyValuesTheReadoutWrites) {
  for (const RingdownLaw& law : ringdownLaws()) {
    SCOPED_TRACE(law.name);
    std::vector<std::string> keys;
    if (!templateKeys(law.cause_text, &keys) || keys.empty()) continue;
    const int np = static_cast<int>(law.parameters.size());
    RingdownFit fit;
    fit.model = law.name;
    fit.names = law.parameters;
    fit.frequency_hz = 100.0;
    fit.p = Eigen::VectorXd::Constant(np, 0.5);
    fit.cov_hac = 1e-4 * Eigen::MatrixXd::Identity(np, np);
    fit.cov_crb = fit.cov_hac;
    const RingdownReadout r{law, fit, 1.96, 2.0, M_PI * 100.0 * 2.0, 1.0, 0.0, 1.0};
    law.readout(r);
    for (const std::string& k : keys) EXPECT_EQ(fit.derived.count(k), 1u) << k;
  }
}

TEST(RingdownLaws, ZeroDampingIsNeverPhysicalForACandidate) {
  const RingdownPlausibilityOptions o;
  for (const RingdownLaw& law : ringdownLaws()) {
    if (law.kind == RingdownLawKind::kBaseline) continue;
    SCOPED_TRACE(law.name);
    const Eigen::VectorXd p = Eigen::VectorXd::Zero(static_cast<int>(law.parameters.size()));
    EXPECT_FALSE(law.physical_check(p, o).empty());
  }
}

TEST(RingdownLaws, DefaultCandidatesAreTheNonBaselineLawsInRegistryOrder) {
  std::vector<std::string> expected;
  for (const RingdownLaw& law : ringdownLaws())
    if (law.kind != RingdownLawKind::kBaseline) expected.push_back(law.name);
  EXPECT_EQ(RingdownExplainOptions().candidates, expected);
  EXPECT_EQ(ringdownExtensionNames(), expected);
}

TEST(RingdownLaws, UnknownNameIsNotFound) {
  EXPECT_EQ(findRingdownLaw("no_such_law"), nullptr);
  EXPECT_THROW(ringdownLaw("no_such_law"), InputError);
}

}  // namespace
}  // namespace cvg_bench

// The registry of one-mode response terms (response_laws.h): every term has its entries, parses
// back from its name and sets its own flag and coefficient only; the combinations (explain's
// candidates) are every subset of the terms once, linear first, and their names parse back.
#include "cvg_bench/core/single_mode/response_laws.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace cvg_bench {
namespace {

int flagsSet(const ResponseTerms& t) {
  return (t.backbone ? 1 : 0) + (t.width_growth ? 1 : 0) + (t.background_slope ? 1 : 0);
}

TEST(ResponseLaws, EveryTermHasItsEntries) {
  const std::vector<ResponseLaw>& laws = responseLaws();
  ASSERT_FALSE(laws.empty());
  std::set<std::string> names, keys;
  for (const ResponseLaw& law : laws) {
    ASSERT_NE(law.name, nullptr);
    const std::string name = law.name;
    ASSERT_NE(law.flag, nullptr) << name;
    ASSERT_NE(law.coefficient, nullptr) << name;
    ASSERT_NE(law.derived_key, nullptr) << name;
    ASSERT_NE(law.unit, nullptr) << name;
    ASSERT_NE(law.description, nullptr) << name;
    ASSERT_NE(law.verdict_words, nullptr) << name;
    EXPECT_FALSE(name.empty());
    EXPECT_EQ(name.find('+'), std::string::npos) << name;
    EXPECT_NE(name, kLinearResponseModel);
    EXPECT_FALSE(std::string(law.derived_key).empty()) << name;
    EXPECT_FALSE(std::string(law.unit).empty()) << name;
    EXPECT_FALSE(std::string(law.description).empty()) << name;
    EXPECT_FALSE(std::string(law.verdict_words(-1.0)).empty()) << name;
    EXPECT_FALSE(std::string(law.verdict_words(1.0)).empty()) << name;
    EXPECT_NE(law.flag, &ResponseTerms::background_slope) << name;
    if (law.model_term_key) {
      EXPECT_NE(law.model_term_per_unit, 0.0) << name;
    }
    EXPECT_TRUE(names.insert(name).second) << "duplicate name " << name;
    EXPECT_TRUE(keys.insert(law.derived_key).second) << "duplicate key " << law.derived_key;
    EXPECT_EQ(findResponseLaw(name), &law);
  }
  EXPECT_EQ(findResponseLaw(kLinearResponseModel), nullptr);
  EXPECT_EQ(findResponseLaw("xi_diff"), nullptr);
}

TEST(ResponseLaws, EachTermParsesBackAndSetsOnlyItsOwnFlagAndCoefficient) {
  for (const ResponseLaw& law : responseLaws()) {
    const ResponseTerms t = parseResponseTerms(law.name);
    EXPECT_TRUE(t.*law.flag) << law.name;
    EXPECT_EQ(flagsSet(t), 1) << law.name;
    EXPECT_EQ(responseTermCount(t), 1) << law.name;
    EXPECT_EQ(t.name(), law.name);
    ResponseParams p;
    p.*law.coefficient = 1.0;
    int set = 0;
    for (const ResponseLaw& other : responseLaws()) set += p.*other.coefficient != 0.0 ? 1 : 0;
    EXPECT_EQ(set, 1) << law.name << " shares its coefficient with another term";
  }
}

TEST(ResponseLaws, CombinationsAreEverySubsetOnceLinearFirst) {
  const std::vector<ResponseTerms> all = responseTermCombinations();
  const size_t n_laws = responseLaws().size();
  ASSERT_EQ(all.size(), size_t{1} << n_laws);
  EXPECT_EQ(all.front().name(), kLinearResponseModel);
  EXPECT_EQ(responseTermCount(all.back()), static_cast<int>(n_laws));
  std::set<std::string> names;
  for (const ResponseTerms& t : all) {
    EXPECT_FALSE(t.background_slope);
    EXPECT_TRUE(names.insert(t.name()).second) << "duplicate " << t.name();
    const ResponseTerms back = parseResponseTerms(t.name());
    for (const ResponseLaw& law : responseLaws())
      EXPECT_EQ(back.*law.flag, t.*law.flag) << t.name();
  }
  // Two terms: the candidates in the order explain reports them.
  if (n_laws == 2) {
    EXPECT_EQ(all[1].name(), responseLaws()[0].name);
    EXPECT_EQ(all[2].name(), responseLaws()[1].name);
  }
}

TEST(ResponseLaws, UnknownTermsAreRefusedWithTheKnownOnesListed) {
  try {
    parseResponseTerms("mu");
    FAIL() << "mu parsed";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    for (const ResponseTerms& t : responseTermCombinations())
      EXPECT_NE(what.find(t.name()), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace cvg_bench

// Every registered ModelTerm carries what its consumers need (issue #23: a term owns everything
// about itself): explain's candidacy (cause, unit, signature, modes, a unique rank), the
// amplitude-law class that identifiability and explain's caveat read, and a description for the
// help texts. The class is checked against the term's own averaged equations, so a new
// amplitude-dependent term that forgets to say so fails here. (The drift effect of each term is
// checked by orbit_rates_chain_rule_test.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/diagnose/candidate_extensions.h"
#include "cvg_bench/core/model/model_term.h"

namespace cvg_bench {
namespace {

/// How the term's averaged force scales with the amplitude: 1 linear, 0 independent (a drive),
/// otherwise faster (an amplitude law).
double amplitudeScaling(const ModelTerm& t) {
  const Eigen::Vector4d q(0.31, 0.52, -0.17, 0.23);
  SlowContext ctx;
  ctx.t_s = 3.0;
  Eigen::MatrixXd a(4, t.numParameters()), b(4, t.numParameters());
  t.averagedColumns(q, ctx, a);
  t.averagedColumns(2.0 * q, ctx, b);
  return std::log2(b.norm() / a.norm());
}

TEST(ModelTermRegistry, EveryTermIsACandidateWhereItApplies) {
  std::set<int> ranks;
  for (const auto& name : knownModelTermNames()) {
    const ModelTermPtr t = makeModelTerm(name);
    EXPECT_FALSE(t->description().empty()) << name;
    bool own = false;
    for (const auto& c : t->candidates()) {
      EXPECT_FALSE(c.cause.empty() || c.unit.empty() || c.signature.empty()) << c.name;
      EXPECT_TRUE(ranks.insert(c.rank).second) << c.name << ": rank " << c.rank << " taken";
      EXPECT_TRUE(c.free_decay || c.forced) << c.name << " offered in no mode";
      if (c.name != name) continue;
      own = true;
      EXPECT_TRUE(!c.free_decay || t->appliesTo(ExperimentMode::kFreeDecay)) << name;
      EXPECT_TRUE(!c.forced || t->appliesTo(ExperimentMode::kForced)) << name;
    }
    // The base terms are always in the model; every other term is an extension explain tries.
    if (name != "linear" && name != "controls") {
      EXPECT_TRUE(own) << name << " is no candidate";
    }
  }
}

TEST(ModelTermRegistry, TimeVaryingTermsAreTheTermsWhoseForceDependsOnTime) {
  const Eigen::Vector4d q(0.31, 0.52, -0.17, 0.23);
  int time_varying = 0;
  for (const auto& name : knownModelTermNames()) {
    const ModelTermPtr t = makeModelTerm(name);
    SlowContext early, late;
    early.t_s = 1.0;
    late.t_s = 5.0;
    Eigen::MatrixXd a(4, t->numParameters()), b(4, t->numParameters());
    t->averagedColumns(q, early, a);
    t->averagedColumns(q, late, b);
    EXPECT_EQ(t->isTimeVarying(), (a - b).norm() > 1e-12 * a.norm()) << name;
    time_varying += t->isTimeVarying();
  }
  EXPECT_EQ(time_varying, 1);  // cm_rate
}

TEST(ModelTermRegistry, AmplitudeLawsAreTheTermsWhoseForceGrowsFasterThanTheAmplitude) {
  for (const auto& name : knownModelTermNames()) {
    const ModelTermPtr t = makeModelTerm(name);
    const double p = amplitudeScaling(*t);
    const bool grows = std::abs(p - 1.0) > 1e-9 && std::abs(p) > 1e-9;
    EXPECT_EQ(t->isAmplitudeLaw(), grows) << name << ": force ~ amplitude^" << p;
    for (const auto& param : t->parameterNames())
      EXPECT_EQ(isAmplitudeLawParameter(param), grows) << param;
    EXPECT_EQ(isAmplitudeLawTerm(name), grows) << name;
  }
  EXPECT_FALSE(isAmplitudeLawTerm("mu"));
  EXPECT_FALSE(isAmplitudeLawParameter("gamma"));
}

TEST(ModelTermRegistry, ExplainsCandidateListsKeepTheirOrder) {
  std::vector<std::string> free_decay, forced;
  for (const auto& c : candidateExtensions(ExperimentMode::kFreeDecay))
    free_decay.push_back(c.name);
  for (const auto& c : candidateExtensions(ExperimentMode::kForced)) forced.push_back(c.name);
  EXPECT_EQ(free_decay,
            (std::vector<std::string>{"xi", "kappa", "gamma_nl", "cm_rate", "xi_diff", "xi_k"}));
  EXPECT_EQ(forced, (std::vector<std::string>{"xi", "kappa", "mu", "gamma_nl", "xi_diff"}));
  EXPECT_TRUE(findCandidateExtension("mu", ExperimentMode::kForced).needs_output_error);
  EXPECT_THROW(findCandidateExtension("cm_rate", ExperimentMode::kForced), InputError);
}

}  // namespace
}  // namespace cvg_bench

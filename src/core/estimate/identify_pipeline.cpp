#include "cvg_bench/core/estimate/identify_pipeline.h"

#include <cmath>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/number_text.h"
#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {

Method parseMethod(const std::string& name) {
  if (name == "ls") return Method::kLs;
  if (name == "rls") return Method::kRls;
  if (name == "ceres") return Method::kCeres;
  throw InputError("method must be ls, rls or ceres, got '" + name + "'");
}

std::string methodName(Method method) {
  switch (method) {
    case Method::kRls:
      return "rls";
    case Method::kCeres:
      return "ceres";
    case Method::kLs:
      break;
  }
  return "ls";
}

namespace {

/// The regression stage's options: RLS runs as asked, Ceres starts from batch LS.
IdentificationOptions regressionOptions(const PipelineOptions& o) {
  IdentificationOptions r = o.identification;
  r.method = o.method == Method::kRls ? "rls" : "ls";
  return r;
}

/// The refinement's options: one confidence, angular gain and mu for both stages.
CeresOptions refinementOptions(const PipelineOptions& o) {
  CeresOptions c = o.ceres;
  c.confidence = o.identification.confidence;
  c.angular_gain_k = o.identification.angular_gain_k;
  c.known_mu = o.identification.mu;
  c.mu_start = o.identification.mu;
  return c;
}

Estimate keptStart(const Estimate& start, const AnalysisError& err) {
  Estimate kept = start;
  kept.notes.push_back(std::string("output-error refinement failed, equation-error LS kept (its "
                                   "xi-type terms carry an EIV bias): ") +
                       err.what());
  return kept;
}

template <class Record>
Estimate refine(const Record& record, const Estimate& start, const PipelineOptions& o) {
  if (o.method != Method::kCeres) return start;
  try {
    return refineWithCeres(record, start, refinementOptions(o));
  } catch (const AnalysisError& err) {
    if (o.on_ceres_failure == CeresFailure::kThrow) throw;
    return keptStart(start, err);
  }
}

}  // namespace

std::vector<std::string> PipelineOptions::validate() const {
  std::vector<std::string> p = regressionOptions(*this).validate();
  if (method == Method::kCeres)
    for (const auto& c : refinementOptions(*this).validate()) p.push_back(c);
  return p;
}

Estimate identify(const SlowRecord& record, const PipelineOptions& options) {
  throwIfInvalid("invalid identification options", options.validate());
  return refine(record, identifyFreeDecay(record, regressionOptions(options)), options);
}

Estimate identify(const std::vector<SlowRecord>& records, const PipelineOptions& options) {
  if (records.size() == 1) return identify(records.front(), options);
  throwIfInvalid("invalid identification options", options.validate());
  if (options.method == Method::kCeres)
    throw InputError(
        "--method ceres integrates one trajectory through the record; stacked free decays "
        "(several records) are fitted with --method ls or rls");
  return identifyFreeDecay(records, regressionOptions(options));
}

DeferredEstimate identifyDeferred(const SlowRecord& record, const PipelineOptions& options) {
  throwIfInvalid("invalid identification options", options.validate());
  DeferredEstimate d;
  const Estimate start = identifyFreeDecay(record, regressionOptions(options));
  if (options.method != Method::kCeres) {
    d.estimate = start;
    return d;
  }
  Estimate near = start;
  CeresOptions refinement_options = refinementOptions(options);
  if (!options.ceres_start.empty()) {
    for (size_t i = 0; i < near.names.size(); ++i) {
      const auto it = options.ceres_start.find(near.names[i]);
      if (it != options.ceres_start.end() && std::isfinite(it->second)) near.values[i] = it->second;
    }
    near.initial_slow_state = options.ceres_start_state;
    refinement_options.coarse_samples = 0;
  }
  try {
    const FreeDecayRefinement refinement(record, near, refinement_options);
    d.estimate = refinement.solved();
    d.finish = [refinement]() { return refinement.finish(); };
  } catch (const AnalysisError& err) {
    if (options.on_ceres_failure == CeresFailure::kThrow) throw;
    d.estimate = keptStart(start, err);
  }
  return d;
}

Estimate identify(const SweepRecord& record, const PipelineOptions& options) {
  throwIfInvalid("invalid identification options", options.validate());
  const ResonatorModel model(options.identification.model, ExperimentMode::kForced);
  if (!model.estimatesMu())
    return refine(record, identifyForced(record, regressionOptions(options)), options);
  if (options.method != Method::kCeres)
    throw InputError(
        "model '" + options.identification.model +
        "' estimates mu (bilinear with u~ in (3.2)): use method ceres (--method ceres)");
  // mu multiplies u~ bilinearly (3.2): LS fits the linear part at the start mu, Ceres fits both.
  IdentificationOptions linear = regressionOptions(options);
  linear.model = model.linearPart().spec();
  Estimate start = identifyForced(record, linear);
  start.model = model.spec();
  // std::to_string's format, kept for the tool's notes
  start.notes.push_back("Ceres start: LS with mu = " + fixedText(options.identification.mu, 6));
  return refine(record, start, options);
}

}  // namespace cvg_bench

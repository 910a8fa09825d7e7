#include "cvg_bench/core/diagnose/forward_selection.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cvg_bench/core/model/errors.h"

namespace cvg_bench {

std::vector<std::string> SelectionOptions::validate() const {
  std::vector<std::string> p;
  if (!(alpha > 0.0 && alpha < 0.5)) p.push_back("alpha must lie in (0, 0.5)");
  if (!(min_holdout_ratio >= 0.0) || !std::isfinite(min_holdout_ratio))
    p.push_back("min_holdout_ratio must be finite and >= 0");
  if (max_steps < 1) p.push_back("max_steps must be >= 1");
  return p;
}

namespace {

double ratio(double a, double b) {
  if (!(b > 0.0)) return a > 0.0 ? std::numeric_limits<double>::infinity() : 1.0;
  return a / b;
}

/// The parameters a candidate adds (its term's parameter names; mu for mu).
std::vector<std::string> addedParameters(const CandidateExtension& c) {
  return {c.parameter};
}

}  // namespace

SelectionResult forwardSelect(const NestedModelFitter& fitter,
                              const std::vector<CandidateExtension>& candidates,
                              const SelectionOptions& options, std::vector<std::string>* notes) {
  const auto problems = options.validate();
  if (!problems.empty()) {
    std::string msg = "invalid selection options:";
    for (const auto& p : problems) msg += " " + p + ";";
    throw InputError(msg);
  }
  SelectionResult result;
  result.holdout_description = fitter.holdoutDescription();
  result.baseline = fitter.fit({});
  NestedFit current = result.baseline;
  double current_holdout = fitter.holdoutRms({});
  std::vector<CandidateExtension> remaining = candidates;

  while (!remaining.empty() && static_cast<int>(result.steps.size()) < options.max_steps) {
    std::vector<SelectionStep> round;
    std::vector<double> round_holdout;
    for (const auto& c : remaining) {
      std::vector<std::string> ext = current.extensions;
      ext.push_back(c.name);
      SelectionStep s;
      s.added = c.name;
      double holdout = 0.0;
      try {
        s.fit = fitter.fit(ext);
        holdout = fitter.holdoutRms(ext);
      } catch (const std::exception& err) {
        if (notes) notes->push_back("candidate " + c.name + " skipped: " + err.what());
        continue;
      }
      s.model = s.fit.model;
      s.sigma = s.fit.sigma;
      s.sigma_ratio = ratio(current.sigma, s.fit.sigma);
      s.wald = waldTest(s.fit.estimate, addedParameters(c));
      s.delta_bic = deltaBic(current.rss, s.fit.rss, s.fit.n_equations,
                             s.fit.estimate.n_params - current.estimate.n_params);
      s.holdout_ratio = ratio(current_holdout, holdout);
      round.push_back(s);
      round_holdout.push_back(holdout);
    }
    if (round.empty()) break;
    const double threshold = options.alpha / static_cast<double>(round.size());
    int best = -1;
    for (size_t i = 0; i < round.size(); ++i) {
      round[i].threshold = threshold;
      if (round[i].wald.p_value < threshold && round[i].holdout_ratio > options.min_holdout_ratio &&
          round[i].sigma_ratio > 1.0 &&
          (best < 0 || round[i].wald.p_value < round[best].wald.p_value ||
           (round[i].wald.p_value == round[best].wald.p_value &&
            round[i].wald.f_statistic > round[best].wald.f_statistic)))
        best = static_cast<int>(i);
    }
    if (best < 0) {
      result.last_round = round;
      break;
    }
    round[best].accepted = true;
    current = round[best].fit;
    current_holdout = round_holdout[best];
    result.steps.push_back(round[best]);
    remaining.erase(
        std::remove_if(remaining.begin(), remaining.end(),
                       [&](const CandidateExtension& c) { return c.name == round[best].added; }),
        remaining.end());
  }

  // Backward check: an accepted term that the later ones made redundant is dropped.
  if (options.backward_check && current.extensions.size() > 1) {
    bool changed = true;
    while (changed && current.extensions.size() > 1) {
      changed = false;
      const double threshold = options.alpha / static_cast<double>(current.extensions.size());
      double worst_p = threshold;
      std::string worst;
      for (const auto& name : current.extensions) {
        const WaldTestResult w = waldTest(current.estimate, {name});
        if (w.p_value >= worst_p) worst_p = w.p_value, worst = name;
      }
      if (!worst.empty()) {
        std::vector<std::string> ext;
        for (const auto& e : current.extensions)
          if (e != worst) ext.push_back(e);
        current = fitter.fit(ext);
        result.dropped.push_back(worst);
        if (notes)
          notes->push_back("backward check: " + worst + " dropped (Wald p = " +
                           std::to_string(worst_p) + " in the final model)");
        changed = true;
      }
    }
  }
  result.selected = current.extensions;
  result.final_fit = current;
  return result;
}

}  // namespace cvg_bench

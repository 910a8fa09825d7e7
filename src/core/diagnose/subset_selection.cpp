// Best-subset selection of model extensions (forward_selection.h has the criterion):
//   1. every subset of up to max_steps candidates is fitted by the cheap fit (equation-error LS of
//      (2.8) / (3.4)) and scored by IC with c from the residuals of the whole library's cheap fit;
//   2. the linear model and the `finalists` best subsets are refined (output-error fit of the
//      trajectory in free decay, docs/paper.md items 10, 15: the LS of (2.8) carries an
//      errors-in-variables bias) and scored again, c from the output-error residuals of the largest
//      finalist (and never below the record's known noise_correlation);
//   3. the best refined subset is checked backwards (a term goes when the subset without it
//      scores better) and confirmed on the hold-out: it must predict the held-out data better than
//      the linear model, else the next subset in criterion order is tried;
//      (before 3, every one-term extension of the best refined subset is refined as well, until
//      none scores better: the LS ranking can miss terms that act together);
//   4. the steps ladder adds the chosen terms one at a time, best refined criterion first; the
//      runner-up is the best refined subset not chosen.
// Subsets act together: cubic + quintic stiffness in a decay are nearly collinear (amplitude^2 and
// amplitude^4 both fall monotonically), each alone can worsen the hold-out, the pair does not.
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/number_text.h"
#include "cvg_bench/core/diagnose/forward_selection.h"
#include "cvg_bench/core/diagnose/nested_model_fitters.h"
#include "cvg_bench/core/diagnose/parallel_tasks.h"
#include "cvg_bench/core/estimate/uncertainty/long_run_variance.h"

namespace cvg_bench {

std::vector<std::string> SelectionOptions::validate() const {
  std::vector<std::string> p;
  if (!(alpha > 0.0 && alpha < 0.5)) p.push_back("alpha must lie in (0, 0.5)");
  if (!(min_holdout_ratio >= 0.0) || !std::isfinite(min_holdout_ratio))
    p.push_back("min_holdout_ratio must be finite and >= 0");
  if (max_steps < 1 || max_steps > 4) p.push_back("max_steps must lie in 1..4");
  if (finalists < 1 || finalists > 20) p.push_back("finalists must lie in 1..20");
  if (max_tried_per_finalist < 1) p.push_back("max_tried_per_finalist must be >= 1");
  if (threads < 0 || threads > 64) p.push_back("threads must lie in 0..64");
  return p;
}

namespace {

using Terms = std::vector<std::string>;
constexpr double kInf = std::numeric_limits<double>::infinity();
/// Residuals per block (equation error) or per sample (output error, q has 4 components): the
/// channels of longRunVarianceFactor.
constexpr int kResidualChannels = 4;

double ratio(double a, double b) {
  if (!(b > 0.0)) return a > 0.0 ? kInf : 1.0;
  return a / b;
}

/// The subset as a model specification ("linear+xi+..."), its key in the tables.
std::string key(const Terms& t) {
  std::string s = "linear";
  for (const auto& e : t) s += "+" + e;
  return s;
}

/// All subsets of `names` with up to `max_size` elements, in candidate order, smallest first.
std::vector<Terms> subsetsUpTo(const std::vector<std::string>& names, int max_size) {
  std::vector<Terms> out = {{}};
  for (size_t i = 0; i < out.size(); ++i) {
    if (static_cast<int>(out[i].size()) >= max_size) continue;
    size_t start = 0;
    if (!out[i].empty())
      start = std::find(names.begin(), names.end(), out[i].back()) - names.begin() + 1;
    for (size_t j = start; j < names.size(); ++j) {
      Terms t = out[i];
      t.push_back(names[j]);
      out.push_back(t);
    }
  }
  return out;
}

Terms without(const Terms& t, const std::string& name) {
  Terms o;
  for (const auto& x : t)
    if (x != name) o.push_back(x);
  return o;
}

/// The fits, scores and hold-outs of one selection, each computed once.
class SubsetSearch {
 public:
  SubsetSearch(const NestedModelFitter& fitter, const std::vector<CandidateExtension>& candidates,
               const SelectionOptions& options, std::vector<std::string>* notes)
      : fitter_(fitter), options_(options), notes_(notes) {
    for (const auto& c : candidates) names_.push_back(c.name);
    const boost::math::chi_squared chi2(1);
    penalty_floor_ = boost::math::quantile(
        boost::math::complement(chi2, options.alpha / std::max<size_t>(1, candidates.size())));
  }

  const std::vector<std::string>& names() const { return names_; }

  /// Orders `terms` as the candidates are ordered.
  Terms canonical(const Terms& terms) const {
    Terms t;
    for (const auto& n : names_)
      if (std::find(terms.begin(), terms.end(), n) != terms.end()) t.push_back(n);
    return t;
  }

  const NestedFit* cheap(const Terms& t) { return cached(t, &cheap_, false); }
  const NestedFit* refined(const Terms& t) {
    if (!fitter_.refinesByOutputError()) return cheap(t);
    return cached(t, &refined_, true);
  }

  double criterion(const NestedFit& f, size_t k, double c) const {
    const double n = static_cast<double>(f.n_equations);
    if (!(f.rss > 0.0) || n < 1) return kInf;
    const double n_eff = n / c;
    return n_eff * std::log(f.rss / n) + static_cast<double>(k) * penalty(c, n);
  }
  double penalty(double c, double n) const {
    return std::max(std::log(std::max(n / c, 1.0)), penalty_floor_);
  }
  double penaltyFloor() const { return penalty_floor_; }

  bool hasHoldout(const Terms& t) const { return holdout_.count(key(t)) > 0; }
  double holdout(const Terms& t) {
    const std::string k = key(t);
    const auto it = holdout_.find(k);
    if (it != holdout_.end()) return it->second;
    double h = kInf;
    std::exception_ptr error;
    try {
      h = fitter_.holdoutRms(t);
    } catch (...) {
      error = std::current_exception();
    }
    return storeHoldout(k, h, error);
  }

  /// Refines every subset of `batch` not refined yet, several at a time (options.threads); the
  /// cache and the notes end as if refined() had been called on each in batch order.
  /// `near` (optional): a refined fit nested in every subset of the batch, their start.
  void refineAll(const std::vector<Terms>& batch, const NestedFit* near = nullptr) {
    // Without an output-error stage refined() is the cheap fit, which extends a shared factor.
    if (!fitter_.refinesByOutputError()) return;
    std::vector<Terms> todo;
    for (const auto& t : batch) {
      const std::string k = key(t);
      if (refined_.count(k) || failed_.count(k + "/r") || contains(todo, t)) continue;
      todo.push_back(t);
    }
    std::vector<NestedFit> fits(todo.size());
    std::vector<std::exception_ptr> errors(todo.size());
    runTasks(todo.size(), options_.threads, [&](size_t i) {
      try {
        fits[i] = near ? fitter_.fitNear(todo[i], *near) : fitter_.fit(todo[i]);
        // The linear model is always reported (the baseline): its intervals made here, on the
        // batch's threads.
        if (todo[i].empty() && fits[i].finish) {
          fits[i].estimate = fits[i].finish();
          fits[i].finish = nullptr;
        }
      } catch (...) {
        errors[i] = std::current_exception();
      }
    });
    for (size_t i = 0; i < todo.size(); ++i)
      store(key(todo[i]), &refined_, true, std::move(fits[i]), errors[i]);
  }

  /// A refined fit that fell back to its LS start (the output-error fit failed): retried once from
  /// the output-error fit of its best nested subset one term smaller (refined first, and retried
  /// the same way when it fell back too; the added term starts at zero), else of any smaller
  /// refined subset, the linear model at worst. The retry replaces the cached fit when it
  /// converges. Said in the notes either way.
  void retryFallback(const Terms& t) {
    const std::string k = key(t);
    const auto it = refined_.find(k);
    if (it == refined_.end() || it->second.estimate.method == "ceres" || retried_.count(k)) return;
    retried_[k] = true;
    std::string why = "reason not recorded";
    for (const auto& n : it->second.estimate.notes)
      if (n.find("refinement failed") != std::string::npos) why = n.substr(n.rfind(": ") + 2);
    for (const auto& name : t) {
      Terms sub;
      for (const auto& n : t)
        if (n != name) sub.push_back(n);
      refined(sub);
      retryFallback(sub);
    }
    const NestedFit* near = nullptr;
    for (const auto& kv : refined_) {
      const NestedFit& c = kv.second;
      if (c.estimate.method != "ceres" || c.extensions.size() >= t.size()) continue;
      bool nested = true;
      for (const auto& e : c.extensions)
        nested = nested && std::find(t.begin(), t.end(), e) != t.end();
      if (nested && (!near || c.extensions.size() > near->extensions.size() ||
                     (c.extensions.size() == near->extensions.size() && c.rss < near->rss)))
        near = &c;
    }
    std::string msg = "subset " + k + ": output-error fit failed from the LS start (" + why + ")";
    if (!near) {
      msg += "; no refined nested subset to start from: not ranked";
    } else {
      msg += "; retried from the refined " + near->model;
      try {
        NestedFit again = fitter_.fitNear(t, *near);
        if (again.estimate.method == "ceres") {
          it->second = std::move(again);
          msg += ": converged";
        } else {
          msg += ": failed again: not ranked";
        }
      } catch (const std::exception& e) {
        msg += std::string(": ") + e.what() + ": not ranked";
      }
    }
    if (notes_) notes_->push_back(msg);
  }

  /// The refined fit with its covariance and intervals (NestedFit::finish run once); for the
  /// fits the result reports (baseline, steps, near misses), the others are only ranked.
  const NestedFit* complete(const Terms& t) {
    const NestedFit* f = refined(t);
    if (f && f->finish) completeAll({t});
    return f;
  }
  /// complete() of each of `batch`, several at a time.
  void completeAll(const std::vector<Terms>& batch) {
    std::vector<NestedFit*> todo;
    for (const auto& t : batch) {
      const auto it = refined_.find(key(t));
      if (it != refined_.end() && it->second.finish &&
          std::find(todo.begin(), todo.end(), &it->second) == todo.end())
        todo.push_back(&it->second);
    }
    runTasks(todo.size(), options_.threads, [&](size_t i) {
      todo[i]->estimate = todo[i]->finish();
      todo[i]->finish = nullptr;
    });
  }

  /// The hold-outs of `batch` not computed yet, several at a time; as holdout() in batch order.
  void holdoutAll(const std::vector<Terms>& batch) {
    std::vector<Terms> todo;
    for (const auto& t : batch)
      if (!hasHoldout(t) && !contains(todo, t)) todo.push_back(t);
    std::vector<double> h(todo.size(), kInf);
    std::vector<std::exception_ptr> errors(todo.size());
    runTasks(todo.size(), options_.threads, [&](size_t i) {
      try {
        h[i] = fitter_.holdoutRms(todo[i]);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    });
    for (size_t i = 0; i < todo.size(); ++i) storeHoldout(key(todo[i]), h[i], errors[i]);
  }

 private:
  static bool contains(const std::vector<Terms>& list, const Terms& t) {
    return std::find(list.begin(), list.end(), t) != list.end();
  }

  const NestedFit* cached(const Terms& t, std::map<std::string, NestedFit>* cache, bool refine) {
    const std::string k = key(t);
    const auto it = cache->find(k);
    if (it != cache->end()) return &it->second;
    if (failed_.count(k + (refine ? "/r" : "/c"))) return nullptr;
    NestedFit f;
    std::exception_ptr error;
    try {
      f = refine ? fitter_.fit(t) : fitter_.fitEquationError(t);
    } catch (...) {
      error = std::current_exception();
    }
    return store(k, cache, refine, std::move(f), error);
  }

  /// Keeps a finished fit, or notes why it failed (errors other than std::exception propagate).
  const NestedFit* store(const std::string& k, std::map<std::string, NestedFit>* cache, bool refine,
                         NestedFit f, const std::exception_ptr& error) {
    if (!error) return &cache->emplace(k, std::move(f)).first->second;
    try {
      std::rethrow_exception(error);
    } catch (const std::exception& err) {
      failed_[k + (refine ? "/r" : "/c")] = true;
      if (notes_)
        notes_->push_back("subset " + k + " skipped (" + (refine ? "refined" : "LS") +
                          " fit failed): " + err.what());
    }
    return nullptr;
  }

  double storeHoldout(const std::string& k, double h, const std::exception_ptr& error) {
    if (error) {
      try {
        std::rethrow_exception(error);
      } catch (const std::exception& err) {
        if (notes_) notes_->push_back("hold-out of " + k + " failed: " + err.what());
      }
      h = kInf;
    }
    holdout_[k] = h;
    return h;
  }

  const NestedModelFitter& fitter_;
  SelectionOptions options_;
  std::vector<std::string>* notes_;
  std::vector<std::string> names_;
  double penalty_floor_ = 0.0;
  std::map<std::string, NestedFit> cheap_, refined_;
  std::map<std::string, double> holdout_;
  std::map<std::string, bool> failed_, retried_;
};

/// Stacked output-error residuals of a refined fit (4 per sample).
Eigen::VectorXd adequacyVector(const NestedModelFitter& fitter, const NestedFit& f) {
  const auto blocks = fitter.adequacyResiduals(f);
  Eigen::VectorXd r(4 * blocks.size());
  for (size_t i = 0; i < blocks.size(); ++i) r.segment<4>(4 * i) = blocks[i].e;
  return r;
}

/// Every problem with the options, in one InputError.
void throwIfInvalid(const SelectionOptions& options) {
  const auto problems = options.validate();
  if (!problems.empty()) {
    std::string msg = "invalid selection options:";
    for (const auto& p : problems) msg += " " + p + ";";
    throw InputError(msg);
  }
}

/// One selection: its steps (the header comment of this file) and the state they pass on.
class SelectionRun {
 public:
  /// Fits the linear model cheaply (AnalysisError when it cannot be fitted).
  SelectionRun(const NestedModelFitter& fitter, const std::vector<CandidateExtension>& candidates,
               const SelectionOptions& options, std::vector<std::string>* notes)
      : fitter_(fitter),
        options_(options),
        notes_(notes),
        search_(fitter, candidates, options, notes) {
    result_.holdout_description = fitter.holdoutDescription();
    base_cheap_ = search_.cheap({});
    if (!base_cheap_) throw AnalysisError("explain: the linear model cannot be fitted");
  }

  // 1. Cheap scores of every subset; c from the whole library's cheap fit (least misfit).
  void scoreCheap() {
    all_ = subsetsUpTo(search_.names(), options_.max_steps);
    const NestedFit* widest = widestCheapFit();
    result_.correlation_factor_ls = longRunVarianceFactor(
        widest->scored_residuals.size() ? widest->scored_residuals : widest->residuals,
        kResidualChannels);
    c_ls_ = result_.correlation_factor_ls;
    for (const auto& t : all_) {
      const NestedFit* f = search_.cheap(t);
      if (!f) continue;
      SubsetScore s;
      s.terms = t;
      s.model = key(t);
      s.criterion_ls = search_.criterion(*f, t.size(), c_ls_);
      s.criterion = s.criterion_ls;
      s.sigma = f->sigma;
      scores_.push_back(s);
    }
    std::stable_sort(
        scores_.begin(), scores_.end(),
        [](const SubsetScore& a, const SubsetScore& b) { return a.criterion_ls < b.criterion_ls; });
  }

  // 2. Refine the linear model and the finalists.
  void refineFinalists() {
    std::vector<Terms> finalists = {{}};
    for (const auto& s : scores_)
      if (!s.terms.empty() && static_cast<int>(finalists.size()) <= options_.finalists)
        finalists.push_back(s.terms);
    search_.refineAll(finalists);  // the linear model first: the order refined() would be called in
    const NestedFit* base = search_.refined({});
    refined_scale_ =
        fitter_.refinesByOutputError() && base != nullptr && base->estimate.method == "ceres";
    if (fitter_.refinesByOutputError() && !base && notes_)
      notes_->push_back("the linear model's output-error fit failed: subsets compared on LS alone");
    c_ = c_ls_;
    if (refined_scale_) c_ = refinedCorrelationFactor(finalists);
    result_.correlation_factor = c_;
    scoreFinalists(finalists);
  }

  // Refined neighbours: the LS ranking of (2.8) can miss a subset whose terms act together (its
  // errors-in-variables bias hides small terms), so every one-term extension of the best refined
  // subset is refined too, until none scores better.
  void refineNeighbours() {
    for (int round = 0; round < options_.max_steps; ++round) {
      const auto r = ranked();
      if (r.empty()) break;
      const Terms best = r.front().second;
      const double best_v = r.front().first;
      bool improved = false;
      std::vector<Terms> extensions;
      for (const auto& name : search_.names()) {
        if (std::find(best.begin(), best.end(), name) != best.end()) continue;
        Terms t = best;
        t.push_back(name);
        t = search_.canonical(t);
        if (static_cast<int>(t.size()) > options_.max_steps || crit_.count(key(t))) continue;
        extensions.push_back(t);
      }
      // Started from the best subset's refined fit.
      search_.refineAll(extensions, search_.refined(best));
      for (const auto& t : extensions)
        if (score(t) < best_v) improved = true;
      if (!improved) break;
    }
  }

  // 3. Best refined subset, backward check, hold-out confirmation.
  void choose() {
    const double base_crit = score({});
    for (;;) {
      Terms top;
      if (!nextUnrejected(&top) || top.empty() || !(score(top) < base_crit)) break;
      rejected_keys_.push_back(key(top));  // each round retires its pick: the loop ends
      const Terms best = backwardCheck(top);
      if (best.empty()) break;
      if (best != top && rejected(best)) continue;
      if (best != top) rejected_keys_.push_back(key(best));
      if (confirmedOnHoldout(best)) {
        chosen_ = best;
        break;
      }
    }
    result_.dropped.erase(std::remove_if(result_.dropped.begin(), result_.dropped.end(),
                                         [&](const std::string& n) {
                                           return std::find(chosen_.begin(), chosen_.end(), n) !=
                                                  chosen_.end();
                                         }),
                          result_.dropped.end());
  }

  // 4. Steps ladder, runner-up, subset table. The fits reported get their intervals: the
  // baseline, the chosen subset and its refined one-term extensions (at once), the ladder's.
  void completeReported() {
    const Terms chosen_sorted = search_.canonical(chosen_);
    std::vector<Terms> reported = {{}, chosen_sorted};
    for (const auto& name : search_.names()) {
      Terms t = chosen_sorted;
      if (std::find(t.begin(), t.end(), name) != t.end()) continue;
      t.push_back(name);
      t = search_.canonical(t);
      if (crit_.count(key(t))) reported.push_back(t);
    }
    search_.completeAll(reported);
  }

  /// The steps ladder: the chosen terms added one at a time, best refined criterion first; the
  /// baseline, the selected terms and the final fit.
  void climbLadder() {
    const NestedFit* prev = search_.complete({});
    if (!prev) prev = base_cheap_;
    result_.baseline = *prev;
    Terms prefix;
    while (prefix.size() < chosen_.size()) {
      double best_v = kInf;
      const std::string add = nextRung(prefix, &best_v);
      Terms next = prefix;
      next.push_back(add);
      const NestedFit* f = search_.complete(search_.canonical(next));
      if (!f) break;
      SelectionStep s = stepOver(*prev, *f, add);
      search_.holdoutAll({search_.canonical(prefix), search_.canonical(next)});
      s.holdout_ratio = ratio(search_.holdout(search_.canonical(prefix)),
                              search_.holdout(search_.canonical(next)));
      s.delta_criterion = best_v - score(search_.canonical(prefix));
      s.accepted = true;
      result_.steps.push_back(s);
      prefix = next;
      prev = f;
    }
    result_.selected = prefix;
    result_.final_fit = *prev;
    result_.final_fit.extensions = prefix;
    final_ = prev;
    chosen_c_ = search_.canonical(prefix);
  }

  /// Candidates one term beyond the chosen subset that were refined (the verdict's near misses).
  void addNearMisses() {
    for (const auto& name : search_.names()) {
      if (std::find(chosen_c_.begin(), chosen_c_.end(), name) != chosen_c_.end()) continue;
      Terms t = chosen_c_;
      t.push_back(name);
      t = search_.canonical(t);
      if (!crit_.count(key(t)) || !std::isfinite(crit_[key(t)])) continue;
      const NestedFit* f = search_.complete(t);
      SelectionStep s = stepOver(*final_, *f, name);
      s.delta_criterion = crit_[key(t)] - score(chosen_c_);
      result_.last_round.push_back(s);
    }
  }

  /// The subset table: the refined criterion and sigma where refined, the hold-out ratio where
  /// computed.
  void fillSubsetTable() {
    for (auto& s : scores_) {
      const std::string k = key(s.terms);
      if (crit_.count(k)) {
        s.refined = true;
        s.criterion = crit_[k];
        if (const NestedFit* f = search_.refined(s.terms)) s.sigma = f->sigma;
      }
      // Hold-out ratios only where they were computed (no extra fits for the table).
      if (search_.hasHoldout(s.terms))
        s.holdout_ratio = ratio(search_.holdout({}), search_.holdout(s.terms));
    }
    result_.subsets = scores_;
  }

  /// The chosen subset's row, and the runner-up: the best refined subset not chosen.
  void pickRunnerUp() {
    result_.chosen = scoreOf(chosen_c_);
    double runner = kInf;
    for (const auto& r : ranked()) {
      if (key(r.second) == key(chosen_c_)) continue;
      result_.runner_up = scoreOf(r.second);
      runner = r.first;
      break;
    }
    result_.runner_up_delta = std::isfinite(runner) ? runner - score(chosen_c_) : kInf;
  }

  /// The criterion in words.
  void describeCriterion() {
    std::ostringstream d;
    d << "best subset of up to " << options_.max_steps << " of " << search_.names().size()
      << " candidates by IC = n_eff ln(RSS/N) + k max(ln n_eff, "
      << numberText(search_.penaltyFloor(), 3)
      << "), n_eff = N / c; ranked on the equation-error LS fit (c = " << numberText(c_ls_, 3)
      << "), the "
      << "linear model and " << options_.finalists << " finalists refined"
      << (refined_scale_ ? " by the output-error fit (c = " + numberText(c_, 3) + ")" : "")
      << ", confirmed on the hold-out";
    result_.criterion_description = d.str();
  }

  SelectionResult take() { return std::move(result_); }

 private:
  /// The whole library's cheap fit, else the widest cheap fit (the least RSS among equals); every
  /// subset fitted cheaply on the way.
  const NestedFit* widestCheapFit() {
    const NestedFit* widest = search_.cheap(search_.names());
    for (const auto& t : all_) search_.cheap(t);
    if (!widest) {
      for (const auto& t : all_) {
        const NestedFit* f = search_.cheap(t);
        if (f && (!widest || t.size() > widest->extensions.size() ||
                  (t.size() == widest->extensions.size() && f->rss < widest->rss)))
          widest = f;
      }
    }
    return widest;
  }

  /// c of the refined fits: from the largest finalist whose trajectory exists over the record (a
  /// fit that diverged has no output-error residuals; the linear model at worst), never below
  /// that of the record's known noise correlation.
  double refinedCorrelationFactor(const std::vector<Terms>& finalists) {
    std::vector<const NestedFit*> by_size;
    for (const auto& t : finalists)
      if (const NestedFit* f = search_.refined(t)) by_size.push_back(f);
    std::stable_sort(by_size.begin(), by_size.end(), [](const NestedFit* a, const NestedFit* b) {
      return a->extensions.size() > b->extensions.size();
    });
    Eigen::VectorXd e;
    for (const NestedFit* f : by_size) {
      if (f->estimate.method != "ceres") continue;
      e = adequacyVector(fitter_, *f);
      if (e.size() > 0) break;
    }
    return std::max(e.size() > 0 ? longRunVarianceFactor(e, kResidualChannels) : 1.0,
                    longRunVarianceFactor(fitter_.knownNoiseCorrelation()));
  }

  /// A finalist whose output-error fit failed is not comparable: refine further subsets in LS
  /// order until `finalists` comparable ones exist (at most max_tried_per_finalist times as many
  /// tried).
  void scoreFinalists(const std::vector<Terms>& finalists) {
    int comparable = 0;
    for (const auto& t : finalists)
      if (!t.empty() && std::isfinite(score(t))) ++comparable;
    int tried = static_cast<int>(finalists.size()) - 1;
    for (const auto& sc : scores_) {
      if (comparable >= options_.finalists ||
          tried >= options_.max_tried_per_finalist * options_.finalists)
        break;
      if (sc.terms.empty() || crit_.count(key(sc.terms))) continue;
      ++tried;
      if (std::isfinite(score(sc.terms))) ++comparable;
    }
  }

  /// The refined criterion of `t` (c_), computed once; kInf when not comparable.
  double score(const Terms& t) {
    const std::string k = key(t);
    const auto it = crit_.find(k);
    if (it != crit_.end()) return it->second;
    const NestedFit* f = search_.refined(t);
    // A free-decay refinement that fell back to LS has residuals in other units: not comparable
    // unless a retry from a refined nested fit converges; said either way (notes).
    if (f && refined_scale_ && f->estimate.method != "ceres") {
      search_.retryFallback(t);
      f = search_.refined(t);
    }
    const bool comparable = f && (!refined_scale_ || f->estimate.method == "ceres");
    const double v = comparable ? search_.criterion(*f, t.size(), c_) : kInf;
    crit_[k] = v;
    return v;
  }

  /// The scored subsets with a finite criterion, best first.
  std::vector<std::pair<double, Terms>> ranked() const {
    std::vector<std::pair<double, Terms>> r;
    for (const auto& kv : crit_) {
      for (const auto& s : all_)
        if (key(s) == kv.first && std::isfinite(kv.second)) r.push_back({kv.second, s});
    }
    std::stable_sort(r.begin(), r.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    return r;
  }

  bool rejected(const Terms& t) const {
    return std::find(rejected_keys_.begin(), rejected_keys_.end(), key(t)) != rejected_keys_.end();
  }
  void drop(const std::string& n) {
    if (std::find(result_.dropped.begin(), result_.dropped.end(), n) == result_.dropped.end())
      result_.dropped.push_back(n);
  }

  /// The best ranked subset not rejected yet into *top; false when there is none.
  bool nextUnrejected(Terms* top) const {
    for (const auto& r : ranked()) {
      if (rejected(r.second)) continue;
      *top = r.second;
      return true;
    }
    return false;
  }

  /// Backward check: a term goes when the subset without it scores better.
  Terms backwardCheck(const Terms& top) {
    Terms best = top;
    bool shrunk = options_.backward_check;
    while (shrunk && !best.empty()) {
      shrunk = false;
      Terms better = best;
      std::vector<Terms> smaller_subsets;
      for (const auto& name : best) smaller_subsets.push_back(without(best, name));
      search_.refineAll(smaller_subsets);
      for (const auto& name : best) {
        const Terms smaller = without(best, name);
        if (score(smaller) < score(better)) better = smaller;
      }
      if (better != best) {
        for (const auto& n : best)
          if (std::find(better.begin(), better.end(), n) == better.end()) drop(n);
        if (notes_)
          notes_->push_back("backward check: " + key(best) + " -> " + key(better) + " (criterion " +
                            numberText(score(best), 3) + " -> " + numberText(score(better), 3) +
                            ")");
        best = better;
        shrunk = true;
      }
    }
    return best;
  }

  /// Hold-out confirmation: `best` must predict the held-out data better than the linear model,
  /// else its terms are dropped (said in the notes).
  bool confirmedOnHoldout(const Terms& best) {
    search_.holdoutAll({{}, best});
    const double h = ratio(search_.holdout({}), search_.holdout(best));
    if (h > options_.min_holdout_ratio) return true;
    for (const auto& n : best) drop(n);
    if (notes_)
      notes_->push_back("hold-out confirmation: " + key(best) +
                        " (best criterion) predicts the held-out data no better than the linear "
                        "model (ratio " +
                        numberText(h, 3) + "): not chosen");
    return false;
  }

  /// The ladder's next term: of the chosen terms not in `prefix`, the one whose addition scores
  /// best (its criterion into *best_v); those extensions refined at once first.
  std::string nextRung(const Terms& prefix, double* best_v) {
    std::string add;
    std::vector<Terms> next_subsets;
    for (const auto& n : chosen_) {
      if (std::find(prefix.begin(), prefix.end(), n) != prefix.end()) continue;
      Terms t = prefix;
      t.push_back(n);
      next_subsets.push_back(search_.canonical(t));
    }
    search_.refineAll(next_subsets);
    for (const auto& n : chosen_) {
      if (std::find(prefix.begin(), prefix.end(), n) != prefix.end()) continue;
      Terms t = prefix;
      t.push_back(n);
      const double v = score(search_.canonical(t));
      if (add.empty() || v < *best_v) add = n, *best_v = v;
    }
    return add;
  }

  /// The step from `prev` to its extension `f` by `added`, with the gains of forward_selection.h.
  SelectionStep stepOver(const NestedFit& prev, const NestedFit& f,
                         const std::string& added) const {
    SelectionStep s;
    s.added = added;
    s.fit = f;
    s.model = f.model;
    s.sigma = f.sigma;
    s.sigma_ratio = ratio(prev.sigma, f.sigma);
    s.wald = waldTest(f.estimate, {added});
    s.delta_bic =
        deltaBic(prev.rss, f.rss, f.n_equations, f.estimate.n_params - prev.estimate.n_params);
    s.threshold = options_.alpha;
    return s;
  }

  /// The row of `t` in the subset table (a bare row when it is not there).
  SubsetScore scoreOf(const Terms& t) const {
    for (const auto& s : scores_)
      if (key(s.terms) == key(t)) return s;
    SubsetScore s;
    s.terms = t;
    s.model = key(t);
    return s;
  }

  const NestedModelFitter& fitter_;
  const SelectionOptions& options_;
  std::vector<std::string>* notes_;
  SubsetSearch search_;
  SelectionResult result_;
  const NestedFit* base_cheap_ = nullptr;  ///< the linear model's cheap fit
  std::vector<Terms> all_;                 ///< every subset of up to max_steps candidates
  double c_ls_ = 1.0;                      ///< c of the cheap fits
  std::vector<SubsetScore> scores_;        ///< every subset fitted, best cheap criterion first
  bool refined_scale_ = false;             ///< the refined fits are output-error fits
  double c_ = 1.0;                         ///< c of the refined fits (c_ls_ without them)
  std::map<std::string, double> crit_;     ///< refined criterion by subset key
  std::vector<std::string> rejected_keys_;
  Terms chosen_;                      ///< the confirmed subset (empty: the linear model)
  const NestedFit* final_ = nullptr;  ///< the ladder's last fit
  Terms chosen_c_;                    ///< the selected terms, candidate order
};

}  // namespace

SelectionResult selectExtensions(const NestedModelFitter& fitter,
                                 const std::vector<CandidateExtension>& candidates,
                                 const SelectionOptions& options, std::vector<std::string>* notes) {
  throwIfInvalid(options);
  SelectionRun run(fitter, candidates, options, notes);
  run.scoreCheap();        // 1. cheap scores of every subset
  run.refineFinalists();   // 2. the linear model and the finalists refined
  run.refineNeighbours();  //    their one-term extensions refined while they score better
  run.choose();            // 3. best refined subset, backward check, hold-out confirmation
  run.completeReported();  // 4. intervals of the fits reported,
  run.climbLadder();       //    the steps ladder,
  run.addNearMisses();     //    the near misses,
  run.fillSubsetTable();   //    the subset table,
  run.pickRunnerUp();      //    the runner-up,
  run.describeCriterion();
  return run.take();
}

}  // namespace cvg_bench

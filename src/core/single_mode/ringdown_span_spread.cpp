#include "cvg_bench/core/single_mode/ringdown_span_spread.h"

#include <cmath>
#include <vector>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/uncertainty/student_t.h"

namespace cvg_bench {

void addSpanSpread(const RingdownEnvelope& env, const RingdownSegment& seg,
                   const RingdownFitOptions& options, RingdownFit* fit,
                   const RingdownSpanSpreadOptions& spread) {
  const size_t len = seg.i_end - seg.i_start;
  if (len < spread.min_span_samples) return;
  RingdownFitOptions o = options;
  o.q_bins = 0;
  std::vector<std::string> names;
  for (const char* k : {"Q", "Q0"})
    if (fit->derived.count(k)) names.push_back(k);
  std::vector<double> sum2(names.size(), 0.0);
  int used = 0;
  for (const auto& cut : {std::pair<double, double>{spread.near_cut, 0.0},
                          {spread.far_cut, 0.0},
                          {0.0, spread.near_cut},
                          {0.0, spread.far_cut}}) {
    RingdownSegment s = seg;
    s.i_start = seg.i_start + static_cast<size_t>(cut.first * len);
    s.i_end = seg.i_end - static_cast<size_t>(cut.second * len);
    s.t_start_s = env.t_s[s.i_start];
    s.t_end_s = env.t_s[s.i_end - 1];
    try {
      const RingdownFit f = fitRingdown(env, s, fit->model, o);
      std::vector<double> d(names.size());
      for (size_t k = 0; k < names.size(); ++k) {
        const auto it = f.derived.find(names[k]);
        if (it == f.derived.end() || !std::isfinite(it->second.value)) throw AnalysisError("no Q");
        d[k] = it->second.value - fit->derived[names[k]].value;
      }
      // Only a neighbour that gave every value counts (its Q is not added without its Q0).
      for (size_t k = 0; k < names.size(); ++k) sum2[k] += d[k] * d[k];
      ++used;
    } catch (const AnalysisError&) {
      // A neighbouring span that does not fit adds nothing; at least three are needed.
    }
  }
  if (used < spread.min_fits) return;
  const double z = studentQuantile(options.confidence, 0);  // normal: the span part has no dof
  for (size_t k = 0; k < names.size(); ++k) {
    RingdownValue& v = fit->derived[names[k]];
    v.std_span = std::sqrt(sum2[k] / used);
    v.std_total = std::sqrt(v.std * v.std + v.std_span * v.std_span);
    const double rel = v.std_total / std::fabs(v.value);
    v.ci_total_low = std::min(v.ci_low, v.value * std::exp(-z * rel));
    v.ci_total_high = std::max(v.ci_high, v.value * std::exp(z * rel));
  }
}

}  // namespace cvg_bench

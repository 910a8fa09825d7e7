#include "cvg_bench/core/demod/raw_glitches.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace cvg_bench {

namespace {

double quantile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

double speed(const RawRecord& r, size_t a, size_t b) {
  const double dt = r.t_s[b] - r.t_s[a];
  const double d = std::hypot(r.f[b] - r.f[a], r.g[b] - r.g[a]);
  return dt > 0.0 ? d / dt : (d > 0.0 ? INFINITY : 0.0);
}

void keepOnly(RawRecord& r, const std::vector<bool>& keep) {
  size_t j = 0;
  for (size_t i = 0; i < keep.size(); ++i)
    if (keep[i]) {
      r.t_s[j] = r.t_s[i];
      r.f[j] = r.f[i];
      r.g[j] = r.g[i];
      ++j;
    }
  r.t_s.resize(j);
  r.f.resize(j);
  r.g.resize(j);
  for (auto& col : r.extra) {
    if (col.second.size() != keep.size()) continue;
    size_t m = 0;
    for (size_t i = 0; i < keep.size(); ++i)
      if (keep[i]) col.second[m++] = col.second[i];
    col.second.resize(m);
  }
}

}  // namespace

std::string RawGlitchReport::describe() const {
  if (!any()) return "";
  std::ostringstream s;
  s.precision(6);
  s << "bad samples (steps faster than " << speed_limit << " amplitude units/s, 3x what the "
    << "oscillation and its noise allow):";
  if (!spike_times_s.empty()) {
    s << " " << spike_times_s.size() << " isolated spike(s) left out (t =";
    for (size_t i = 0; i < spike_times_s.size() && i < 5; ++i) s << " " << spike_times_s[i];
    s << (spike_times_s.size() > 5 ? " ...)" : ")") << ";";
  }
  if (head_dropped > 0)
    s << " the first " << head_dropped << " sample(s) left out (start-up glitch);";
  if (tail_dropped > 0)
    s << " the last " << tail_dropped << " sample(s) left out (glitch at the end);";
  if (!jump_times_s.empty()) {
    s << " " << jump_times_s.size() << " jump(s) kept (t =";
    for (size_t i = 0; i < jump_times_s.size() && i < 5; ++i) s << " " << jump_times_s[i];
    s << (jump_times_s.size() > 5 ? " ...)" : ")") << ": tracking lost or a gap?";
  }
  std::string out = s.str();
  if (!out.empty() && out.back() == ';') out.pop_back();
  return out;
}

RawGlitchReport removeRawGlitches(RawRecord& raw, double omega_rad_s) {
  RawGlitchReport rep;
  const size_t n = raw.size();
  if (n < 20 || !(omega_rad_s > 0.0) || raw.f.size() != n || raw.g.size() != n) return rep;
  std::vector<double> fs(raw.f), gs(raw.g);
  const double fc = quantile(fs, 0.5), gc = quantile(gs, 0.5);
  std::vector<double> radius(n), steps(n - 1);
  for (size_t i = 0; i < n; ++i) radius[i] = std::hypot(raw.f[i] - fc, raw.g[i] - gc);
  for (size_t i = 0; i + 1 < n; ++i) steps[i] = speed(raw, i, i + 1);
  rep.speed_limit = 3.0 * std::max(omega_rad_s * quantile(radius, 0.95), quantile(steps, 0.99));
  const double L = rep.speed_limit;
  if (!(L > 0.0) || !std::isfinite(L)) return rep;
  std::vector<bool> keep(n, true);
  // Spikes: both steps implausible, the step over the sample plausible.
  for (size_t i = 1; i + 1 < n; ++i)
    if (steps[i - 1] > L && steps[i] > L && speed(raw, i - 1, i + 1) <= L) {
      keep[i] = false;
      rep.spike_times_s.push_back(raw.t_s[i]);
    }
  // The remaining implausible steps, between kept neighbours.
  std::vector<size_t> kept;
  for (size_t i = 0; i < n; ++i)
    if (keep[i]) kept.push_back(i);
  const size_t edge = std::max<size_t>(10, kept.size() / 100);
  size_t first = 0, last = kept.size() - 1;  // positions in `kept`
  for (size_t k = 0; k + 1 < kept.size(); ++k) {
    if (speed(raw, kept[k], kept[k + 1]) <= L) continue;
    if (k + 1 < edge)
      first = std::max(first, k + 1);
    else if (k + 1 >= kept.size() - edge)
      last = std::min(last, k);
    else
      rep.jump_times_s.push_back(raw.t_s[kept[k]]);
  }
  for (size_t k = 0; k < first; ++k) keep[kept[k]] = false;
  for (size_t k = last + 1; k < kept.size(); ++k) keep[kept[k]] = false;
  rep.head_dropped = static_cast<int>(first);
  rep.tail_dropped = static_cast<int>(kept.size() - 1 - last);
  if (rep.any()) keepOnly(raw, keep);
  return rep;
}

}  // namespace cvg_bench

#include "cvg_bench/core/single_mode/ringdown_straight_span.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "cvg_bench/core/common/sample_median.h"
#include "cvg_bench/core/single_mode/ringdown_envelope.h"
#include "cvg_bench/core/single_mode/ringdown_segmentation.h"

namespace cvg_bench {
namespace {

double medianOf(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}

/// Least-squares line c0 + c1 t over [a, b] of (u, v).
Eigen::Vector2d line(const std::vector<double>& u, const std::vector<double>& v, size_t a,
                     size_t b) {
  const size_t m = b - a + 1;
  Eigen::MatrixXd X(m, 2);
  Eigen::VectorXd Y(m);
  for (size_t i = 0; i < m; ++i) X(i, 0) = 1.0, X(i, 1) = u[a + i] - u[a], Y(i) = v[a + i];
  Eigen::Vector2d c = X.colPivHouseholderQr().solve(Y);
  c(0) -= c(1) * u[a];
  return c;
}

struct Grown {
  size_t a = 0, e = 0, j = 0;  ///< start, last on the line, first of the departing run
  Eigen::Vector2d c;
};

/// Step 2 of the header from grid sample a; false when the first fall is not straight.
bool grow(const std::vector<double>& u, const std::vector<double>& sm, size_t a, double tol,
          size_t run, const StraightSpanOptions& o, Grown* g) {
  const size_t m = u.size();
  size_t i1 = a;
  while (i1 + 1 < m && sm[i1] > sm[a] - o.first_db) ++i1;
  if (i1 < a + o.first_min_steps) return false;
  Eigen::Vector2d c = line(u, sm, a, i1);
  if (!(c(1) < 0.0)) return false;
  for (size_t i = a; i <= i1; ++i)
    if (std::fabs(sm[i] - c(0) - c(1) * u[i]) > tol) return false;
  size_t e = i1, bad = 0, refit = i1, j = i1 + 1;
  for (; j < m; ++j) {
    if (std::fabs(sm[j] - c(0) - c(1) * u[j]) > tol) {
      if (++bad >= run) break;
    } else {
      bad = 0;
      e = j;
      if (e - refit >= std::max<size_t>(o.min_refit, (e - a) / o.refit_divisor))
        c = line(u, sm, a, e), refit = e;
    }
  }
  g->a = a, g->e = e, g->j = std::min(j, m), g->c = line(u, sm, a, e);
  return true;
}

}  // namespace

std::string StraightSpan::endName() const {
  switch (end) {
    case StraightSpanEnd::kFloor:
      return "a noise floor";
    case StraightSpanEnd::kSmoothRise:
      return "a slowing decay";
    case StraightSpanEnd::kFall:
      return "a faster fall";
    default:
      return "the record's end";
  }
}

StraightSpan findStraightSpan(const std::vector<double>& t, const std::vector<double>& y,
                              const std::vector<bool>& skip, const StraightSpanOptions& o) {
  StraightSpan out;
  const size_t n = y.size();
  if (n < o.min_points || t.size() != n) return out;
  // 1. Block medians (u: block centre time, raw: median level in dB, first[k]: first sample).
  const size_t stride = std::max<size_t>(1, (n + o.grid - 1) / o.grid);
  std::vector<double> u, raw;
  std::vector<size_t> first;
  for (size_t k = 0; k < n; k += stride) {
    std::vector<double> b;
    double tb = 0.0;
    size_t nb = 0;
    for (size_t i = k; i < std::min(n, k + stride); ++i)
      if (!(i < skip.size() && skip[i]) && std::isfinite(y[i]))
        b.push_back(y[i] * kDbPerNeper), tb += t[i], ++nb;
    if (nb == 0) continue;
    u.push_back(tb / nb), raw.push_back(medianOf(b)), first.push_back(k);
  }
  const size_t m = u.size();
  if (m < o.min_points) return out;
  const std::vector<bool> none(m, false);
  const std::vector<double> sm =
      runningMedian(raw, none, std::max<int>(o.min_smooth_half, m / o.smooth_divisor));
  std::vector<double> d;
  for (size_t i = 1; i < m; ++i) d.push_back(std::fabs(raw[i] - raw[i - 1]));
  const double sd = kGaussianSdPerMad * medianOf(d) / std::sqrt(2.0);
  const double tol = std::max(o.tol_db, o.tol_sd * sd);
  const size_t run = std::max<size_t>(o.min_run, m / o.run_divisor);
  // The peak from a wider median (2 % of the grid), so that a glitch of a few samples is none.
  // Its last `hw` samples are left out (a clipped window there is a median of a few).
  const size_t hw = std::max<size_t>(o.min_peak_median_half, m / o.peak_median_divisor);
  const std::vector<double> wide = runningMedian(raw, none, static_cast<int>(hw));
  size_t ip = 0;
  for (size_t i = 1; i + hw < m; ++i)
    if (wide[i] > wide[ip]) ip = i;
  std::vector<size_t> peaks{ip};
  if (o.all_peaks) {
    // The last sample of each run within peak_near_db of the top, in time order.
    peaks.clear();
    for (size_t i = 0; i + hw < m; ++i)
      if (wide[i] >= wide[ip] - o.peak_near_db &&
          !(i + 1 + hw < m && wide[i + 1] >= wide[ip] - o.peak_near_db))
        peaks.push_back(i);
  }
  // 2-3. Candidates from falls below the peak(s).
  bool found = false;
  Grown best;
  double best_db = 0.0, best_score = 0.0;
  for (const size_t pk : peaks)
    for (const double drop : o.start_drops_db) {
      size_t a = pk;
      while (a + 1 < m && sm[a] > sm[pk] - drop) ++a;
      if (a + o.first_min_steps + 1 >= m) break;
      Grown g;
      if (!grow(u, sm, a, tol, run, o, &g)) continue;
      const double span_db = -g.c(1) * (u[g.e] - u[g.a]);
      const double score = span_db * std::sqrt(double(g.e - g.a + 1));
      if (!found || score > o.tie_ratio * best_score)
        found = true, best = g, best_db = span_db, best_score = score;
    }
  if (!found) return out;
  out.ok = true;
  out.i_start = first[best.a];
  out.i_end = best.e + 1 < m ? first[best.e + 1] : n;
  out.slope_db_s = best.c(1);
  out.span_db = best_db;
  // 4. How it ends: the level's slope past the end, over post_tenths tenths of the stretch (at
  // least `run` grid samples), against the stretch's own.
  if (best.j >= m) return out;
  const size_t len = std::max<size_t>(run, (best.e - best.a) * o.post_tenths / 10);
  const size_t p_end = std::min(m - 1, best.e + len);
  double past_mean = 0.0;
  for (size_t i = best.e + 1; i <= std::min(m - 1, best.e + run); ++i)
    past_mean += sm[i] - best.c(0) - best.c(1) * u[i];
  if (p_end >= best.e + 3) out.post_slope_db_s = line(u, sm, best.e + 1, p_end)(1);
  if (p_end >= best.e + 3 && out.post_slope_db_s > o.flat_fraction * out.slope_db_s)
    out.end = StraightSpanEnd::kFloor;
  else if (past_mean < 0.0)
    out.end = StraightSpanEnd::kFall;
  else
    out.end = StraightSpanEnd::kSmoothRise;
  return out;
}

}  // namespace cvg_bench

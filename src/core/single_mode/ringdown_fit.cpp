#include "cvg_bench/core/single_mode/ringdown_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/sample_median.h"
#include "cvg_bench/core/estimate/numeric_least_squares.h"
#include "cvg_bench/core/estimate/uncertainty/ar_noise_covariance.h"
#include "cvg_bench/core/estimate/uncertainty/student_t.h"
#include "cvg_bench/core/single_mode/ringdown_envelope.h"
#include "cvg_bench/core/single_mode/ringdown_laws.h"
#include "cvg_bench/core/single_mode/ringdown_models.h"

namespace cvg_bench {
namespace {

/// The law whose weighted straight line starts every fit (and gives the others' starts).
constexpr char kBaselineLaw[] = "linear";
/// Guard of the time scale T against a span of one time.
constexpr double kMinTimeScale = 1e-300;
/// Guard of a bin's normalized half-width (time axis of its local fit).
constexpr double kMinBinHalfWidth = 1e-12;
/// Smallest variance a bin reads.
constexpr double kMinBinVariance = 1e-30;

const double kInf = std::numeric_limits<double>::infinity();

double median(const std::vector<double>& v) {
  return sampleMedian(v);
}

struct Data {
  Eigen::VectorXd t, y, w;  // normalized time, ln A', weights
};

/// Weighted residuals sqrt(w) (y - f(p)); false when the model is not finite somewhere.
bool residuals(const RingdownLaw& law, const Eigen::VectorXd& p, const Data& d, double floor_rel,
               Eigen::VectorXd& r) {
  r.resize(d.t.size());
  for (int i = 0; i < d.t.size(); ++i) {
    const double f = law.logAmplitude(p, d.t(i), floor_rel);
    if (!std::isfinite(f)) return false;
    r(i) = std::sqrt(d.w(i)) * (d.y(i) - f);
  }
  return true;
}

/// Jacobian of the weighted model sqrt(w) f(p) (= -d r / dp) by central differences.
bool jacobian(const RingdownLaw& law, const Eigen::VectorXd& p, const Data& d, double floor_rel,
              Eigen::MatrixXd& J) {
  const ResidualFunction r = [&](const Eigen::VectorXd& q, Eigen::VectorXd& out) {
    return residuals(law, q, d, floor_rel, out);
  };
  if (!centralDifferenceJacobian(r, p, J)) return false;
  J = -J;
  return true;
}

/// Step 1: the span's usable samples (no dropout, finite level) and the normalization they give:
/// t_ref, t_scale, log_a_ref (median of the first levels) and floor_rel.
std::vector<size_t> normalizeSpan(const RingdownEnvelope& env, const RingdownSegment& seg,
                                  const RingdownFitOptions& options, RingdownFit& fit) {
  std::vector<size_t> used;
  for (size_t i = seg.i_start; i < seg.i_end; ++i)
    if (!seg.dropout[i] && std::isfinite(env.log_amplitude[i])) used.push_back(i);
  if (used.size() < fit.names.size() + options.min_samples_over_parameters)
    throw AnalysisError("ring-down: " + std::to_string(used.size()) + " samples in the span for " +
                        std::to_string(fit.names.size()) + " parameters of model " + fit.model);
  fit.t_ref_s = env.t_s[used.front()];
  fit.t_scale_s = std::max(env.t_s[used.back()] - fit.t_ref_s, kMinTimeScale);
  {
    std::vector<double> first;
    for (size_t i = 0; i < std::min<size_t>(used.size(), options.reference_samples); ++i)
      first.push_back(env.log_amplitude[used[i]]);
    fit.log_a_ref = median(first);
  }
  // A floor the decay only bends towards counts for the model and the noise as a confirmed one.
  fit.floor_rel = seg.has_floor ? std::exp(seg.floor_log_amplitude - fit.log_a_ref)
                  : std::isfinite(seg.suspected_floor_log_amplitude)
                      ? std::exp(seg.suspected_floor_log_amplitude - fit.log_a_ref)
                      : 0.0;
  return used;
}

/// Step 2: the held-out samples dropped from `used` (the normalization keeps them), and the fitted
/// samples in normalized units (weights still unset).
Data fittedSamples(const RingdownEnvelope& env, const RingdownFitOptions& options,
                   const RingdownFit& fit, std::vector<size_t>& used) {
  if (!options.hold_out.empty()) {
    if (options.hold_out.size() != env.size())
      throw InputError("ring-down fit: hold_out has " + std::to_string(options.hold_out.size()) +
                       " flags for " + std::to_string(env.size()) + " samples");
    std::vector<size_t> kept;
    for (size_t i : used)
      if (!options.hold_out[i]) kept.push_back(i);
    used.swap(kept);
  }
  const int n = static_cast<int>(used.size());
  if (n < static_cast<int>(fit.names.size()) + options.min_samples_over_parameters)
    throw AnalysisError("ring-down: " + std::to_string(n) + " samples fitted for " +
                        std::to_string(fit.names.size()) + " parameters of model " + fit.model);
  Data d;
  d.t.resize(n), d.y.resize(n), d.w.resize(n);
  for (int i = 0; i < n; ++i) {
    d.t(i) = (env.t_s[used[i]] - fit.t_ref_s) / fit.t_scale_s;
    d.y(i) = env.log_amplitude[used[i]] - fit.log_a_ref;
  }
  return d;
}

/// Robust variance of ln A about a local quadratic and median level, per time bin with enough
/// samples.
struct ScatterBins {
  std::vector<double> var, lvl;
};

ScatterBins scatterBins(const Data& d, const RingdownFitOptions& options) {
  const int n = static_cast<int>(d.t.size());
  const int nb = std::max(options.min_scatter_bins,
                          std::min(options.max_scatter_bins, n / options.samples_per_scatter_bin));
  ScatterBins bins;
  for (int b = 0; b < nb; ++b) {
    const int lo = b * n / nb, hi = (b + 1) * n / nb;
    if (hi - lo < options.min_samples_in_scatter_bin) continue;
    Eigen::MatrixXd Xq(hi - lo, 3);
    Eigen::VectorXd Yq(hi - lo);
    const double tm = 0.5 * (d.t(lo) + d.t(hi - 1)),
                 th = std::max(d.t(hi - 1) - tm, kMinBinHalfWidth);
    for (int i = lo; i < hi; ++i) {
      const double u = (d.t(i) - tm) / th;
      Xq(i - lo, 0) = 1.0, Xq(i - lo, 1) = u, Xq(i - lo, 2) = u * u, Yq(i - lo) = d.y(i);
    }
    const Eigen::VectorXd eq = Yq - Xq * Xq.colPivHouseholderQr().solve(Yq);
    std::vector<double> dd, lv;
    for (int i = 0; i < eq.size(); ++i) dd.push_back(std::fabs(eq(i)));
    for (int i = lo; i < hi; ++i) lv.push_back(d.y(i));
    const double s = kGaussianSdPerMad * median(dd);
    bins.var.push_back(std::max(s * s, kMinBinVariance));
    bins.lvl.push_back(median(lv));
  }
  return bins;
}

/// var = s_m^2 + s_a^2 exp(-2 level) fitted to the bins, both terms non-negative.
struct NoiseTerms {
  double s_m2 = 0.0, s_a2 = 0.0;
};

NoiseTerms fitNoiseTerms(const ScatterBins& bins) {
  const std::vector<double>&var_k = bins.var, &lvl_k = bins.lvl;
  NoiseTerms t;
  if (var_k.size() >= 2) {
    Eigen::MatrixXd X(var_k.size(), 2);
    Eigen::VectorXd V(var_k.size());
    for (size_t k = 0; k < var_k.size(); ++k)
      X(k, 0) = 1.0, X(k, 1) = std::exp(-2.0 * lvl_k[k]), V(k) = var_k[k];
    Eigen::VectorXd c = X.colPivHouseholderQr().solve(V);
    if (c(0) < 0.0 || c(1) < 0.0) {  // non-negative: the better one-term fit
      const double m_only = V.mean();
      const double a_only = X.col(1).dot(V) / X.col(1).squaredNorm();
      const double e_m = (V.array() - m_only).square().sum();
      const double e_a = (V - a_only * X.col(1)).squaredNorm();
      c << (e_m <= e_a ? m_only : 0.0), (e_m <= e_a ? 0.0 : a_only);
    }
    t.s_m2 = c(0), t.s_a2 = c(1);
  } else if (!var_k.empty()) {
    t.s_m2 = var_k.front();
  }
  return t;
}

/// The error model's why text.
std::string describeErrorModel(const RingdownFitOptions& options, const ScatterBins& bins,
                               bool additive, bool floor_sets_noise) {
  const std::vector<double>& var_k = bins.var;
  std::ostringstream w;
  w.precision(3);
  const double sd_first = var_k.empty() ? 0.0 : std::sqrt(var_k.front()) * kDbPerNeper;
  const double sd_last = var_k.empty() ? 0.0 : std::sqrt(var_k.back()) * kDbPerNeper;
  w << (options.error_model == "auto" ? "chosen from the data: " : "forced by option: ")
    << "sd of the level " << sd_first << " dB at the start, " << sd_last
    << " dB at the end of the span -> "
    << (additive ? "additive noise on the amplitude (sd grows as 1/A; floor in the model)"
                 : "noise on the log/dB scale (sd constant)");
  if (additive && floor_sets_noise)
    w << "; additive sd from the floor's rms (above the span's scatter, which correlated noise "
         "understates)";
  return w.str();
}

/// The variance terms the weights use: var = s_m2 + s_a2 exp(-2 level).
struct ErrorModel {
  double s_m2 = 0.0, s_a2 = 0.0;
  bool additive = false;
};

/// Step 3: error model from the scatter about a local quadratic in eight time bins (not from
/// sample-to-sample differences, which correlated detector noise makes small): var = s_m^2 +
/// s_a^2 exp(-2 level). Sets fit.error_model and its why.
ErrorModel chooseErrorModel(const Data& d, const RingdownFitOptions& options, RingdownFit& fit) {
  const ScatterBins bins = scatterBins(d, options);
  const std::vector<double>&var_k = bins.var, &lvl_k = bins.lvl;
  const NoiseTerms terms = fitNoiseTerms(bins);
  double s_m2 = terms.s_m2, s_a2 = terms.s_a2;
  // The floor measured past the span fixes the additive term: circular noise of rms F on an
  // amplitude A >> F scatters ln A with variance F^2 / (2 A^2). The bin scatter above misses much
  // of it when the detector's noise is correlated over a good part of a bin (the local quadratic
  // follows the slow wander), which overweights the tail and narrows the intervals, so the
  // floor's value is a lower bound on the bins' one.
  const double s_a2_floor = 0.5 * fit.floor_rel * fit.floor_rel;
  const bool floor_sets_noise = s_a2_floor > s_a2;
  if (floor_sets_noise) s_a2 = s_a2_floor;
  const double lvl_low = lvl_k.empty() ? 0.0 : *std::min_element(lvl_k.begin(), lvl_k.end());
  const double add_low = s_a2 * std::exp(-2.0 * lvl_low);
  const bool additive =
      options.error_model == "additive" ||
      (options.error_model == "auto" && add_low > options.additive_over_log_variance * s_m2 &&
       ((var_k.size() >= 2 && var_k.back() > options.additive_scatter_growth * var_k.front()) ||
        s_a2_floor > 0.0));
  fit.error_model = additive ? "additive" : "log";
  fit.error_model_why = describeErrorModel(options, bins, additive, floor_sets_noise);
  if (!additive) s_a2 = 0.0;
  // Every record carries some relative (log-scale) noise: with the multiplicative term at zero
  // the weights grow as A^2 and the first samples (a fast first stage, a corner) outweigh the
  // rest of the decay by orders of magnitude. A quarter of the quietest bin's scatter bounds it.
  if (additive && !var_k.empty())
    s_m2 = std::max(
        s_m2, options.min_log_variance_fraction * *std::min_element(var_k.begin(), var_k.end()));
  if (s_m2 <= 0.0 && s_a2 <= 0.0) s_m2 = 1.0;
  ErrorModel em;
  em.s_m2 = s_m2, em.s_a2 = s_a2, em.additive = additive;
  return em;
}

/// Weights at the 5-point running mean of the level.
void weighAtRunningMean(const ErrorModel& em, const RingdownFitOptions& options, Data& d) {
  const int n = static_cast<int>(d.t.size());
  for (int i = 0; i < n; ++i) {
    double acc = 0;
    int c = 0;
    for (int j = std::max(0, i - options.level_mean_half_width);
         j <= std::min(n - 1, i + options.level_mean_half_width); ++j)
      acc += d.y(j), ++c;
    const double lvl = acc / c;
    d.w(i) = 1.0 / (em.s_m2 + em.s_a2 * std::exp(-2.0 * lvl));
  }
}

// Weights at the observed level correlate with the noise of the same samples (a sample lifted
// by noise reads as quieter and weighs more), which pulls the tail up and the rate down under
// additive noise (Q 1-5 % high). The level for the weights is therefore a smooth of the whole
// span instead: a weighted Legendre polynomial of degree 6 in time (leverage 7 / n per sample),
// refitted once with its own weights. The same for every model, so criteria compare.
void weighAtSmoothLevel(const ErrorModel& em, const RingdownFitOptions& options, Data& d) {
  const int n = static_cast<int>(d.t.size());
  const int half =
      std::max(options.min_level_bound_half_width, n / options.level_bound_windows_per_span);
  Eigen::VectorXd y_lo(n), y_hi(n);
  for (int i = 0; i < n; ++i) {
    const int a = std::max(0, i - half), len = std::min(n - 1, i + half) - a + 1;
    y_lo(i) = d.y.segment(a, len).minCoeff(), y_hi(i) = d.y.segment(a, len).maxCoeff();
  }
  for (int pass = 0; pass < options.smooth_level_passes; ++pass) {
    const int deg = options.smooth_level_degree;
    Eigen::MatrixXd X(n, deg + 1);
    Eigen::VectorXd Y(n);
    for (int i = 0; i < n; ++i) {
      const double sw = std::sqrt(d.w(i)), x = 2.0 * d.t(i) - 1.0;
      double p0 = 1.0, p1 = x;
      X(i, 0) = sw, X(i, 1) = sw * x;
      for (int k = 2; k <= deg; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        X(i, k) = sw * p2, p0 = p1, p1 = p2;
      }
      Y(i) = sw * d.y(i);
    }
    const Eigen::VectorXd c = X.colPivHouseholderQr().solve(Y);
    for (int i = 0; i < n; ++i) {
      // Held within the observed levels nearby: a polynomial through a sharp corner (a fast
      // first stage) overshoots, and a level far below the data gives a sample no weight.
      const double lvl = std::min(std::max(X.row(i).dot(c) / std::sqrt(d.w(i)), y_lo(i)), y_hi(i));
      d.w(i) = 1.0 / (em.s_m2 + em.s_a2 * std::exp(-2.0 * lvl));
    }
  }
}

/// Step 4: weights 1 / var at a smoothed level, fixed during the fit, normalized to mean 1 (sigma
/// then reads in units of the mean sd).
void setWeights(const ErrorModel& em, const RingdownFitOptions& options, Data& d) {
  const int n = static_cast<int>(d.t.size());
  weighAtRunningMean(em, options, d);
  if (em.additive && n > options.min_samples_for_smooth_level) weighAtSmoothLevel(em, options, d);
  d.w /= d.w.mean();
}

/// Step 5a: starting points: the weighted straight line for linear, else given or derived from
/// the fitted linear baseline (the law's starts).
std::vector<Eigen::VectorXd> startingPoints(const RingdownEnvelope& env, const RingdownSegment& seg,
                                            const RingdownLaw& law,
                                            const RingdownFitOptions& options,
                                            const std::vector<Eigen::VectorXd>& starts,
                                            const Data& d) {
  std::vector<Eigen::VectorXd> st = starts;
  if (st.empty()) {
    const int n = static_cast<int>(d.t.size());
    Eigen::MatrixXd X(n, 2);
    Eigen::VectorXd Y(n);
    for (int i = 0; i < n; ++i) {
      const double sw = std::sqrt(d.w(i));
      X(i, 0) = sw, X(i, 1) = -sw * d.t(i), Y(i) = sw * d.y(i);
    }
    Eigen::VectorXd lin = X.colPivHouseholderQr().solve(Y);
    if (law.name == std::string(kBaselineLaw)) {
      st.push_back(lin);
    } else {
      RingdownFitOptions lean = options;
      lean.details = false;
      RingdownFit base = fitRingdown(env, seg, kBaselineLaw, lean);
      st = law.starts(base);
    }
  }
  return st;
}

/// Step 5b: the fit from each start; the lowest weighted sse wins (fit.p). Returns that sse.
double fitBestStart(const RingdownLaw& law, const std::vector<Eigen::VectorXd>& st, const Data& d,
                    RingdownFit& fit) {
  double best = kInf;
  for (auto p : st) {
    double sse = kInf;
    if (p.size() != static_cast<int>(fit.names.size())) continue;
    const ResidualFunction weighted = [&](const Eigen::VectorXd& q, Eigen::VectorXd& r) {
      return residuals(law, q, d, fit.floor_rel, r);
    };
    // A fit whose Jacobian cannot be evaluated at its answer (a law at the edge of its domain)
    // has no covariance: that start is dropped.
    Eigen::MatrixXd J_at;
    if (!minimizeSumOfSquares(weighted, p, sse) || !jacobian(law, p, d, fit.floor_rel, J_at))
      continue;
    if (sse < best) best = sse, fit.p = p;
  }
  if (!std::isfinite(best))
    throw AnalysisError("ring-down: model " + fit.model + " could not be fitted (no finite start)");
  return best;
}

/// Step 6: the answer in the law's canonical order and its residual summaries (sse_w, n, sigma,
/// rms_log); returns the weighted residuals there.
Eigen::VectorXd summarizeFit(const RingdownLaw& law, const Data& d, double best, RingdownFit& fit) {
  const int n = static_cast<int>(d.t.size());
  fit.converged = true;
  law.canonical_order(fit.p);
  fit.sse_w = best;
  Eigen::VectorXd r;
  residuals(law, fit.p, d, fit.floor_rel, r);
  const int p_n = static_cast<int>(fit.p.size());
  fit.n = n;
  fit.n_params = p_n;
  fit.sigma = std::sqrt(best / std::max(1, n - p_n));
  {
    double s = 0;
    for (int i = 0; i < n; ++i) s += r(i) * r(i) / d.w(i);
    fit.rms_log = std::sqrt(s / n);
  }
  return r;
}

/// Samples for reports: time, ln A, fitted ln A, weight.
void storeSamples(const RingdownEnvelope& env, const std::vector<size_t>& used,
                  const RingdownLaw& law, const Data& d, RingdownFit& fit) {
  const int n = static_cast<int>(d.t.size());
  for (int i = 0; i < n; ++i) {
    fit.t_s.push_back(env.t_s[used[i]]);
    fit.log_amplitude.push_back(env.log_amplitude[used[i]]);
    fit.fitted.push_back(law.logAmplitude(fit.p, d.t(i), fit.floor_rel) + fit.log_a_ref);
    fit.weight.push_back(d.w(i));
  }
}

/// Step 7: intervals under the residuals' serial correlation
/// (estimate/uncertainty/ar_noise_covariance.h); the Cramer-Rao bound for white noise beside them.
/// Returns the intervals' quantile z.
double storeCovariance(const RingdownLaw& law, const Data& d, const Eigen::VectorXd& r,
                       const RingdownFitOptions& options, RingdownFit& fit) {
  Eigen::MatrixXd J;
  jacobian(law, fit.p, d, fit.floor_rel, J);
  const ArNoiseCovariance rc = arNoiseCovariance(J, r);
  fit.rank = rc.rank;
  fit.rho1 = rc.rho1;
  fit.cov_crb = rc.crb;
  fit.cov_hac = rc.covariance;
  fit.noise_ar_order = static_cast<int>(rc.ar.size());
  fit.noise_ar = rc.ar;
  fit.long_run_factor = rc.long_run_factor;
  fit.effective_n = rc.effective_n;
  fit.interval_method = rc.method + "; " + fit.error_model + " error model";
  return studentQuantile(options.confidence, std::max(1, static_cast<int>(rc.student_df)));
}

/// Local Q over one amplitude bin: a straight ln A fit over the samples idx (HAC interval).
RingdownQBin qBin(const Data& d, const std::vector<int>& idx, const RingdownFitOptions& options,
                  double qc, const RingdownFit& fit) {
  const double T = fit.t_scale_s;
  const int m = static_cast<int>(idx.size());
  Eigen::MatrixXd X(m, 2);
  Eigen::VectorXd Y(m);
  const double tb = d.t(idx.front()), ts = std::max(d.t(idx.back()) - tb, kMinBinHalfWidth);
  double lvl = 0;
  for (int k = 0; k < m; ++k) {
    const double sw = std::sqrt(d.w(idx[k]));
    X(k, 0) = sw, X(k, 1) = -sw * (d.t(idx[k]) - tb) / ts, Y(k) = sw * d.y(idx[k]);
    lvl += fit.fitted[idx[k]];
  }
  lvl /= m;
  const Eigen::VectorXd c = X.colPivHouseholderQr().solve(Y);
  const Eigen::VectorXd res = Y - X * c;
  const ArNoiseCovariance hb = arNoiseCovariance(X, res);
  RingdownValue rate;
  const double zb =
      studentQuantile(options.confidence, std::max(1, static_cast<int>(hb.student_df)));
  rate.value = c(1) / ts;  // in 1/T
  rate.std = std::sqrt(std::max(0.0, hb.covariance(1, 1))) / ts;
  rate.ci_low = rate.value - zb * rate.std, rate.ci_high = rate.value + zb * rate.std;
  RingdownQBin qb;
  qb.n = m;
  qb.t_start_s = fit.t_s[idx.front()], qb.t_end_s = fit.t_s[idx.back()];
  qb.amplitude = std::exp(lvl);
  qb.level_db = lvl * kDbPerNeper;
  qb.decay_rate_1_s = rate.value / T;
  qb.Q = ringdownQFromRate(rate, qc);
  return qb;
}

/// Step 10: Q against amplitude: straight ln A fits over bins of equal fitted-level drop.
void storeQVsAmplitude(const Data& d, const RingdownFitOptions& options, RingdownFit& fit) {
  const int n = static_cast<int>(d.t.size());
  const double qc = M_PI * fit.frequency_hz * fit.t_scale_s;  // Q = qc / rate (rate in 1/T)
  const double drop_db = (fit.fitted.front() - fit.fitted.back()) * kDbPerNeper;
  int bins = options.q_bins > 0
                 ? options.q_bins
                 : static_cast<int>(std::min(options.max_auto_q_bins,
                                             std::floor(drop_db / options.db_per_q_bin)));
  bins = std::min(bins, n / options.samples_per_q_bin);
  if (bins >= 2 && fit.frequency_hz > 0.0) {
    const double l0 = fit.fitted.front(), l1 = fit.fitted.back();
    int i = 0;
    for (int b = 0; b < bins; ++b) {
      const double edge = l0 + (l1 - l0) * (b + 1) / bins;
      std::vector<int> idx;
      while (i < n && (b == bins - 1 || fit.fitted[i] >= edge)) idx.push_back(i++);
      if (static_cast<int>(idx.size()) < options.min_samples_in_q_bin) continue;
      fit.q_vs_amplitude.push_back(qBin(d, idx, options, qc, fit));
    }
  }
}

}  // namespace

void requirePositiveQ(const RingdownFit& fit, const RingdownSegment& seg) {
  const auto q = fit.derived.find("Q");
  if (q == fit.derived.end() || (std::isfinite(q->second.value) && q->second.value > 0.0)) return;
  std::ostringstream m;
  m << "ring-down: the fitted span does not decay (Q " << q->second.value << " from " << fit.model
    << " over " << seg.t_start_s << " .. " << seg.t_end_s << " s; " << seg.why << ")";
  throw AnalysisError(m.str());
}

std::vector<std::string> RingdownFitOptions::validate() const {
  std::vector<std::string> p;
  if (!(confidence > 0.0 && confidence < 1.0)) p.push_back("confidence must be in (0, 1)");
  if (error_model != "auto" && error_model != "log" && error_model != "additive")
    p.push_back("error_model must be auto, log or additive");
  if (q_bins < 0 || q_bins > 20) p.push_back("q_bins must be in [0, 20]");
  return p;
}

std::vector<Eigen::VectorXd> ringdownStarts(const std::string& model, const RingdownFit& lin) {
  return ringdownLaw(model).starts(lin);
}

RingdownFit fitRingdown(const RingdownEnvelope& env, const RingdownSegment& seg,
                        const std::string& model, const RingdownFitOptions& options,
                        const std::vector<Eigen::VectorXd>& starts) {
  const auto problems = options.validate();
  if (!problems.empty()) throw InputError("ring-down fit: " + problems.front());
  const RingdownLaw& law = ringdownLaw(model);
  RingdownFit fit;
  fit.model = model;
  fit.names = law.parameters;
  fit.frequency_hz = env.frequency_hz;
  // 1-2. The span's samples, normalized; the held-out ones left out.
  std::vector<size_t> used = normalizeSpan(env, seg, options, fit);
  Data d = fittedSamples(env, options, fit, used);
  const int n = static_cast<int>(used.size());
  // 3-4. Error model and weights.
  setWeights(chooseErrorModel(d, options, fit), options, d);
  // 5. Fit from each starting point, the best kept.
  const double best = fitBestStart(law, startingPoints(env, seg, law, options, starts, d), d, fit);
  // 6. Canonical order, residual summaries.
  const Eigen::VectorXd r = summarizeFit(law, d, best, fit);
  if (!options.details) {
    storeSamples(env, used, law, d, fit);
    return fit;
  }
  // 7. Intervals.
  const double z = storeCovariance(law, d, r, options, fit);
  // 8. Physical values (the law's readout). Time scale T: rates in 1/T -> 1/s divide by T.
  const double T = fit.t_scale_s;
  const double qc = M_PI * fit.frequency_hz * T;  // Q = qc / rate (rate in 1/T)
  const RingdownReadout readout{law, fit, z, T, qc, std::exp(fit.log_a_ref), d.t(0), d.t(n - 1)};
  law.readout(readout);
  // 9. Samples for reports.
  storeSamples(env, used, law, d, fit);
  // 10. Q against amplitude.
  storeQVsAmplitude(d, options, fit);
  return fit;
}

double ringdownPredict(const RingdownFit& fit, double t_s) {
  return ringdownLogAmplitude(fit.model, fit.p, (t_s - fit.t_ref_s) / fit.t_scale_s,
                              fit.floor_rel) +
         fit.log_a_ref;
}

}  // namespace cvg_bench

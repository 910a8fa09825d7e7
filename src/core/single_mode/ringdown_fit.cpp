#include "cvg_bench/core/single_mode/ringdown_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>

#include "cvg_bench/core/estimate/numeric_least_squares.h"
#include "cvg_bench/core/estimate/student_t.h"
#include "cvg_bench/core/model/errors.h"
#include "cvg_bench/core/model/gamma_nl_conventions.h"
#include "cvg_bench/core/model/sample_median.h"
#include "cvg_bench/core/single_mode/ringdown_envelope.h"
#include "cvg_bench/core/single_mode/ringdown_intervals.h"
#include "cvg_bench/core/single_mode/ringdown_models.h"

namespace cvg_bench {
namespace {

const double kInf = std::numeric_limits<double>::infinity();

double median(const std::vector<double>& v) {
  return sampleMedian(v);
}

struct Data {
  Eigen::VectorXd t, y, w;  // normalized time, ln A', weights
};

/// Weighted residuals sqrt(w) (y - f(p)); false when the model is not finite somewhere.
bool residuals(const std::string& model, const Eigen::VectorXd& p, const Data& d, double floor_rel,
               Eigen::VectorXd& r) {
  r.resize(d.t.size());
  for (int i = 0; i < d.t.size(); ++i) {
    const double f = ringdownLogAmplitude(model, p, d.t(i), floor_rel);
    if (!std::isfinite(f)) return false;
    r(i) = std::sqrt(d.w(i)) * (d.y(i) - f);
  }
  return true;
}

/// Jacobian of the weighted model sqrt(w) f(p) (= -d r / dp) by central differences.
bool jacobian(const std::string& model, const Eigen::VectorXd& p, const Data& d, double floor_rel,
              Eigen::MatrixXd& J) {
  const ResidualFunction r = [&](const Eigen::VectorXd& q, Eigen::VectorXd& out) {
    return residuals(model, q, d, floor_rel, out);
  };
  if (!centralDifferenceJacobian(r, p, J)) return false;
  J = -J;
  return true;
}

/// Standard error and interval of a function of the parameters by the delta method; `rate` gives
/// the interval of a positive rate r, and value_of maps it (e.g. Q = c / r, decreasing).
RingdownValue deltaValue(const std::function<double(const Eigen::VectorXd&)>& fn,
                         const Eigen::VectorXd& p, const Eigen::MatrixXd& cov,
                         const Eigen::MatrixXd& cov_crb, double z) {
  RingdownValue v;
  v.value = fn(p);
  const ResidualFunction value = [&](const Eigen::VectorXd& q, Eigen::VectorXd& out) {
    out = Eigen::VectorXd::Constant(1, fn(q));
    return true;
  };
  Eigen::MatrixXd g;
  // A value that is not finite next to p leaves a NaN gradient (its std then reads 0, as before).
  const Eigen::VectorXd grad = centralDifferenceJacobian(value, p, g)
                                   ? Eigen::VectorXd(g.row(0).transpose())
                                   : Eigen::VectorXd::Constant(p.size(), NAN);
  v.std = std::sqrt(std::max(0.0, grad.dot(cov * grad)));
  v.crb_std = std::sqrt(std::max(0.0, grad.dot(cov_crb * grad)));
  v.ci_low = v.value - z * v.std;
  v.ci_high = v.value + z * v.std;
  return v;
}

/// Q = c / rate. The interval is the delta method on ln Q = ln c - ln rate (sd of ln Q = the
/// rate's relative sd), with the rate's own quantile: positive and of nonzero width for every
/// decaying fit, where mapping the rate's symmetric interval opened above as soon as it reached 0
/// (a 35 dB decay with strongly correlated residuals and few effective samples printed
/// [1.4e6, inf]). A rate that is not positive has no Q interval (-inf, inf).
RingdownValue qFromRate(const RingdownValue& rate, double c) {
  RingdownValue q;
  q.value = c / rate.value;
  q.std = c * rate.std / (rate.value * rate.value);
  q.crb_std = c * rate.crb_std / (rate.value * rate.value);
  if (!(rate.value > 0.0)) {
    q.ci_low = -kInf, q.ci_high = kInf;
    return q;
  }
  const double z = rate.std > 0.0 ? (rate.ci_high - rate.value) / rate.std : 0.0;
  const double half = z * rate.std / rate.value;  // half-width of ln Q's interval
  if (!(half >= 0.0) || !std::isfinite(half)) {   // no usable sd (infinite or NaN): unbounded
    q.ci_low = 0.0, q.ci_high = kInf;
    return q;
  }
  q.ci_low = q.value * std::exp(-half);
  q.ci_high = q.value * std::exp(half);
  return q;
}

RingdownValue scaled(RingdownValue v, double s) {
  v.value *= s, v.std *= std::fabs(s), v.crb_std *= std::fabs(s);
  double lo = v.ci_low * s, hi = v.ci_high * s;
  v.ci_low = std::min(lo, hi), v.ci_high = std::max(lo, hi);
  return v;
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
  const double a = lin.p(0), g = std::max(lin.p(1), 0.05);
  std::vector<Eigen::VectorXd> s;
  if (model == "linear") {
    s.push_back(lin.p);
  } else if (model == "gamma_nl" || model == "gamma_a") {
    for (double frac : {0.0, 0.5, -0.3}) {
      Eigen::VectorXd p(3);
      // Split the rate at the start between g0 and the amplitude-dependent part.
      p << a, g * (1.0 - frac),
          g * frac * (model == "gamma_nl" ? std::exp(-2.0 * a) : std::exp(-a));
      s.push_back(p);
    }
  } else if (model == "two_stage") {
    for (double ratio : {3.0, 10.0}) {
      for (double lvl : {-1.0, -2.5}) {
        Eigen::VectorXd p(4);
        p << a, g * ratio, a + lvl, g * 0.7;
        s.push_back(p);
      }
    }
  } else if (model == "beat") {
    // Residual periodogram of the linear fit: peaks between 1.5 cycles per span and a quarter of
    // the sample rate (at most 256 cycles per span) give the split w; the modulation depth m
    // gives A2/A1 ~ m. The residuals are averaged into at most 1024 equal time bins first. Two
    // periodograms: of the residuals as they are, and weighted by the error model (the quiet
    // start counts more than the noisy end near the floor), and of the first 40 % of the span only
    // (a second mode that decays faster modulates the start alone); the highest peaks of each.
    const int n = static_cast<int>(lin.t_s.size());
    const int nb = std::min(n, 1024);
    std::vector<double> seen;
    for (int variant = 0; variant < 3; ++variant) {
      const bool weighted = variant == 1;
      const double t_cut = variant == 2 ? 0.4 : 1.0;
      std::vector<double> tt(nb, 0.0), rr(nb, 0.0), ww(nb, 0.0);
      std::vector<int> cnt(nb, 0);
      for (int i = 0; i < n; ++i) {
        const double tn = (lin.t_s[i] - lin.t_ref_s) / lin.t_scale_s;
        if (tn > t_cut) break;
        const int b = std::min(nb - 1, std::max(0, static_cast<int>(tn / t_cut * nb)));
        const double wt = weighted && i < static_cast<int>(lin.weight.size()) ? lin.weight[i] : 1.0;
        tt[b] += tn, rr[b] += wt * (lin.log_amplitude[i] - lin.fitted[i]), ww[b] += wt, ++cnt[b];
      }
      int m_used = 0;
      double w_sum = 0.0;
      for (int b = 0; b < nb; ++b)
        if (cnt[b] > 0) {
          tt[m_used] = tt[b] / cnt[b], rr[m_used] = rr[b] / cnt[b], ww[m_used] = ww[b] / cnt[b];
          w_sum += ww[m_used], ++m_used;
        }
      tt.resize(m_used), rr.resize(m_used);
      const double w_max = M_PI * m_used / 2.0;
      std::vector<std::pair<double, double>> peaks;  // power, w
      double prev2 = 0, prev1 = 0, w_prev = 0;
      const double dw = M_PI / 4.0;
      for (double w = 1.5 * 2 * M_PI; w < w_max; w += dw) {
        double c = 0, sn = 0;
        for (int i = 0; i < m_used; ++i)
          c += rr[i] * std::cos(w * tt[i]), sn += rr[i] * std::sin(w * tt[i]);
        const double pw = c * c + sn * sn;
        if (prev1 > prev2 && prev1 >= pw) peaks.emplace_back(prev1, w_prev);
        prev2 = prev1, prev1 = pw, w_prev = w;
      }
      std::sort(peaks.rbegin(), peaks.rend());
      int taken = 0;
      for (size_t k = 0; k < peaks.size() && taken < (variant == 0 ? 3 : 2); ++k) {
        const double w = peaks[k].second;
        bool dup = false;
        for (double v : seen) dup |= std::fabs(v - w) < 1.5 * dw;
        if (dup) continue;
        seen.push_back(w), ++taken;
        double c = 0, sn = 0;
        for (int i = 0; i < m_used; ++i)
          c += rr[i] * std::cos(w * tt[i]), sn += rr[i] * std::sin(w * tt[i]);
        const double norm = weighted ? std::max(w_sum, 1e-300) : m_used;
        const double m = std::min(0.9, std::max(1e-3, 2.0 * std::sqrt(c * c + sn * sn) / norm));
        const double phi = std::atan2(-sn, c);
        Eigen::VectorXd p(6);
        p << a, g, a + std::log(m), g, w, phi;
        s.push_back(p);
      }
    }
    if (s.empty()) {
      Eigen::VectorXd p(6);
      p << a, g, a - 2.0, g, 4.0 * M_PI, 0.0;
      s.push_back(p);
    }
  } else {
    ringdownParameterNames(model);  // throws for unknown names
  }
  return s;
}

RingdownFit fitRingdown(const RingdownEnvelope& env, const RingdownSegment& seg,
                        const std::string& model, const RingdownFitOptions& options,
                        const std::vector<Eigen::VectorXd>& starts) {
  const auto problems = options.validate();
  if (!problems.empty()) throw InputError("ring-down fit: " + problems.front());
  RingdownFit fit;
  fit.model = model;
  fit.names = ringdownParameterNames(model);
  fit.frequency_hz = env.frequency_hz;
  std::vector<size_t> used;
  for (size_t i = seg.i_start; i < seg.i_end; ++i)
    if (!seg.dropout[i] && std::isfinite(env.log_amplitude[i])) used.push_back(i);
  if (used.size() < fit.names.size() + 4)
    throw AnalysisError("ring-down: " + std::to_string(used.size()) + " samples in the span for " +
                        std::to_string(fit.names.size()) + " parameters of model " + model);
  fit.t_ref_s = env.t_s[used.front()];
  fit.t_scale_s = std::max(env.t_s[used.back()] - fit.t_ref_s, 1e-300);
  {
    std::vector<double> first;
    for (size_t i = 0; i < std::min<size_t>(used.size(), 5); ++i)
      first.push_back(env.log_amplitude[used[i]]);
    fit.log_a_ref = median(first);
  }
  // A floor the decay only bends towards counts for the model and the noise as a confirmed one.
  fit.floor_rel = seg.has_floor ? std::exp(seg.floor_log_amplitude - fit.log_a_ref)
                  : std::isfinite(seg.suspected_floor_log_amplitude)
                      ? std::exp(seg.suspected_floor_log_amplitude - fit.log_a_ref)
                      : 0.0;
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
  if (n < static_cast<int>(fit.names.size()) + 4)
    throw AnalysisError("ring-down: " + std::to_string(n) + " samples fitted for " +
                        std::to_string(fit.names.size()) + " parameters of model " + model);
  Data d;
  d.t.resize(n), d.y.resize(n), d.w.resize(n);
  for (int i = 0; i < n; ++i) {
    d.t(i) = (env.t_s[used[i]] - fit.t_ref_s) / fit.t_scale_s;
    d.y(i) = env.log_amplitude[used[i]] - fit.log_a_ref;
  }

  // Error model from the scatter about a local quadratic in eight time bins (not from
  // sample-to-sample differences, which correlated detector noise makes small): var = s_m^2 +
  // s_a^2 exp(-2 level).
  const int nb = std::max(2, std::min(8, n / 12));
  std::vector<double> var_k, lvl_k;
  for (int b = 0; b < nb; ++b) {
    const int lo = b * n / nb, hi = (b + 1) * n / nb;
    if (hi - lo < 6) continue;
    Eigen::MatrixXd Xq(hi - lo, 3);
    Eigen::VectorXd Yq(hi - lo);
    const double tm = 0.5 * (d.t(lo) + d.t(hi - 1)), th = std::max(d.t(hi - 1) - tm, 1e-12);
    for (int i = lo; i < hi; ++i) {
      const double u = (d.t(i) - tm) / th;
      Xq(i - lo, 0) = 1.0, Xq(i - lo, 1) = u, Xq(i - lo, 2) = u * u, Yq(i - lo) = d.y(i);
    }
    const Eigen::VectorXd eq = Yq - Xq * Xq.colPivHouseholderQr().solve(Yq);
    std::vector<double> dd, lv;
    for (int i = 0; i < eq.size(); ++i) dd.push_back(std::fabs(eq(i)));
    for (int i = lo; i < hi; ++i) lv.push_back(d.y(i));
    const double s = 1.4826 * median(dd);
    var_k.push_back(std::max(s * s, 1e-30));
    lvl_k.push_back(median(lv));
  }
  double s_m2 = 0.0, s_a2 = 0.0;
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
    s_m2 = c(0), s_a2 = c(1);
  } else if (!var_k.empty()) {
    s_m2 = var_k.front();
  }
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
      (options.error_model == "auto" && add_low > 1.0 * s_m2 &&
       ((var_k.size() >= 2 && var_k.back() > 2.0 * var_k.front()) || s_a2_floor > 0.0));
  {
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
    fit.error_model = additive ? "additive" : "log";
    fit.error_model_why = w.str();
  }
  if (!additive) s_a2 = 0.0;
  // Every record carries some relative (log-scale) noise: with the multiplicative term at zero
  // the weights grow as A^2 and the first samples (a fast first stage, a corner) outweigh the
  // rest of the decay by orders of magnitude. A quarter of the quietest bin's scatter bounds it.
  if (additive && !var_k.empty())
    s_m2 = std::max(s_m2, 0.25 * *std::min_element(var_k.begin(), var_k.end()));
  if (s_m2 <= 0.0 && s_a2 <= 0.0) s_m2 = 1.0;
  // Weights at a smoothed level (5-point running mean), fixed during the fit.
  for (int i = 0; i < n; ++i) {
    double acc = 0;
    int c = 0;
    for (int j = std::max(0, i - 2); j <= std::min(n - 1, i + 2); ++j) acc += d.y(j), ++c;
    const double lvl = acc / c;
    d.w(i) = 1.0 / (s_m2 + s_a2 * std::exp(-2.0 * lvl));
  }
  // Weights at the observed level correlate with the noise of the same samples (a sample lifted
  // by noise reads as quieter and weighs more), which pulls the tail up and the rate down under
  // additive noise (Q 1-5 % high). The level for the weights is therefore a smooth of the whole
  // span instead: a weighted Legendre polynomial of degree 6 in time (leverage 7 / n per sample),
  // refitted once with its own weights. The same for every model, so criteria compare.
  if (additive && n > 40) {
    const int half = std::max(10, n / 32);
    Eigen::VectorXd y_lo(n), y_hi(n);
    for (int i = 0; i < n; ++i) {
      const int a = std::max(0, i - half), len = std::min(n - 1, i + half) - a + 1;
      y_lo(i) = d.y.segment(a, len).minCoeff(), y_hi(i) = d.y.segment(a, len).maxCoeff();
    }
    for (int pass = 0; pass < 2; ++pass) {
      const int deg = 6;
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
        const double lvl =
            std::min(std::max(X.row(i).dot(c) / std::sqrt(d.w(i)), y_lo(i)), y_hi(i));
        d.w(i) = 1.0 / (s_m2 + s_a2 * std::exp(-2.0 * lvl));
      }
    }
  }
  // Normalize the weights to mean 1 (sigma then reads in units of the mean sd).
  d.w /= d.w.mean();

  // Starting points: the weighted straight line for linear, else given or derived from it.
  std::vector<Eigen::VectorXd> st = starts;
  if (st.empty()) {
    Eigen::MatrixXd X(n, 2);
    Eigen::VectorXd Y(n);
    for (int i = 0; i < n; ++i) {
      const double sw = std::sqrt(d.w(i));
      X(i, 0) = sw, X(i, 1) = -sw * d.t(i), Y(i) = sw * d.y(i);
    }
    Eigen::VectorXd lin = X.colPivHouseholderQr().solve(Y);
    if (model == "linear") {
      st.push_back(lin);
    } else {
      RingdownFitOptions lean = options;
      lean.details = false;
      RingdownFit base = fitRingdown(env, seg, "linear", lean);
      st = ringdownStarts(model, base);
    }
  }
  double best = kInf;
  for (auto p : st) {
    double sse = kInf;
    if (p.size() != static_cast<int>(fit.names.size())) continue;
    const ResidualFunction weighted = [&](const Eigen::VectorXd& q, Eigen::VectorXd& r) {
      return residuals(model, q, d, fit.floor_rel, r);
    };
    // A fit whose Jacobian cannot be evaluated at its answer (a law at the edge of its domain)
    // has no covariance: that start is dropped.
    Eigen::MatrixXd J_at;
    if (!minimizeSumOfSquares(weighted, p, sse) || !jacobian(model, p, d, fit.floor_rel, J_at))
      continue;
    if (sse < best) best = sse, fit.p = p;
  }
  if (!std::isfinite(best))
    throw AnalysisError("ring-down: model " + model + " could not be fitted (no finite start)");
  fit.converged = true;
  // Canonical order for two-component models: component 1 is the faster (two_stage) / the
  // larger at the start (beat).
  if (model == "two_stage" && fit.p(1) < fit.p(3)) {
    std::swap(fit.p(0), fit.p(2));
    std::swap(fit.p(1), fit.p(3));
  }
  if (model == "beat") {
    if (fit.p(2) > fit.p(0)) {
      std::swap(fit.p(0), fit.p(2));
      std::swap(fit.p(1), fit.p(3));
      fit.p(4) = -fit.p(4), fit.p(5) = -fit.p(5);
    }
    if (fit.p(4) < 0.0) fit.p(4) = -fit.p(4), fit.p(5) = -fit.p(5);
    fit.p(5) = std::remainder(fit.p(5), 2.0 * M_PI);
  }
  fit.sse_w = best;
  Eigen::VectorXd r;
  residuals(model, fit.p, d, fit.floor_rel, r);
  const int p_n = static_cast<int>(fit.p.size());
  fit.n = n;
  fit.n_params = p_n;
  fit.sigma = std::sqrt(best / std::max(1, n - p_n));
  {
    double s = 0;
    for (int i = 0; i < n; ++i) s += r(i) * r(i) / d.w(i);
    fit.rms_log = std::sqrt(s / n);
  }
  if (!options.details) {
    for (int i = 0; i < n; ++i) {
      fit.t_s.push_back(env.t_s[used[i]]);
      fit.log_amplitude.push_back(env.log_amplitude[used[i]]);
      fit.fitted.push_back(ringdownLogAmplitude(model, fit.p, d.t(i), fit.floor_rel) +
                           fit.log_a_ref);
      fit.weight.push_back(d.w(i));
    }
    return fit;
  }
  // Intervals under the residuals' serial correlation (ringdown_intervals.h); the Cramer-Rao
  // bound for white noise beside them.
  Eigen::MatrixXd J;
  jacobian(model, fit.p, d, fit.floor_rel, J);
  const RingdownCovariance rc = ringdownCovariance(J, r);
  fit.rank = rc.rank;
  fit.rho1 = rc.rho1;
  fit.cov_crb = rc.crb;
  fit.cov_hac = rc.covariance;
  fit.noise_ar_order = static_cast<int>(rc.ar.size());
  fit.noise_ar = rc.ar;
  fit.long_run_factor = rc.long_run_factor;
  fit.effective_n = rc.effective_n;
  fit.interval_method = rc.method + "; " + fit.error_model + " error model";
  const double z =
      studentQuantile(options.confidence, std::max(1, static_cast<int>(rc.student_df)));

  // Physical values. Time scale T: rates in 1/T -> 1/s divide by T.
  const double T = fit.t_scale_s;
  const double qc = M_PI * fit.frequency_hz * T;  // Q = qc / rate (rate in 1/T)
  auto param = [&](int k) {
    return deltaValue([k](const Eigen::VectorXd& q) { return q(k); }, fit.p, fit.cov_hac,
                      fit.cov_crb, z);
  };
  auto putRate = [&](const std::string& name, const RingdownValue& rate) {
    fit.parameters[name] = scaled(rate, 1.0 / T);
  };
  auto putQ = [&](const std::string& name, const RingdownValue& rate) {
    if (fit.frequency_hz > 0.0) fit.derived[name] = qFromRate(rate, qc);
  };
  const double a_ref = std::exp(fit.log_a_ref);
  if (model == "linear") {
    const RingdownValue g = param(1);
    putRate("decay_rate_1_s", g);
    putQ("Q", g);
    RingdownValue tau = qFromRate(g, T);
    fit.derived["tau_s"] = tau;
    if (g.value < 0.0) fit.flags.push_back("negative_damping");
  } else if (model == "gamma_nl" || model == "gamma_a") {
    const bool sq = model == "gamma_nl";
    const RingdownValue g0 = param(1);
    const RingdownValue gn = param(2);
    putRate("decay_rate_1_s", g0);
    // Physical coefficient: rate = g0 + gamma_nl A^2 (A in the file's unit), or + gamma_a A.
    fit.parameters[model] = scaled(gn, 1.0 / (T * (sq ? a_ref * a_ref : a_ref)));
    // The model term's coefficient (gamma_nl_conventions.h): 8 times the ring-down's.
    if (sq)
      fit.derived["gamma_nl_term"] = scaled(fit.parameters[model], kGammaNlTermPerRingdownRate);
    putQ("Q0", g0);
    const RingdownValue start_rate = deltaValue(
        [sq](const Eigen::VectorXd& q) { return q(1) + q(2) * std::exp((sq ? 2.0 : 1.0) * q(0)); },
        fit.p, fit.cov_hac, fit.cov_crb, z);
    putQ("Q_start", start_rate);
    // Q of the span: the law's mean decay rate over the fitted span (the level it drops over the
    // span per unit time, floor left out), i.e. what a straight line through the same decay
    // gives; the value a ring-down Q is compared by (docs/validation_ringdown_real.md). Q0 is the
    // zero-amplitude limit, Q_start the rate at the span's first sample.
    const double t0 = d.t(0), t1 = d.t(n - 1);
    const std::string law = model;
    const RingdownValue span_rate = deltaValue(
        [law, t0, t1](const Eigen::VectorXd& q) {
          return (ringdownLogAmplitude(law, q, t0, 0.0) - ringdownLogAmplitude(law, q, t1, 0.0)) /
                 (t1 - t0);
        },
        fit.p, fit.cov_hac, fit.cov_crb, z);
    putQ("Q", span_rate);
    fit.derived["tau_s"] = qFromRate(span_rate, T);
    if (g0.value < 0.0 || start_rate.value < 0.0) fit.flags.push_back("negative_damping");
    if (gn.value < 0.0) fit.flags.push_back("negative_amplitude_dependent_damping");
  } else if (model == "beat" || model == "two_stage") {
    const RingdownValue d1 = param(1), d2 = param(3);
    putRate("decay_rate_1_1_s", d1);
    putRate("decay_rate_2_1_s", d2);
    putQ("Q_mode1", d1);
    putQ("Q_mode2", d2);
    // Q: the mode that dominates the span (beat: larger at the start; two_stage: the slow,
    // late stage).
    const RingdownValue& main = model == "beat" ? d1 : d2;
    putQ("Q", main);
    fit.derived["tau_s"] = qFromRate(main, T);
    fit.derived["amplitude_ratio"] =
        deltaValue([](const Eigen::VectorXd& q) { return std::exp(q(2) - q(0)); }, fit.p,
                   fit.cov_hac, fit.cov_crb, z);
    if (model == "beat") {
      fit.derived["frequency_split_hz"] = scaled(param(4), 1.0 / (2.0 * M_PI * T));
      fit.derived["frequency_split_rad_s"] = scaled(param(4), 1.0 / T);
      // Difference of the two modes' amplitude decay rates: the 2-D model's damping anisotropy
      // (docs/paper.md: modes along the damping axes decay at gamma +- anisotropy / 2).
      fit.derived["damping_anisotropy_1_s"] =
          deltaValue([T](const Eigen::VectorXd& q) { return (q(1) - q(3)) / T; }, fit.p,
                     fit.cov_hac, fit.cov_crb, z);
    }
    if (d1.value < 0.0 || d2.value < 0.0) fit.flags.push_back("negative_damping");
  }

  // Samples for reports.
  for (int i = 0; i < n; ++i) {
    fit.t_s.push_back(env.t_s[used[i]]);
    fit.log_amplitude.push_back(env.log_amplitude[used[i]]);
    fit.fitted.push_back(ringdownLogAmplitude(model, fit.p, d.t(i), fit.floor_rel) + fit.log_a_ref);
    fit.weight.push_back(d.w(i));
  }

  // Q against amplitude: straight ln A fits over bins of equal fitted-level drop.
  const double drop_db = (fit.fitted.front() - fit.fitted.back()) * kDbPerNeper;
  int bins = options.q_bins > 0 ? options.q_bins
                                : static_cast<int>(std::min(8.0, std::floor(drop_db / 3.0)));
  bins = std::min(bins, n / 12);
  if (bins >= 2 && fit.frequency_hz > 0.0) {
    const double l0 = fit.fitted.front(), l1 = fit.fitted.back();
    int i = 0;
    for (int b = 0; b < bins; ++b) {
      const double edge = l0 + (l1 - l0) * (b + 1) / bins;
      std::vector<int> idx;
      while (i < n && (b == bins - 1 || fit.fitted[i] >= edge)) idx.push_back(i++);
      const int m = static_cast<int>(idx.size());
      if (m < 10) continue;
      Eigen::MatrixXd X(m, 2);
      Eigen::VectorXd Y(m);
      const double tb = d.t(idx.front()), ts = std::max(d.t(idx.back()) - tb, 1e-12);
      double lvl = 0;
      for (int k = 0; k < m; ++k) {
        const double sw = std::sqrt(d.w(idx[k]));
        X(k, 0) = sw, X(k, 1) = -sw * (d.t(idx[k]) - tb) / ts, Y(k) = sw * d.y(idx[k]);
        lvl += fit.fitted[idx[k]];
      }
      lvl /= m;
      const Eigen::VectorXd c = X.colPivHouseholderQr().solve(Y);
      const Eigen::VectorXd res = Y - X * c;
      const RingdownCovariance hb = ringdownCovariance(X, res);
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
      qb.Q = qFromRate(rate, qc);
      fit.q_vs_amplitude.push_back(qb);
    }
  }
  return fit;
}

double ringdownPredict(const RingdownFit& fit, double t_s) {
  return ringdownLogAmplitude(fit.model, fit.p, (t_s - fit.t_ref_s) / fit.t_scale_s,
                              fit.floor_rel) +
         fit.log_a_ref;
}

}  // namespace cvg_bench

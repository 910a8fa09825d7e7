#include "cvg_bench/core/single_mode/ringdown_filter.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>

#include "cvg_bench/core/common/sample_median.h"
#include "cvg_bench/core/estimate/numeric_least_squares.h"
#include "cvg_bench/core/estimate/uncertainty/ar_noise_covariance.h"
#include "cvg_bench/core/single_mode/ringdown_envelope.h"
#include "cvg_bench/core/single_mode/ringdown_models.h"

namespace cvg_bench {
namespace {

/// The orders whose closed form (ringdownFilterPowerCorrelation) and correlation time are
/// tabulated: 1..kMaxOrder equal real poles (RingdownDetectorFilterOptions::max_order is at most
/// this).
constexpr int kMaxOrder = 4;

double median(const std::vector<double>& v) {
  return sampleMedian(v);
}

double factorial(int k) {
  double f = 1.0;
  for (int i = 2; i <= k; ++i) f *= i;
  return f;
}

/// Integral of rho_n(x)^2 over x >= 0 (the power's correlation time over T).
double correlationTime(int order) {
  static const double c[kMaxOrder] = {0.5, 1.25, 1.75, 2.145};
  return c[std::max(1, std::min(kMaxOrder, order)) - 1];
}

/// Sum of squares of the power autocorrelation r[1..K] against (rho_n(k / T)^2 - b) / (1 - b)
/// (T in samples): b >= 0 is the bias of an autocorrelation taken about an estimated mean and
/// trend (about twice the correlation time over the stretch's length m), fitted in closed form,
/// at most bias_correlation_times correlation times over m and max_bias.
double correlationMisfit(int order, double t_samples, const std::vector<double>& r, double m,
                         const RingdownDetectorFilterOptions& o) {
  double sxy = 0.0, sxx = 0.0;
  for (size_t k = 1; k < r.size(); ++k) {
    const double x = ringdownFilterPowerCorrelation(order, k / t_samples) - 1.0;
    sxy += x * (r[k] - 1.0), sxx += x * x;
  }
  const double b_max =
      std::min(o.max_bias, o.bias_correlation_times * correlationTime(order) * t_samples / m);
  const double alpha = std::min(1.0 / (1.0 - b_max), std::max(1.0, sxx > 0.0 ? sxy / sxx : 1.0));
  double s = 0.0;
  for (size_t k = 1; k < r.size(); ++k) {
    const double e =
        r[k] - 1.0 - alpha * (ringdownFilterPowerCorrelation(order, k / t_samples) - 1.0);
    s += e * e;
  }
  return s;
}

/// Step 1: the floor stretch's first sample.
size_t floorStretchStart(const RingdownEnvelope& env, const RingdownSegment& seg,
                         double decay_rate_1_s, const RingdownDetectorFilterOptions& o) {
  const auto& t = env.t_s;
  const auto& y = env.log_amplitude;
  // Level at the span's end above the floor; the stretch starts below_floor_db below the floor
  // on the decay's straight continuation.
  std::vector<double> last;
  for (size_t i = seg.i_end > o.end_level_samples ? seg.i_end - o.end_level_samples : 0;
       i < seg.i_end && i < y.size(); ++i)
    if (!seg.dropout[i] && std::isfinite(y[i])) last.push_back(y[i]);
  const double above = last.empty() ? o.default_above_floor_db / kDbPerNeper
                                    : median(last) - seg.floor_log_amplitude;
  const double t_a = seg.t_end_s + (above + o.below_floor_db / kDbPerNeper) / decay_rate_1_s;
  size_t a = 0;
  while (a < t.size() && t[a] < t_a) ++a;
  return a;
}

/// The floor stretch's power re the floor, per sample of [a, a + m).
struct FloorPower {
  std::vector<double> p;    ///< less the fitted residual signal and mean (when nv is enough)
  std::vector<bool> valid;  ///< not a drop-out, finite
  int nv = 0;               ///< valid samples
};

/// Step 3 (the fit of c0 and c1 only with min_floor_samples valid samples or more).
FloorPower floorPower(const RingdownEnvelope& env, const RingdownSegment& seg,
                      double decay_rate_1_s, size_t a, size_t m, int min_floor_samples) {
  const auto& t = env.t_s;
  const auto& y = env.log_amplitude;
  FloorPower out;
  std::vector<double>& p = out.p;
  std::vector<bool>& valid = out.valid;
  int& nv = out.nv;
  // Power re the floor, less the residual signal c1 e^{-2 g (t - t_a)} and the mean c0.
  p.assign(m, 0.0);
  valid.assign(m, false);
  Eigen::MatrixXd X(m, 2);
  Eigen::VectorXd P(m);
  for (size_t k = 0; k < m; ++k) {
    const size_t i = a + k;
    if (seg.dropout[i] || !std::isfinite(y[i])) continue;
    valid[k] = true;
    P(nv) = std::exp(2.0 * (y[i] - seg.floor_log_amplitude));
    X(nv, 0) = 1.0, X(nv, 1) = std::exp(-2.0 * decay_rate_1_s * (t[i] - t[a]));
    p[k] = P(nv), ++nv;
  }
  if (nv < min_floor_samples) return out;
  const Eigen::VectorXd c = X.topRows(nv).colPivHouseholderQr().solve(P.head(nv));
  for (size_t k = 0; k < m; ++k)
    if (valid[k]) p[k] -= c(0) + c(1) * std::exp(-2.0 * decay_rate_1_s * (t[a + k] - t[a]));
  return out;
}

/// Step 4: the power's autocorrelation r[0..K] (r[0] = 1) over the valid pairs, normalized by its
/// mean square, up to k_max lags or the first under correlation_end.
std::vector<double> powerAutocorrelation(const FloorPower& fp, int k_max, double correlation_end) {
  const std::vector<double>& p = fp.p;
  const std::vector<bool>& valid = fp.valid;
  const size_t m = p.size();
  std::vector<double> r(1, 1.0);
  double var = 0.0;
  int nvar = 0;
  for (size_t k = 0; k < m; ++k)
    if (valid[k]) var += p[k] * p[k], ++nvar;
  var /= std::max(1, nvar);
  for (int lag = 1; lag <= k_max; ++lag) {
    double s = 0.0;
    int cnt = 0;
    for (size_t k = 0; k + lag < m; ++k)
      if (valid[k] && valid[k + lag]) s += p[k] * p[k + lag], ++cnt;
    r.push_back(cnt > 0 ? s / cnt / std::max(var, 1e-300) : 0.0);
    if (r.back() < correlation_end) break;
  }
  return r;
}

/// T [samples] of the given order that fits r best.
double fitTimeConstant(int order, const std::vector<double>& r, size_t m,
                       const RingdownDetectorFilterOptions& o) {
  // Log grid of T in samples, then golden section between the neighbours of the best node.
  const int ng = o.grid_nodes;
  const double lo = std::log(o.grid_min_samples), hi = std::log(o.grid_max_samples);
  int kb = 0;
  double eb = std::numeric_limits<double>::infinity();
  for (int g = 0; g < ng; ++g) {
    const double e = correlationMisfit(order, std::exp(lo + (hi - lo) * g / (ng - 1)), r, m, o);
    if (e < eb) eb = e, kb = g;
  }
  double u0 = lo + (hi - lo) * std::max(0, kb - 1) / (ng - 1);
  double u1 = lo + (hi - lo) * std::min(ng - 1, kb + 1) / (ng - 1);
  const double gr = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int it = 0; it < o.golden_iterations; ++it) {
    const double x1 = u1 - gr * (u1 - u0), x2 = u0 + gr * (u1 - u0);
    if (correlationMisfit(order, std::exp(x1), r, m, o) <
        correlationMisfit(order, std::exp(x2), r, m, o))
      u1 = x2;
    else
      u0 = x1;
  }
  return std::exp(0.5 * (u0 + u1));
}

/// Step 5: the order (1..max_order) and time constant [s] of the best fit into f; returns its sum
/// of squares (infinite, f untouched, when no order gives a finite one).
double fitFilterShape(const std::vector<double>& r, size_t m, double dt,
                      const RingdownDetectorFilterOptions& o, RingdownDetectorFilter* f) {
  double best = std::numeric_limits<double>::infinity();
  const int max_order = std::min(o.max_order, kMaxOrder);
  for (int order = 1; order <= max_order; ++order) {
    const double ts = fitTimeConstant(order, r, m, o);
    const double e = correlationMisfit(order, ts, r, m, o);
    if (e < best) best = e, f->order = order, f->time_constant_s = ts * dt;
  }
  return best;
}

}  // namespace

double ringdownFilterPowerCorrelation(int order, double x) {
  x = std::fabs(x);
  // rho_n(x) = e^{-x} sum_j C(m, j) x^{m-j} (j+m)! / 2^{j+m+1} / (same at x = 0), m = n - 1:
  // the integral of s^m (s + x)^m e^{-2 s} ds.
  const int m = std::max(0, std::min(kMaxOrder, order) - 1);
  double num = 0.0;
  for (int j = 0; j <= m; ++j)
    num += factorial(m) / (factorial(j) * factorial(m - j)) * std::pow(x, m - j) *
           factorial(j + m) / std::pow(2.0, j + m + 1);
  const double den = factorial(2 * m) / std::pow(2.0, 2 * m + 1);
  const double rho = std::exp(-x) * num / den;
  return rho * rho;
}

RingdownDetectorFilter estimateDetectorFilter(const RingdownEnvelope& env,
                                              const RingdownSegment& seg, double decay_rate_1_s,
                                              const RingdownDetectorFilterOptions& o) {
  RingdownDetectorFilter f;
  f.source = "none";
  auto none = [&f](const std::string& why) {
    f.why = "no detector filter estimated (" + why +
            "): the first decibels after the drive-off "
            "are skipped instead";
    return f;
  };
  if (!seg.has_floor) return none("no noise floor in the record");
  if (!(decay_rate_1_s > 0.0)) return none("no positive decay rate");
  const auto& t = env.t_s;
  // 1. The floor stretch, from below_floor_db below the floor on the decay's straight
  // continuation.
  const size_t a = floorStretchStart(env, seg, decay_rate_1_s, o);
  const size_t m = t.size() - std::min(a, t.size());
  if (m < static_cast<size_t>(o.min_floor_samples)) {
    std::ostringstream w;
    w << m << " samples of floor " << o.below_floor_db
      << " dB below the decay's continuation, under " << o.min_floor_samples;
    return none(w.str());
  }
  // 2. Uniform sampling over it.
  std::vector<double> dts;
  for (size_t i = a + 1; i < t.size(); ++i) dts.push_back(t[i] - t[i - 1]);
  const double dt = median(dts);
  for (double d : dts)
    if (std::fabs(d - dt) > o.sampling_tolerance * dt)
      return none("sampling not uniform in the floor");
  // 3. The floor's power less the residual signal and the mean.
  const FloorPower fp = floorPower(env, seg, decay_rate_1_s, a, m, o.min_floor_samples);
  if (fp.nv < o.min_floor_samples)
    return none("under " + std::to_string(o.min_floor_samples) + " valid floor samples");
  // 4. Its autocorrelation, up to where it falls under correlation_end.
  const int k_max = static_cast<int>(std::min<size_t>(o.max_lags, m / o.lags_divisor));
  const std::vector<double> r = powerAutocorrelation(fp, k_max, o.correlation_end);
  f.n_samples = fp.nv;
  f.n_lags = static_cast<int>(r.size()) - 1;
  if (r.size() < 2 || r[1] < o.min_lag1_correlation) {
    std::ostringstream w;
    w.precision(3);
    w << "floor power correlation at lag 1 is " << (r.size() > 1 ? r[1] : 0.0) << ", under "
      << o.min_lag1_correlation << ": a filter shorter than the sample interval";
    return none(w.str());
  }
  if (static_cast<int>(r.size()) - 1 >= k_max) return none("floor correlation does not decay");
  // 5. The order and time constant whose rho_n^2 fits it best.
  const double best = fitFilterShape(r, m, dt, o, &f);
  f.found = true;
  f.source = "noise_floor";
  f.fit_rms = std::sqrt(best / f.n_lags);
  // A floor stretch under min_filter_lengths filter lengths (n T) gives an autocorrelation too
  // noisy to trust.
  if (m * dt < o.min_filter_lengths * f.order * f.time_constant_s) {
    f.found = false;
    std::ostringstream w;
    w << "floor shorter than " << o.min_filter_lengths << " filter lengths";
    return none(w.str());
  }
  std::ostringstream w;
  w.precision(3);
  w << "detector low-pass of " << f.order << " pole" << (f.order > 1 ? "s" : "")
    << ", T = " << f.time_constant_s << " s each, from the correlation of the floor's power ("
    << fp.nv << " samples after " << t[a] << " s, lags 1.." << f.n_lags << ", rms misfit "
    << f.fit_rms << "); assumed to act on the amplitude (a lock-in's output filter)";
  f.why = w.str();
  return f;
}

std::vector<double> ringdownFilteredLogAmplitude(const std::string& law, const Eigen::VectorXd& p,
                                                 double t_off, int order, double time_constant,
                                                 const std::vector<double>& t, double floor_rel) {
  std::vector<double> out;
  if (t.empty() || !(time_constant > 0.0) || order < 1) return out;
  const double t_max = std::max(t.back(), t_off);
  double dg = time_constant / 8.0;
  int ng = static_cast<int>(std::ceil((t_max - t_off) / dg)) + 2;
  if (ng > 40000) ng = 40000, dg = (t_max - t_off) / (ng - 2);
  std::vector<double> x(ng);
  for (int k = 0; k < ng; ++k) {
    const double la = ringdownLogAmplitude(law, p, t_off + k * dg, 0.0);
    if (!std::isfinite(la)) return out;
    x[k] = std::exp(la);
  }
  // n stages, each exact for an input linear between grid points, started on the plateau x[0].
  const double a = std::exp(-dg / time_constant);
  const double c = 1.0 - (time_constant / dg) * (1.0 - a);
  for (int s = 0; s < order; ++s) {
    double yk = x[0], xk = x[0];
    for (int k = 1; k < ng; ++k) {
      const double xn = x[k];
      yk = a * yk + (1.0 - a) * xk + (xn - xk) * c;
      xk = xn;
      x[k] = yk;
    }
  }
  out.resize(t.size());
  Eigen::VectorXd q(2);
  for (size_t i = 0; i < t.size(); ++i) {
    double v = x[0];
    if (t[i] > t_off) {
      const double u = (t[i] - t_off) / dg;
      const int k = std::min(ng - 2, static_cast<int>(u));
      const double fr = u - k;
      v = x[k] + fr * (x[k + 1] - x[k]);
    }
    if (!(v > 0.0)) return {};
    q << std::log(v), 0.0;
    out[i] = ringdownLogAmplitude("linear", q, 0.0, floor_rel);
  }
  return out;
}

RingdownFilteredFit fitRingdownThroughFilter(const RingdownEnvelope& env,
                                             const RingdownSegment& seg, const RingdownFit& law_fit,
                                             const RingdownDetectorFilter& filter,
                                             const std::vector<double>& ar,
                                             const RingdownFilteredFitOptions& o) {
  RingdownFilteredFit out;
  out.model = law_fit.model;
  if (!filter.found || law_fit.t_s.empty()) return out;
  const double ts = law_fit.t_scale_s, tr = law_fit.t_ref_s;
  const double tf = filter.time_constant_s / ts;
  const double t_lo = seg.has_plateau ? seg.drive_off_s - o.lead_filter_lengths * filter.order *
                                                              filter.time_constant_s
                                      : -std::numeric_limits<double>::infinity();
  std::vector<double> tt, yy, ww;
  size_t j = 0;
  for (size_t i = 0; i < seg.i_end && i < env.size(); ++i) {
    if (env.t_s[i] < t_lo || seg.dropout[i] || !std::isfinite(env.log_amplitude[i])) continue;
    while (j < law_fit.t_s.size() && law_fit.t_s[j] < env.t_s[i]) ++j;
    const double w = j < law_fit.t_s.size() && law_fit.t_s[j] == env.t_s[i]
                         ? law_fit.weight[j]
                         : law_fit.weight.front();
    tt.push_back((env.t_s[i] - tr) / ts);
    yy.push_back(env.log_amplitude[i] - law_fit.log_a_ref);
    ww.push_back(std::sqrt(w));
  }
  const int n = static_cast<int>(tt.size());
  const int np = static_cast<int>(law_fit.p.size());
  if (n < np + o.min_extra_samples) return out;
  auto res = [&](const Eigen::VectorXd& q, Eigen::VectorXd& r) {
    const std::vector<double> f = ringdownFilteredLogAmplitude(
        law_fit.model, q.head(np), q(np), filter.order, tf, tt, law_fit.floor_rel);
    if (f.empty()) return false;
    r.resize(n);
    for (int i = 0; i < n; ++i) r(i) = ww[i] * (yy[i] - f[i]);
    return r.allFinite();
  };
  const double off0 = ((seg.has_plateau ? seg.drive_off_s : env.t_s.front()) - tr) / ts;
  double best = std::numeric_limits<double>::infinity();
  for (double shift : {0.0, -1.0}) {
    Eigen::VectorXd q(np + 1);
    q.head(np) = law_fit.p;
    q(np) = off0 + shift * filter.order * tf;
    double sse = 0.0;
    if (!minimizeSumOfSquares(res, q, sse, o.max_iterations)) continue;
    if (sse < best) best = sse, out.p = q;
  }
  if (!std::isfinite(best)) return out;
  out.ok = true;
  out.sse_w = best;
  out.n = n;
  out.t_start_s = tt.front() * ts + tr;
  out.drive_off_s = out.p(np) * ts + tr;
  Eigen::VectorXd r;
  res(out.p, r);
  std::vector<double> e(r.data(), r.data() + r.size());
  double s = 0.0;
  for (double v : arWhiten(ar, e)) s += v * v;
  out.sse_whitened = s;
  return out;
}

}  // namespace cvg_bench

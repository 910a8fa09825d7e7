#include "cvg_bench/core/diagnose/orbit_reading.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "cvg_bench/core/common/number_text.h"
#include "cvg_bench/core/common/sample_median.h"
#include "cvg_bench/core/estimate/internal/centred_line_fit.h"
#include "cvg_bench/core/estimate/internal/hac_slope.h"
#include "cvg_bench/core/estimate/uncertainty/derived_uncertainty.h"
#include "cvg_bench/core/estimate/uncertainty/student_t.h"
#include "cvg_bench/core/model/orbit_elements.h"
#include "cvg_bench/core/model/orbit_rates_chain_rule.h"

namespace cvg_bench {

namespace {

constexpr double kDegPerHour = 180.0 / M_PI * 3600.0;

double median(const std::vector<double>& v) {
  return sampleMedian(v, 0.0);
}

/// Mean of window values with a Student-t interval from their scatter.
ParameterEstimate meanOfWindows(const std::vector<double>& x, double confidence) {
  ParameterEstimate p;
  const int b = static_cast<int>(x.size());
  if (b < 2) return p;
  double m = 0, ss = 0;
  for (double v : x) m += v;
  m /= b;
  for (double v : x) ss += (v - m) * (v - m);
  p.value = m;
  p.std_error = std::sqrt(ss / (b - 1) / b);
  const double s = studentQuantile(confidence, b - 1);
  p.ci_low = m - s * p.std_error;
  p.ci_high = m + s * p.std_error;
  return p;
}

std::string degH(const ParameterEstimate& p) {
  return valueWithInterval(p.value * kDegPerHour, p.ci_low * kDegPerHour, p.ci_high * kDegPerHour,
                           3, "deg/h");
}

/// Least-squares slope of y on x with the standard error from the points' scatter about the line
/// and a Student-t interval (n - 2 dof): the windows' rates are independent estimates, too few
/// (8) for a HAC error (it came out ~2.5x too narrow on a known coupling, orbit_reading_test).
/// All zero under 4 points or without spread in x.
ParameterEstimate scatterSlope(const std::vector<double>& x, const std::vector<double>& y,
                               double confidence) {
  const size_t n = x.size();
  if (n < 4 || y.size() != n) return {};
  const CentredLineFit f = centredLineFit(x.data(), y.data(), n);
  if (!(f.sxx > 0.0)) return {};
  double sse = 0.0;
  for (size_t i = 0; i < n; ++i) sse += std::pow(f.residual(x[i], y[i]), 2);
  const double dof = static_cast<double>(n) - 2.0;
  return interval(f.slope, sse / dof / f.sxx, studentQuantile(confidence, static_cast<int>(dof)));
}

/// OrbitReading::rk_slope_*: the windows' theta' (measured, and predicted where every window has
/// a prediction) regressed on r k / 8.
void readRkSlope(OrbitReading& out, double confidence) {
  std::vector<double> x, measured, predicted;
  bool all_predicted = true;
  for (const OrbitWindow& w : out.windows) {
    x.push_back(w.r * w.k / 8.0);
    measured.push_back(w.theta_rate.value);
    predicted.push_back(w.predicted_theta_rate.value);
    all_predicted = all_predicted && w.has_prediction;
  }
  out.rk_slope_measured = scatterSlope(x, measured, confidence);
  if (all_predicted) out.rk_slope_model = scatterSlope(x, predicted, confidence);
}

std::string withInterval(const ParameterEstimate& p) {
  return valueWithInterval(p.value, p.ci_low, p.ci_high, 3);
}

/// OrbitReading::summary: one paragraph for the text report.
std::string summaryOf(const OrbitReading& out) {
  std::ostringstream s;
  s.precision(4);
  s << "measured, before any model (orbit elements (5.2) of " << out.n_samples
    << " slow samples in " << out.windows.size() << " windows): pattern angle rate theta' "
    << degH(out.theta_rate) << " over the record (the oscillation plane, 2 theta, turns twice as "
    << "fast)";
  if (!out.windows.empty()) {
    const OrbitWindow &a = out.windows.front(), &b = out.windows.back();
    s << ", " << degH(a.theta_rate) << " in the first window and " << degH(b.theta_rate)
      << " in the last; amplitude r " << a.r << " -> " << b.r << ", quadrature k " << a.k << " -> "
      << b.k;
    if (a.q.value > 0 && b.q.value > 0)
      s << ", Q from the amplitude decay " << a.q.value << " at r " << a.r << " -> " << b.q.value
        << " at r " << b.r;
    if (a.has_prediction && b.has_prediction)
      s << "; " << out.model << " predicts theta' " << degH(a.predicted_theta_rate) << " and "
        << degH(b.predicted_theta_rate) << " there; k' " << a.k_rate.value << " and "
        << b.k_rate.value << " measured, " << a.predicted_k_rate.value << " and "
        << b.predicted_k_rate.value << " predicted";
  }
  if (out.period_s > 0) s << "; period " << out.period_s << " s";
  if (out.rk_slope_measured.std_error > 0.0) {
    s << ". theta' against r k / 8 over the windows: slope " << withInterval(out.rk_slope_measured)
      << " 1/(s amplitude^2) measured";
    if (out.rk_slope_model.std_error > 0.0 && out.rk_slope_measured.value != 0.0)
      s << ", " << withInterval(out.rk_slope_model) << " from " << out.model
        << "'s predictions at the same states ("
        << out.rk_slope_model.value / out.rk_slope_measured.value << "x)";
  }
  if (out.quadrature_growth.valid) s << ". Ellipse: " << out.quadrature_growth.summary;
  return s.str();
}

}  // namespace

OrbitReading readOrbit(const SlowRecord& record, double omega_rad_s, const Estimate* final_estimate,
                       int n_windows, double confidence) {
  OrbitReading out;
  const double omega = omega_rad_s > 0.0 ? omega_rad_s : record.omega_rad_s;
  const size_t n = record.size();
  if (n < static_cast<size_t>(8 * n_windows) || n_windows < 2) {
    out.why_not = "too few slow samples for a reading in " + std::to_string(n_windows) + " windows";
    return out;
  }
  // Orbit elements of every sample, theta unwrapped (it is defined modulo pi / 2); samples near a
  // travelling wave (r^2 - k^2 under 1e-4 r^2) have no pattern angle and are left out of theta.
  std::vector<double> t, r, k, th;
  double unwrap = 0.0, last = 0.0;
  bool first = true;
  for (size_t i = 0; i < n; ++i) {
    const OrbitElements e = orbitFromSlow(record.q[i]);
    if (!(e.r > 0.0) || e.r * e.r - e.k * e.k < 1e-4 * e.r * e.r) continue;
    if (!first) {
      const double d = e.theta - last;
      if (d > M_PI / 4) unwrap -= M_PI / 2;
      if (d < -M_PI / 4) unwrap += M_PI / 2;
    }
    first = false;
    last = e.theta;
    t.push_back(record.t_s[i]);
    r.push_back(e.r);
    k.push_back(e.k);
    th.push_back(e.theta + unwrap);
  }
  if (t.size() < static_cast<size_t>(8 * n_windows)) {
    out.why_not = "the orbit is a travelling wave (r = |k|) on most samples: no pattern angle";
    return out;
  }
  out.valid = true;
  out.period_s = omega > 0.0 ? 2.0 * M_PI / omega : 0.0;
  out.n_samples = static_cast<int>(t.size());
  UncertainParameters up;
  ResonatorModel model("linear", ExperimentMode::kFreeDecay);
  if (final_estimate != nullptr) {
    up = uncertainParameters(*final_estimate);
    out.model = final_estimate->model;
    model = freeOscillationModelOf(up.values);
  }
  const double span = t.back() - t.front();
  std::vector<double> theta_rates, k_rates;
  size_t i0 = 0;
  for (int w = 0; w < n_windows; ++w) {
    const double t_end = t.front() + span * (w + 1) / n_windows;
    size_t i1 = i0;
    while (i1 < t.size() && (t[i1] <= t_end || w == n_windows - 1)) ++i1;
    OrbitWindow win;
    const std::vector<double> tw(t.begin() + i0, t.begin() + i1);
    const std::vector<double> rw(r.begin() + i0, r.begin() + i1),
        kw(k.begin() + i0, k.begin() + i1), thw(th.begin() + i0, th.begin() + i1);
    i0 = i1;
    win.n = static_cast<int>(tw.size());
    if (win.n < 6) continue;
    win.t_start_s = tw.front();
    win.t_end_s = tw.back();
    win.r = median(rw);
    win.k = median(kw);
    win.theta_rad = std::remainder(median(thw), M_PI / 2);
    win.theta_rate = hacSlope(tw, thw, confidence);
    win.k_rate = hacSlope(tw, kw, confidence);
    std::vector<double> lnr(rw.size());
    for (size_t i = 0; i < rw.size(); ++i) lnr[i] = std::log(rw[i]);
    const ParameterEstimate lam = hacSlope(tw, lnr, confidence);
    if (omega > 0.0 && -2.0 * lam.value > 0.0) {
      try {
        win.q = qualityFactorFromRate(omega, -2.0 * lam.value, 4.0 * lam.std_error * lam.std_error,
                                      confidence, win.n - 2);
      } catch (const std::exception&) {
      }
    }
    if (final_estimate != nullptr && std::abs(win.k) < win.r) {
      try {
        win.predicted_theta_rate = driftRateWithInterval(win.r, win.k, win.theta_rad, up);
        const OrbitElements state{win.r, win.k, win.theta_rad, 0.0};
        win.predicted_k_rate = deltaMethod(
            [&](const ParameterValues& v) { return orbitRatesOfModel(model, v, state).k_dot; }, up);
        win.has_prediction = true;
      } catch (const std::exception&) {
      }
    }
    theta_rates.push_back(win.theta_rate.value);
    k_rates.push_back(win.k_rate.value);
    out.windows.push_back(win);
  }
  out.theta_rate = meanOfWindows(theta_rates, confidence);
  out.k_rate = meanOfWindows(k_rates, confidence);
  readRkSlope(out, confidence);
  if (final_estimate != nullptr) {
    const double r_med = median(r), k_med = median(k),
                 th_med = std::remainder(median(th), M_PI / 2);
    out.quadrature_growth = explainQuadratureGrowth(up, r_med, k_med, th_med, out.k_rate);
  }
  out.summary = summaryOf(out);
  return out;
}

}  // namespace cvg_bench

#include "cvg_bench/core/diagnose/drift_measurement.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "cvg_bench/core/estimate/student_t.h"
#include "cvg_bench/core/model/errors.h"
#include "cvg_bench/core/model/orbit_elements.h"
#include "cvg_bench/core/model/orbit_rates_chain_rule.h"
#include "cvg_bench/core/model/sample_median.h"

namespace cvg_bench {

namespace {

double median(const std::vector<double>& v) {
  return sampleMedian(v);
}

/// What a pass through the bin [c - w/2, c + w/2] measures: the slope of theta(t) across it is
/// w / (time to cross) = the harmonic mean of the walk + theta'(theta) over the bin, less the walk
/// (Simpson over 9 points). The bin centre's theta' differs from it by the drift's curvature and
/// spread over the bin, which on a long run (narrow intervals) is several of the measured
/// intervals (quartz at k0 = 0: smooth runs of z 1.5-3 over neighbouring bins). The centre's value
/// where the walk does not carry the pattern through the whole bin.
ParameterEstimate binDriftWithInterval(const ResonatorModel& model, double r, double k, double c,
                                       double w, double walk, const UncertainParameters& params) {
  auto crossing = [&](const ParameterValues& v) {
    constexpr int kPoints = 9;
    double time = 0.0;
    for (int i = 0; i < kPoints; ++i) {
      const double th = c - w / 2 + w * i / (kPoints - 1);
      const double rate =
          walk + orbitRatesOfModel(model, v, OrbitElements{r, k, th, 0.0}).theta_dot;
      if (!(rate * walk > 0.0)) return std::numeric_limits<double>::quiet_NaN();
      const double simpson = (i == 0 || i == kPoints - 1) ? 1.0 : (i % 2 ? 4.0 : 2.0);
      time += simpson / rate;
    }
    return w / (time * w / (3.0 * (kPoints - 1))) - walk;
  };
  if (walk == 0.0 || !std::isfinite(crossing(params.values)))
    return driftRateWithInterval(r, k, c, params);
  return deltaMethod(crossing, params);
}

}  // namespace

DriftHarmonics fitDriftHarmonics(const std::vector<double>& theta, const std::vector<double>& y) {
  DriftHarmonics h;
  const int n = static_cast<int>(theta.size());
  if (n < 5) return h;
  Eigen::MatrixXd a(n, 5);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) {
    a(i, 0) = 1.0;
    a(i, 1) = std::cos(4 * theta[i]);
    a(i, 2) = std::sin(4 * theta[i]);
    a(i, 3) = std::cos(8 * theta[i]);
    a(i, 4) = std::sin(8 * theta[i]);
    b(i) = y[i];
  }
  const Eigen::VectorXd x = a.colPivHouseholderQr().solve(b);
  h.c0 = x(0);
  h.a4 = x(1);
  h.b4 = x(2);
  h.a8 = x(3);
  h.b8 = x(4);
  return h;
}

DriftComparison measureDrift(const SlowRecord& record, double walk_rad_s,
                             const UncertainParameters& params, int n_bins, double confidence) {
  if (n_bins < 4 || n_bins > 3600) throw InputError("drift --measured: 4 .. 3600 theta bins");
  std::vector<double> t, th, rs, ks;
  double unwrap = 0.0, last = 0.0;
  for (size_t i = 0; i < record.size(); ++i) {
    const OrbitElements e = orbitFromSlow(record.q[i]);
    if (!(e.r > 0.0) || e.r * e.r - e.k * e.k < 1e-4 * e.r * e.r) continue;
    if (!t.empty()) {
      const double d = e.theta - last;
      if (d > M_PI / 4) unwrap -= M_PI / 2;
      if (d < -M_PI / 4) unwrap += M_PI / 2;
    }
    last = e.theta;
    t.push_back(record.t_s[i]);
    th.push_back(e.theta + unwrap);
    rs.push_back(e.r);
    ks.push_back(e.k);
  }
  if (t.size() < static_cast<size_t>(4 * n_bins))
    throw InputError(record.source + ": too few samples with a pattern angle for " +
                     std::to_string(n_bins) + " theta bins");
  const double covered =
      *std::max_element(th.begin(), th.end()) - *std::min_element(th.begin(), th.end());
  if (covered < 0.75 * M_PI / 2)
    throw InputError(
        record.source + ": the pattern angle covers " + std::to_string(covered * 180 / M_PI) +
        " deg, under 3/4 of its period (90 deg): walk it further to measure theta'(theta)");
  DriftComparison out;
  out.walk_rad_s = walk_rad_s;
  out.r = median(rs);
  out.k = median(ks);
  const double width = (M_PI / 2) / n_bins;
  auto binOf = [&](double theta) {
    const double w = std::remainder(theta, M_PI / 2);  // [-pi/4, pi/4]
    return std::min(n_bins - 1, static_cast<int>(std::floor((w + M_PI / 4) / width)));
  };
  // Each pass through a bin: the least-squares slope of theta(t) over it. Its standard error
  // comes from the noise pooled over all passes (residual variance with sum(n - 2) dof, lag-1
  // correlation as an AR(1) long-run factor), not from each pass alone: a pass of ~10 samples
  // (quartz at k0 = 0.1) gave a HAC variance so noisy that the truth lay 2-3 of its intervals
  // away in one bin of four (issue #26).
  struct Pass {
    int bin;
    double slope, sxx;
  };
  std::vector<Pass> passes;
  std::vector<int> samples(n_bins, 0);
  double sse = 0.0, lag1 = 0.0;
  long noise_dof = 0;
  // Samples are assigned to bins by a centred moving average of theta, not by their own noisy
  // value: selecting a pass's samples by the value they are fitted on keeps those pushed into the
  // bin by noise and drops those pushed out, which biases every slope low by a fraction of the
  // whole rate (walk included; quartz at k0 = 0.1: 2-3 of a pass's interval). The window is about
  // a quarter of a pass (2 .. 50 samples each side).
  const double crossings = std::max(1.0, covered / width);
  const int half = std::clamp(static_cast<int>(0.125 * t.size() / crossings), 2, 50);
  std::vector<double> sel(th.size());
  for (size_t i = 0; i < th.size(); ++i) {
    const size_t lo = i >= static_cast<size_t>(half) ? i - half : 0;
    const size_t hi = std::min(th.size() - 1, i + half);
    const size_t w = std::min(i - lo, hi - i);  // symmetric: unbiased on a straight path
    double sum = 0.0;
    for (size_t j = i - w; j <= i + w; ++j) sum += th[j];
    sel[i] = sum / static_cast<double>(2 * w + 1);
  }
  size_t start = 0;
  for (size_t i = 1; i <= t.size(); ++i) {
    if (i < t.size() && binOf(sel[i]) == binOf(sel[start])) continue;
    const int b = binOf(sel[start]);
    samples[b] += static_cast<int>(i - start);
    // A pass counts when it crosses at least half the bin (fragments at the record's ends and
    // noise-driven re-entries would give slopes of a few samples).
    const double travel = std::abs(sel[i - 1] - sel[start]);
    if (i - start >= 6 && travel >= 0.5 * width) {
      const int n = static_cast<int>(i - start);
      double tm = 0.0, ym = 0.0;
      for (size_t j = start; j < i; ++j) tm += t[j], ym += th[j];
      tm /= n;
      ym /= n;
      double sxx = 0.0, sxy = 0.0;
      for (size_t j = start; j < i; ++j) {
        sxx += (t[j] - tm) * (t[j] - tm);
        sxy += (t[j] - tm) * (th[j] - ym);
      }
      const double slope = sxy / sxx;
      double prev = 0.0;
      for (size_t j = start; j < i; ++j) {
        const double e = th[j] - ym - slope * (t[j] - tm);
        sse += e * e;
        if (j > start) lag1 += e * prev;
        prev = e;
      }
      noise_dof += n - 2;
      passes.push_back({b, slope - walk_rad_s, sxx});
    }
    start = i;
  }
  const double s2 = noise_dof > 0 ? sse / static_cast<double>(noise_dof) : 0.0;
  const double rho = sse > 0.0 ? std::clamp(lag1 / sse, 0.0, 0.9) : 0.0;
  const double long_run = std::sqrt((1.0 + rho) / (1.0 - rho));
  std::vector<double> weight(n_bins, 0.0), mean(n_bins, 0.0);
  std::vector<int> count(n_bins, 0);
  auto varianceOf = [&](const Pass& p) {
    return std::max(s2 * long_run * long_run / p.sxx, 1e-300);
  };
  for (const Pass& p : passes) {
    weight[p.bin] += 1.0 / varianceOf(p);
    mean[p.bin] += p.slope / varianceOf(p);
    count[p.bin] += 1;
  }
  for (int b = 0; b < n_bins; ++b)
    if (count[b] > 0) mean[b] /= weight[b];
  // Passes through one bin measure the same theta': their scatter about the bin means, pooled,
  // checks the noise model; where they scatter more (slow noise, a wandering base), every
  // interval is widened by that ratio, with Student's quantile at its dof.
  double chi2 = 0.0;
  int scatter_dof = 0;
  for (const Pass& p : passes)
    chi2 += (p.slope - mean[p.bin]) * (p.slope - mean[p.bin]) / varianceOf(p);
  for (int b = 0; b < n_bins; ++b) scatter_dof += std::max(0, count[b] - 1);
  out.pass_scatter_ratio = scatter_dof > 0 ? std::max(1.0, std::sqrt(chi2 / scatter_dof)) : 1.0;
  out.pass_scatter_dof = scatter_dof;
  out.noise_dof = noise_dof;
  out.noise_lag1 = rho;
  const double quantile =
      out.pass_scatter_ratio > 1.0
          ? studentQuantile(confidence, scatter_dof)
          : studentQuantile(confidence, static_cast<int>(std::min<long>(noise_dof, 100000)));
  const ResonatorModel model = freeOscillationModelOf(params.values);
  out.model = model.spec();
  std::vector<double> centres, meas, pred, diff;
  for (int b = 0; b < n_bins; ++b) {
    DriftBin bin;
    bin.theta_rad = -M_PI / 4 + (b + 0.5) * width;
    bin.samples = samples[b];
    bin.passes = count[b];
    if (count[b] > 0) {
      bin.measured.value = mean[b];
      bin.measured.std_error = std::sqrt(1.0 / weight[b]) * out.pass_scatter_ratio;
      bin.measured.ci_low = mean[b] - quantile * bin.measured.std_error;
      bin.measured.ci_high = mean[b] + quantile * bin.measured.std_error;
      bin.measured_ok = true;
    }
    bin.predicted =
        binDriftWithInterval(model, out.r, out.k, bin.theta_rad, width, walk_rad_s, params);
    if (bin.measured_ok) {
      centres.push_back(bin.theta_rad);
      meas.push_back(bin.measured.value);
      pred.push_back(bin.predicted.value);
      diff.push_back(bin.measured.value - bin.predicted.value);
    }
    out.bins.push_back(bin);
  }
  out.bins_measured = static_cast<int>(centres.size());
  if (out.bins_measured < n_bins / 2)
    throw InputError(record.source + ": only " + std::to_string(out.bins_measured) + " of " +
                     std::to_string(n_bins) +
                     " theta bins have a pass of 6 samples or more (sample faster or walk slower)");
  double s_d = 0, s_m = 0;
  for (size_t i = 0; i < diff.size(); ++i) {
    s_d += diff[i] * diff[i];
    s_m += meas[i] * meas[i];
  }
  out.rms_difference_rad_s = std::sqrt(s_d / diff.size());
  out.rms_measured_rad_s = std::sqrt(s_m / meas.size());
  out.measured_harmonics = fitDriftHarmonics(centres, meas);
  out.predicted_harmonics = fitDriftHarmonics(centres, pred);
  out.residual_harmonics = fitDriftHarmonics(centres, diff);
  const double dh = 180.0 / M_PI * 3600.0;
  std::ostringstream s;
  s.precision(4);
  s << "drift measured in " << out.bins_measured << " of " << n_bins << " theta bins (r " << out.r
    << ", k " << out.k << ", walk " << walk_rad_s * dh << " deg/h subtracted): RMS "
    << out.rms_measured_rad_s * dh << " deg/h uncompensated; predicted by " << out.model
    << ": RMS of measured - predicted " << out.rms_difference_rad_s * dh
    << " deg/h (the residual drift after compensation), "
    << (out.rms_difference_rad_s > 0 ? out.rms_measured_rad_s / out.rms_difference_rad_s : 0.0)
    << "x less";
  out.summary = s.str();
  return out;
}

}  // namespace cvg_bench

namespace cvg_bench {

PredictedDriftHarmonics predictDriftHarmonics(const UncertainParameters& params, double r,
                                              double k) {
  PredictedDriftHarmonics out;
  const ResonatorModel model = freeOscillationModelOf(params.values);
  out.model = model.spec();
  constexpr int kGrid = 36;
  std::vector<double> theta(kGrid);
  for (int i = 0; i < kGrid; ++i) theta[i] = -M_PI / 4 + (i + 0.5) * (M_PI / 2) / kGrid;
  auto harmonicsAt = [&](const ParameterValues& v) {
    std::vector<double> y(kGrid);
    for (int i = 0; i < kGrid; ++i)
      y[i] = orbitRatesOfModel(model, v, OrbitElements{r, k, theta[i], 0.0}).theta_dot;
    return fitDriftHarmonics(theta, y);
  };
  out.c0 = deltaMethod([&](const ParameterValues& v) { return harmonicsAt(v).c0; }, params);
  out.amp4 = deltaMethod(
      [&](const ParameterValues& v) {
        const DriftHarmonics h = harmonicsAt(v);
        return std::hypot(h.a4, h.b4);
      },
      params);
  out.amp8 = deltaMethod(
      [&](const ParameterValues& v) {
        const DriftHarmonics h = harmonicsAt(v);
        return std::hypot(h.a8, h.b8);
      },
      params);
  return out;
}

}  // namespace cvg_bench

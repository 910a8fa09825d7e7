#include "cvg_bench/core/diagnose/drift_measurement.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "cvg_bench/core/estimate/internal/hac_slope.h"
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
  std::vector<std::vector<ParameterEstimate>> pass_rates(n_bins);
  std::vector<int> samples(n_bins, 0);
  size_t start = 0;
  for (size_t i = 1; i <= t.size(); ++i) {
    if (i < t.size() && binOf(th[i]) == binOf(th[start])) continue;
    const int b = binOf(th[start]);
    samples[b] += static_cast<int>(i - start);
    // A pass counts when it crosses at least half the bin (fragments at the record's ends and
    // noise-driven re-entries would give slopes of a few samples).
    const double travel = std::abs(th[i - 1] - th[start]);
    if (i - start >= 6 && travel >= 0.5 * width) {
      const std::vector<double> tp(t.begin() + start, t.begin() + i),
          yp(th.begin() + start, th.begin() + i);
      ParameterEstimate p = hacSlope(tp, yp, confidence);
      p.value -= walk_rad_s;
      p.ci_low -= walk_rad_s;
      p.ci_high -= walk_rad_s;
      pass_rates[b].push_back(p);
    }
    start = i;
  }
  // A bin passed once has only its pass's own (HAC) interval, which understates the noise of the
  // pattern angle: the passes of the bins passed twice or more scatter about their means by more
  // than their intervals say (quartz at k0 = 0.1: truth outside the one-pass intervals at z RMS
  // ~2). So one-pass bins take the pooled ratio sqrt(chi^2 / dof) of those bins (at least 1) and
  // Student's quantile at its dof; bins of several passes keep their own ratio (issue #26).
  double chi2_pooled = 0.0;
  int dof_pooled = 0;
  for (const auto& passes : pass_rates) {
    if (passes.size() < 2) continue;
    double sw = 0, m = 0;
    for (const auto& p : passes) {
      const double w = 1.0 / std::max(p.std_error * p.std_error, 1e-300);
      sw += w;
      m += w * p.value;
    }
    m /= sw;
    for (const auto& p : passes)
      chi2_pooled += (p.value - m) * (p.value - m) / std::max(p.std_error * p.std_error, 1e-300);
    dof_pooled += static_cast<int>(passes.size()) - 1;
  }
  out.one_pass_scale = dof_pooled > 0 ? std::max(1.0, std::sqrt(chi2_pooled / dof_pooled)) : 1.0;
  out.one_pass_scale_dof = dof_pooled;
  const ResonatorModel model = freeOscillationModelOf(params.values);
  out.model = model.spec();
  std::vector<double> centres, meas, pred, diff;
  for (int b = 0; b < n_bins; ++b) {
    DriftBin bin;
    bin.theta_rad = -M_PI / 4 + (b + 0.5) * width;
    bin.samples = samples[b];
    bin.passes = static_cast<int>(pass_rates[b].size());
    if (bin.passes == 1) {
      bin.measured = pass_rates[b][0];
      if (dof_pooled > 0) {
        ParameterEstimate& m = bin.measured;
        m.std_error *= out.one_pass_scale;
        const double s = studentQuantile(confidence, dof_pooled);
        m.ci_low = m.value - s * m.std_error;
        m.ci_high = m.value + s * m.std_error;
      }
      bin.measured_ok = true;
    } else if (bin.passes >= 2) {
      // Inverse-variance mean of the passes; its std scaled up by the Birge ratio when the passes
      // scatter more than their own intervals say.
      double sw = 0, m = 0;
      for (const auto& p : pass_rates[b]) {
        const double w = 1.0 / std::max(p.std_error * p.std_error, 1e-300);
        sw += w;
        m += w * p.value;
      }
      m /= sw;
      double chi2 = 0;
      for (const auto& p : pass_rates[b])
        chi2 += (p.value - m) * (p.value - m) / std::max(p.std_error * p.std_error, 1e-300);
      bin.measured.value = m;
      bin.measured.std_error =
          std::sqrt(1.0 / sw) * std::max(1.0, std::sqrt(chi2 / (bin.passes - 1)));
      const double s = studentQuantile(confidence, bin.passes - 1);
      bin.measured.ci_low = m - s * bin.measured.std_error;
      bin.measured.ci_high = m + s * bin.measured.std_error;
      bin.measured_ok = true;
    }
    bin.predicted = driftRateWithInterval(out.r, out.k, bin.theta_rad, params);
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

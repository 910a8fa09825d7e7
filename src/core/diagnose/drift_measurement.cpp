#include "cvg_bench/core/diagnose/drift_measurement.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/sample_median.h"
#include "cvg_bench/core/estimate/internal/centred_line_fit.h"
#include "cvg_bench/core/estimate/uncertainty/student_t.h"
#include "cvg_bench/core/model/orbit_elements.h"
#include "cvg_bench/core/model/orbit_rates_chain_rule.h"

namespace cvg_bench {

namespace {

/// Fewest and most theta bins over one period (the InputError text says "4 .. 3600").
constexpr int kMinBins = 4;
constexpr int kMaxBins = 3600;
/// A sample's pattern angle is used where r^2 - k^2 is at least this fraction of r^2 (at r = |k|,
/// a travelling wave, theta is undefined).
constexpr double kMinStandingFraction = 1e-4;
/// Floor of a pass's slope variance (keeps the inverse-variance weights finite).
constexpr double kMinPassVariance = 1e-300;
/// Student's quantile at the noise dof is taken at no more dof than this (normal by then).
constexpr long kMaxQuantileDof = 100000;
/// rad/s -> deg/h (the summary's unit).
constexpr double kDegPerHourPerRadPerSec = 180.0 / M_PI * 3600.0;

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

/// The slow samples where the pattern angle is defined: time, theta ((5.2), unwrapped across its
/// period pi/2), r and k.
struct PatternTrack {
  std::vector<double> t, th, rs, ks;
};

PatternTrack trackPatternAngle(const SlowRecord& record) {
  PatternTrack p;
  double unwrap = 0.0, last = 0.0;
  for (size_t i = 0; i < record.size(); ++i) {
    const OrbitElements e = orbitFromSlow(record.q[i]);
    if (!(e.r > 0.0) || e.r * e.r - e.k * e.k < kMinStandingFraction * e.r * e.r) continue;
    if (!p.t.empty()) {
      const double d = e.theta - last;
      if (d > M_PI / 4) unwrap -= M_PI / 2;
      if (d < -M_PI / 4) unwrap += M_PI / 2;
    }
    last = e.theta;
    p.t.push_back(record.t_s[i]);
    p.th.push_back(e.theta + unwrap);
    p.rs.push_back(e.r);
    p.ks.push_back(e.k);
  }
  return p;
}

/// The angle theta covers over the run; InputError when the samples are too few for `n_bins` or
/// the coverage is under 3/4 of the period.
double checkedCoverage(const SlowRecord& record, const PatternTrack& p, int n_bins,
                       const DriftMeasurementOptions& o) {
  if (p.t.size() < static_cast<size_t>(o.min_samples_per_bin * n_bins))
    throw InputError(record.source + ": too few samples with a pattern angle for " +
                     std::to_string(n_bins) + " theta bins");
  const double covered =
      *std::max_element(p.th.begin(), p.th.end()) - *std::min_element(p.th.begin(), p.th.end());
  if (covered < o.min_covered_fraction * M_PI / 2)
    throw InputError(
        record.source + ": the pattern angle covers " + std::to_string(covered * 180 / M_PI) +
        " deg, under 3/4 of its period (90 deg): walk it further to measure theta'(theta)");
  return covered;
}

/// The `n` bins of one period of theta, [-pi/4, pi/4).
struct ThetaBins {
  int n;
  double width;
  int of(double theta) const {
    const double w = std::remainder(theta, M_PI / 2);  // [-pi/4, pi/4]
    return std::min(n - 1, static_cast<int>(std::floor((w + M_PI / 4) / width)));
  }
};

/// Samples are assigned to bins by a centred moving average of theta, not by their own noisy
/// value: selecting a pass's samples by the value they are fitted on keeps those pushed into the
/// bin by noise and drops those pushed out, which biases every slope low by a fraction of the
/// whole rate (walk included; quartz at k0 = 0.1: 2-3 of a pass's interval). The window is about
/// a quarter of a pass (2 .. 50 samples each side): its half-width.
int halfWindow(double covered, double width, size_t n_samples, const DriftMeasurementOptions& o) {
  const double crossings = std::max(1.0, covered / width);
  return std::clamp(static_cast<int>(o.half_window_fraction * n_samples / crossings),
                    o.min_half_window, o.max_half_window);
}

/// The centred moving average of `th` over up to `half` samples each side (the selection angle).
std::vector<double> selectionAngle(const std::vector<double>& th, int half) {
  std::vector<double> sel(th.size());
  for (size_t i = 0; i < th.size(); ++i) {
    const size_t lo = i >= static_cast<size_t>(half) ? i - half : 0;
    const size_t hi = std::min(th.size() - 1, i + half);
    const size_t w = std::min(i - lo, hi - i);  // symmetric: unbiased on a straight path
    double sum = 0.0;
    for (size_t j = i - w; j <= i + w; ++j) sum += th[j];
    sel[i] = sum / static_cast<double>(2 * w + 1);
  }
  return sel;
}

// Each pass through a bin: the least-squares slope of theta(t) over it. Its standard error
// comes from the noise pooled over all passes (residual variance with sum(n - 2) dof, lag-1
// correlation as an AR(1) long-run factor), not from each pass alone: a pass of ~10 samples
// (quartz at k0 = 0.1) gave a HAC variance so noisy that the truth lay 2-3 of its intervals
// away in one bin of four (issue #26).
struct Pass {
  int bin;
  double slope, sxx;
};

/// The passes of a run, the samples per bin, and the noise sums pooled over the passes.
struct PassSet {
  std::vector<Pass> passes;
  std::vector<int> samples;
  double sse = 0.0, lag1 = 0.0;
  long noise_dof = 0;
};

/// One pass, samples [start, end) in bin `b`: its slope of theta(t) less the walk into `set`, its
/// residuals into the pooled noise sums.
void fitPass(const PatternTrack& p, size_t start, size_t end, int b, double walk_rad_s,
             PassSet* set) {
  const int n = static_cast<int>(end - start);
  const CentredLineFit f = centredLineFit(&p.t[start], &p.th[start], end - start);
  double prev = 0.0;
  for (size_t j = start; j < end; ++j) {
    const double e = f.residual(p.t[j], p.th[j]);
    set->sse += e * e;
    if (j > start) set->lag1 += e * prev;
    prev = e;
  }
  set->noise_dof += n - 2;
  set->passes.push_back({b, f.slope - walk_rad_s, f.sxx});
}

/// Cuts the run into runs of consecutive samples whose selection angle lies in one bin; those
/// that count as passes are fitted.
PassSet measurePasses(const PatternTrack& p, const std::vector<double>& sel, const ThetaBins& bins,
                      double walk_rad_s, const DriftMeasurementOptions& o) {
  PassSet set;
  set.samples.assign(bins.n, 0);
  size_t start = 0;
  for (size_t i = 1; i <= p.t.size(); ++i) {
    if (i < p.t.size() && bins.of(sel[i]) == bins.of(sel[start])) continue;
    const int b = bins.of(sel[start]);
    set.samples[b] += static_cast<int>(i - start);
    // A pass counts when it crosses at least half the bin (fragments at the record's ends and
    // noise-driven re-entries would give slopes of a few samples).
    const double travel = std::abs(sel[i - 1] - sel[start]);
    if (i - start >= o.min_pass_samples && travel >= o.min_pass_travel * bins.width)
      fitPass(p, start, i, b, walk_rad_s, &set);
    start = i;
  }
  return set;
}

/// The noise pooled over the passes: variance, lag-1 correlation, its AR(1) long-run factor.
struct PooledNoise {
  double s2 = 0.0, rho = 0.0, long_run = 1.0;
  double varianceOf(const Pass& p) const {
    return std::max(s2 * long_run * long_run / p.sxx, kMinPassVariance);
  }
};

PooledNoise poolNoise(const PassSet& set, double max_lag1) {
  PooledNoise noise;
  noise.s2 = set.noise_dof > 0 ? set.sse / static_cast<double>(set.noise_dof) : 0.0;
  noise.rho = set.sse > 0.0 ? std::clamp(set.lag1 / set.sse, 0.0, max_lag1) : 0.0;
  noise.long_run = std::sqrt((1.0 + noise.rho) / (1.0 - noise.rho));
  return noise;
}

/// Per bin: the inverse-variance mean of its passes, the sum of their weights, their count.
struct BinMeans {
  std::vector<double> weight, mean;
  std::vector<int> count;
};

BinMeans meanPerBin(const PassSet& set, const PooledNoise& noise, int n_bins) {
  BinMeans m;
  m.weight.assign(n_bins, 0.0);
  m.mean.assign(n_bins, 0.0);
  m.count.assign(n_bins, 0);
  for (const Pass& p : set.passes) {
    m.weight[p.bin] += 1.0 / noise.varianceOf(p);
    m.mean[p.bin] += p.slope / noise.varianceOf(p);
    m.count[p.bin] += 1;
  }
  for (int b = 0; b < n_bins; ++b)
    if (m.count[b] > 0) m.mean[b] /= m.weight[b];
  return m;
}

/// Passes through one bin measure the same theta': their scatter about the bin means, pooled,
/// checks the noise model; where they scatter more (slow noise, a wandering base), every
/// interval is widened by that ratio, with Student's quantile at its dof. Sets the noise and
/// scatter fields of `out`; returns the intervals' quantile.
double scatterQuantile(const PassSet& set, const PooledNoise& noise, const BinMeans& m, int n_bins,
                       double confidence, DriftComparison* out) {
  double chi2 = 0.0;
  int scatter_dof = 0;
  for (const Pass& p : set.passes)
    chi2 += (p.slope - m.mean[p.bin]) * (p.slope - m.mean[p.bin]) / noise.varianceOf(p);
  for (int b = 0; b < n_bins; ++b) scatter_dof += std::max(0, m.count[b] - 1);
  out->pass_scatter_ratio = scatter_dof > 0 ? std::max(1.0, std::sqrt(chi2 / scatter_dof)) : 1.0;
  out->pass_scatter_dof = scatter_dof;
  out->noise_dof = set.noise_dof;
  out->noise_lag1 = noise.rho;
  return out->pass_scatter_ratio > 1.0
             ? studentQuantile(confidence, scatter_dof)
             : studentQuantile(confidence,
                               static_cast<int>(std::min<long>(set.noise_dof, kMaxQuantileDof)));
}

/// The measured bins' centres, measured and predicted drift, and their difference.
struct BinSeries {
  std::vector<double> centres, meas, pred, diff;
};

/// Every bin's measured theta' (with its interval) and its prediction, into out->bins.
BinSeries compareBins(const ResonatorModel& model, const ThetaBins& bins, const PassSet& set,
                      const BinMeans& m, double quantile, double walk_rad_s,
                      const UncertainParameters& params, DriftComparison* out) {
  BinSeries s;
  for (int b = 0; b < bins.n; ++b) {
    DriftBin bin;
    bin.theta_rad = -M_PI / 4 + (b + 0.5) * bins.width;
    bin.samples = set.samples[b];
    bin.passes = m.count[b];
    if (m.count[b] > 0) {
      bin.measured.value = m.mean[b];
      bin.measured.std_error = std::sqrt(1.0 / m.weight[b]) * out->pass_scatter_ratio;
      bin.measured.ci_low = m.mean[b] - quantile * bin.measured.std_error;
      bin.measured.ci_high = m.mean[b] + quantile * bin.measured.std_error;
      bin.measured_ok = true;
    }
    bin.predicted =
        binDriftWithInterval(model, out->r, out->k, bin.theta_rad, bins.width, walk_rad_s, params);
    if (bin.measured_ok) {
      s.centres.push_back(bin.theta_rad);
      s.meas.push_back(bin.measured.value);
      s.pred.push_back(bin.predicted.value);
      s.diff.push_back(bin.measured.value - bin.predicted.value);
    }
    out->bins.push_back(bin);
  }
  return s;
}

/// The RMS of the measured drift and of measured - predicted, the harmonics of each, the summary.
void summarize(const BinSeries& s, int n_bins, double walk_rad_s, DriftComparison* out) {
  double s_d = 0, s_m = 0;
  for (size_t i = 0; i < s.diff.size(); ++i) {
    s_d += s.diff[i] * s.diff[i];
    s_m += s.meas[i] * s.meas[i];
  }
  out->rms_difference_rad_s = std::sqrt(s_d / s.diff.size());
  out->rms_measured_rad_s = std::sqrt(s_m / s.meas.size());
  out->measured_harmonics = fitDriftHarmonics(s.centres, s.meas);
  out->predicted_harmonics = fitDriftHarmonics(s.centres, s.pred);
  out->residual_harmonics = fitDriftHarmonics(s.centres, s.diff);
  const double dh = kDegPerHourPerRadPerSec;
  std::ostringstream o;
  o.precision(4);
  o << "drift measured in " << out->bins_measured << " of " << n_bins << " theta bins (r " << out->r
    << ", k " << out->k << ", walk " << walk_rad_s * dh << " deg/h subtracted): RMS "
    << out->rms_measured_rad_s * dh << " deg/h uncompensated; predicted by " << out->model
    << ": RMS of measured - predicted " << out->rms_difference_rad_s * dh
    << " deg/h (the residual drift after compensation), "
    << (out->rms_difference_rad_s > 0 ? out->rms_measured_rad_s / out->rms_difference_rad_s : 0.0)
    << "x less";
  out->summary = o.str();
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
                             const UncertainParameters& params, int n_bins, double confidence,
                             const DriftMeasurementOptions& options) {
  if (n_bins < kMinBins || n_bins > kMaxBins)
    throw InputError("drift --measured: 4 .. 3600 theta bins");
  const PatternTrack track = trackPatternAngle(record);
  const double covered = checkedCoverage(record, track, n_bins, options);
  DriftComparison out;
  out.walk_rad_s = walk_rad_s;
  out.r = median(track.rs);
  out.k = median(track.ks);
  const ThetaBins bins{n_bins, (M_PI / 2) / n_bins};
  const std::vector<double> sel =
      selectionAngle(track.th, halfWindow(covered, bins.width, track.t.size(), options));
  const PassSet set = measurePasses(track, sel, bins, walk_rad_s, options);
  const PooledNoise noise = poolNoise(set, options.max_noise_lag1);
  const BinMeans means = meanPerBin(set, noise, n_bins);
  const double quantile = scatterQuantile(set, noise, means, n_bins, confidence, &out);
  const ResonatorModel model = freeOscillationModelOf(params.values);
  out.model = model.spec();
  const BinSeries series = compareBins(model, bins, set, means, quantile, walk_rad_s, params, &out);
  out.bins_measured = static_cast<int>(series.centres.size());
  if (out.bins_measured < n_bins / 2)
    throw InputError(record.source + ": only " + std::to_string(out.bins_measured) + " of " +
                     std::to_string(n_bins) +
                     " theta bins have a pass of 6 samples or more (sample faster or walk slower)");
  summarize(series, n_bins, walk_rad_s, &out);
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

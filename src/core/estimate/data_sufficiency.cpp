#include "cvg_bench/core/estimate/data_sufficiency.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/number_text.h"
#include "cvg_bench/core/common/sample_median.h"

namespace cvg_bench {
namespace {

double median(const std::vector<double>& v) {
  return sampleMedian(v, 0.0);
}

/// Noise variance of one channel: second differences of white noise have variance 6 sigma^2; the
/// scale is the median absolute deviation (1.4826 MAD = sigma for Gaussian noise), so that the few
/// large second differences of fast features do not count as noise.
double noiseVariance(const SlowRecord& r, int channel) {
  std::vector<double> d2;
  d2.reserve(r.size());
  for (size_t i = 2; i < r.size(); ++i)
    d2.push_back(r.q[i][channel] - 2.0 * r.q[i - 1][channel] + r.q[i - 2][channel]);
  const double m = median(d2);
  for (double& x : d2) x = std::fabs(x - m);
  const double s = kGaussianSdPerMad * median(d2);
  return s * s / 6.0;
}

/// Signal-to-noise power of a coordinate pair (channels c, c + 1): mean square over the noise's.
double pairSnr(const SlowRecord& r, int c) {
  double power = 0.0;
  for (const auto& q : r.q) power += q[c] * q[c] + q[c + 1] * q[c + 1];
  power /= static_cast<double>(r.size());
  const double noise = noiseVariance(r, c) + noiseVariance(r, c + 1);
  // Exact zeros (a noise-free standing wave) are no noise: exact rank reports the combinations.
  if (power == 0.0) return INFINITY;
  if (!(power > 0.0)) return 0.0;
  if (!(noise > 0.0)) return INFINITY;
  return power / noise;
}

std::string tooFew(size_t n, const char* what, long equations, int n_params) {
  return std::to_string(n) + " " + what + " give " + std::to_string(equations) + " equations for " +
         std::to_string(n_params) + " parameters: too few to estimate them and their noise (need " +
         "at least " + std::to_string(2 * n_params) + " equations)";
}

}  // namespace

DataSufficiency assessFreeDecay(const SlowRecord& record, int n_params) {
  DataSufficiency d;
  const size_t n = record.size();
  // (2.7): one block of 4 equations per interior sample.
  const long equations = n >= 2 ? 4 * static_cast<long>(n - 2) : 0;
  // Up to n_params equations the record is bad input (the regression's own check, exit 2).
  if (equations > n_params && equations < 2L * n_params) {
    d.sufficient = false;
    d.reason = tooFew(n, "samples", equations, n_params);
    return d;
  }
  d.snr_f = pairSnr(record, 0);
  d.snr_g = pairSnr(record, 2);
  const bool f_ok = d.snr_f >= kMinSignalToNoisePower, g_ok = d.snr_g >= kMinSignalToNoisePower;
  if (f_ok && g_ok) return d;
  d.sufficient = false;
  const std::string figures = " (signal/noise power: f " + printfGText(d.snr_f, 3) + ", g " +
                              printfGText(d.snr_g, 3) + "; need " +
                              printfGText(kMinSignalToNoisePower, 3) + ")";
  if (!f_ok && !g_ok)
    d.reason = "no decay signal above the noise: the record looks like pure noise" + figures;
  else {
    d.coupling_only = true;
    d.reason = std::string("the ") + (f_ok ? "g coordinate (q2, p2)" : "f coordinate (q1, p1)") +
               " carries no signal above the noise, so the terms coupling f and g (nu, b_c, b_s, "
               "h_c, h_s) are not identified" +
               figures;
  }
  return d;
}

DataSufficiency assessSweep(const SweepRecord& record, int n_params) {
  DataSufficiency d;
  const size_t n = record.size();
  const long equations = 4 * static_cast<long>(n);  // (3.4): four equations per point
  if (equations > n_params && equations < 2L * n_params) {
    d.sufficient = false;
    d.reason = tooFew(n, "sweep points", equations, n_params);
    return d;
  }
  std::vector<double> w = record.omega0_rad_s;
  std::sort(w.begin(), w.end());
  int distinct = w.empty() ? 0 : 1;
  for (size_t i = 1; i < w.size(); ++i)
    if (w[i] - w[i - 1] > 1e-12 * std::fabs(w[i])) ++distinct;
  if (distinct < kMinDistinctFrequencies) {
    d.sufficient = false;
    d.reason = "the " + std::to_string(n) + " sweep points lie at " + std::to_string(distinct) +
               " distinct excitation frequenc" + (distinct == 1 ? "y" : "ies") + " (span " +
               printfGText(w.empty() ? 0.0 : w.back() - w.front(), 3) + " rad/s; need " +
               std::to_string(kMinDistinctFrequencies) +
               "): the detuning terms of (3.4) cannot be told from the controls";
  }
  return d;
}

void requireSufficientData(const SlowRecord& record, int n_params) {
  const DataSufficiency d = assessFreeDecay(record, n_params);
  if (!d.sufficient && !d.coupling_only)
    throw AnalysisError((record.source.empty() ? "free decay" : record.source) + ": " + d.reason);
}

void requireSufficientData(const SweepRecord& record, int n_params) {
  const DataSufficiency d = assessSweep(record, n_params);
  if (!d.sufficient)
    throw AnalysisError((record.source.empty() ? "sweep" : record.source) + ": " + d.reason);
}

}  // namespace cvg_bench

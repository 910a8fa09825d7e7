#include "cvg_bench/core/estimate/ringdown_segmentation.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "cvg_bench/core/model/errors.h"

namespace cvg_bench {
namespace {

constexpr double kDbPerNeper = 20.0 / 2.302585092994046;  // 20 / ln 10
/// A floor: the tail lies this far above the decay's straight continuation [dB].
constexpr double kFloorExcessDb = 5.0;

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}

/// Least-squares slope of y on t over the finite, non-skipped samples of [a, b).
double slopeOver(const std::vector<double>& t, const std::vector<double>& y,
                 const std::vector<bool>& skip, size_t a, size_t b) {
  std::vector<double> tt, yy;
  for (size_t i = a; i < b; ++i)
    if (!skip[i] && std::isfinite(y[i])) tt.push_back(t[i]), yy.push_back(y[i]);
  if (tt.size() < 3) return 0.0;
  Eigen::MatrixXd X(tt.size(), 2);
  Eigen::VectorXd Y(tt.size());
  for (size_t i = 0; i < tt.size(); ++i) X(i, 0) = 1.0, X(i, 1) = tt[i] - tt.front(), Y(i) = yy[i];
  return X.colPivHouseholderQr().solve(Y)(1);
}

}  // namespace

std::vector<std::string> RingdownSegmentationOptions::validate() const {
  std::vector<std::string> p;
  if (!(floor_margin_db >= 3.0 && floor_margin_db <= 40.0))
    p.push_back("floor_margin_db must be in [3, 40] dB");
  if (!(dropout_depth_db > 0.0)) p.push_back("dropout_depth_db must be > 0 dB");
  if (!(min_decay_db > 0.0)) p.push_back("min_decay_db must be > 0 dB");
  return p;
}

std::vector<double> runningMedian(const std::vector<double>& y, const std::vector<bool>& skip,
                                  int half) {
  const int n = static_cast<int>(y.size());
  std::vector<double> out(n, std::numeric_limits<double>::quiet_NaN());
  std::vector<double> w;
  for (int i = 0; i < n; ++i) {
    w.clear();
    for (int j = std::max(0, i - half); j <= std::min(n - 1, i + half); ++j)
      if (!skip[j] && std::isfinite(y[j])) w.push_back(y[j]);
    if (!w.empty()) out[i] = median(w);
  }
  return out;
}

RingdownSegment segmentRingdown(const RingdownEnvelope& env,
                                const RingdownSegmentationOptions& options) {
  const auto problems = options.validate();
  if (!problems.empty()) throw InputError("ring-down segmentation: " + problems.front());
  const size_t n = env.size();
  if (n < 8) throw InputError("ring-down envelope has " + std::to_string(n) + " samples (< 8)");
  const auto& t = env.t_s;
  const auto& y = env.log_amplitude;
  RingdownSegment seg;
  seg.dropout.assign(n, false);
  for (size_t i = 0; i < n; ++i) seg.dropout[i] = !std::isfinite(y[i]);

  // 1. Drop-outs against the running median (window 11), robust scale from differences.
  {
    const std::vector<double> med = runningMedian(y, seg.dropout, 5);
    std::vector<double> d;
    // Scale from the first half (plateau and early decay): the floor's log noise is far larger.
    for (size_t i = 1; i < std::max<size_t>(n / 2, 8); ++i)
      if (!seg.dropout[i] && !seg.dropout[i - 1]) d.push_back(std::fabs(y[i] - y[i - 1]));
    seg.noise_sd_log = d.empty() ? 0.0 : 1.4826 * median(d) / std::sqrt(2.0);
    // Depth: 3 dB, or 6 local robust sd (MAD about the running median over 21 samples), so that
    // the Rice dips of additive noise near the floor are not taken for drop-outs.
    const double depth0 = std::max(8.0 * seg.noise_sd_log, options.dropout_depth_db / kDbPerNeper);
    std::vector<double> dev(n, 0.0);
    for (size_t i = 0; i < n; ++i)
      dev[i] = std::isfinite(med[i]) && !seg.dropout[i] ? std::fabs(y[i] - med[i]) : 0.0;
    for (size_t i = 0; i < n; ++i) {
      if (seg.dropout[i] || !std::isfinite(med[i])) continue;
      std::vector<double> w;
      for (size_t j = i >= 10 ? i - 10 : 0; j <= std::min(n - 1, i + 10); ++j)
        if (!seg.dropout[j]) w.push_back(dev[j]);
      const double local = 1.4826 * median(w);
      if (y[i] < med[i] - std::max(depth0, 6.0 * local)) seg.dropout[i] = true;
    }
  }
  const int half = std::max(2, static_cast<int>(n / 100));
  const std::vector<double> sm = runningMedian(y, seg.dropout, half);

  // 3 (first pass). Hinge fit of the smoothed envelope on a subsampled grid (<= 1500 points).
  const size_t stride = std::max<size_t>(1, n / 1500);
  std::vector<size_t> idx;
  for (size_t i = 0; i < n; i += stride)
    if (std::isfinite(sm[i])) idx.push_back(i);
  if (idx.size() < 8) throw AnalysisError("ring-down: fewer than 8 usable envelope samples");

  // 2. Noise floor: the record's last tenth lies well above the straight continuation of the decay
  // (fitted on the decay's last stretch above that tail level), which a pure decay does not.
  const size_t tail_a = n - std::max<size_t>(4, n / 10);
  double peak_sm = -std::numeric_limits<double>::infinity();
  size_t i_peak = 0;
  for (size_t i : idx)
    if (sm[i] > peak_sm) peak_sm = sm[i], i_peak = i;
  size_t i_end = n;
  {
    std::vector<double> tail;
    for (size_t i = tail_a; i < n; ++i)
      if (std::isfinite(sm[i])) tail.push_back(sm[i]);
    const double tail_level = tail.empty() ? peak_sm : median(tail);
    const double total = peak_sm - tail_level;
    // The decay's last stretch: from 25 dB (or 3/4 of the drop) to 10 dB (or 1/4) above the tail.
    const double hi = tail_level + std::min(25.0 / kDbPerNeper, 0.75 * total);
    const double lo = tail_level + std::min(10.0 / kDbPerNeper, 0.25 * total);
    size_t a = n, b = n;
    for (size_t i = i_peak; i < n; ++i) {
      if (!std::isfinite(sm[i])) continue;
      if (a == n && sm[i] <= hi) a = i;
      if (sm[i] <= lo) {
        b = i;
        break;
      }
    }
    const double excess_min = kFloorExcessDb / kDbPerNeper;
    if (total > (options.floor_margin_db + options.min_decay_db) / kDbPerNeper && a < n && b < n &&
        b > a + 4) {
      const double slope = slopeOver(t, sm, seg.dropout, a, b);
      double level_a = 0.0;  // the line through the stretch's mean
      double t_mean = 0.0;
      int cnt = 0;
      for (size_t i = a; i < b; ++i)
        if (!seg.dropout[i] && std::isfinite(sm[i])) level_a += sm[i], t_mean += t[i], ++cnt;
      level_a /= std::max(1, cnt), t_mean /= std::max(1, cnt);
      const double t_tail = 0.5 * (t[tail_a] + t.back());
      const double extrapolated = level_a + slope * (t_tail - t_mean);
      if (slope < 0.0 && tail_level - extrapolated > excess_min) {
        // Floor power: the tail's mean power less the decay's continuation.
        double pow_sum = 0.0;
        size_t c = 0;
        for (size_t i = tail_a; i < n; ++i) {
          if (seg.dropout[i] || !std::isfinite(y[i])) continue;
          const double line = level_a + slope * (t[i] - t_mean);
          pow_sum += std::exp(2.0 * (y[i] - tail_level)) - std::exp(2.0 * (line - tail_level));
          ++c;
        }
        const double floor_log =
            tail_level + 0.5 * std::log(std::max(pow_sum / std::max<size_t>(1, c), 1e-6));
        seg.has_floor = true;
        seg.floor_log_amplitude = floor_log;
        const double cut = floor_log + options.floor_margin_db / kDbPerNeper;
        // The span ends at the first smoothed sample after the peak at or below the cut.
        for (size_t i = i_peak; i < n; ++i)
          if (std::isfinite(sm[i]) && sm[i] <= cut) {
            i_end = i;
            break;
          }
        const double reach = floor_log + 3.0 / kDbPerNeper;
        seg.floor_start_s = t.back();
        for (size_t i = i_end; i < n; ++i)
          if (std::isfinite(sm[i]) && sm[i] <= reach) {
            seg.floor_start_s = t[i];
            break;
          }
      }
    }
  }

  // 3. Drive switch-off: the plateau level c0 is the median of the smoothed envelope over the first
  // twentieth (a running median keeps the corner sharp); the decay starts where the envelope first
  // falls delta = max(6 sd, 0.1 dB) below it. A plateau exists when that crossing comes later than
  // three times the time the decay takes to fall by delta.
  std::vector<double> head;
  for (size_t i = 0; i < std::max<size_t>(5, n / 20) && i < n; ++i)
    if (std::isfinite(sm[i])) head.push_back(sm[i]);
  const double c0 = median(head);
  const double delta = std::max(6.0 * seg.noise_sd_log, 0.1 / kDbPerNeper);
  size_t i_cross = 0;
  for (size_t i = 0; i < i_end; ++i)
    if (std::isfinite(sm[i]) && sm[i] < c0 - delta) {
      i_cross = i;
      break;
    }
  const size_t m_after = std::min(i_end, i_cross + std::max<size_t>(8, n / 20));
  const double s_after = -slopeOver(t, sm, seg.dropout, i_cross, m_after);
  seg.has_plateau = s_after > 0.0 && i_cross > 2 && t[i_cross] - t.front() > 3.0 * delta / s_after;
  seg.drive_off_s = seg.has_plateau ? t[i_cross] - delta / s_after : t.front();
  seg.plateau_log_amplitude = c0;
  const double best_c = c0;
  size_t i_start = seg.has_plateau ? i_cross : 0;
  if (i_end <= i_start + 8) throw AnalysisError("ring-down: no decay above the noise floor");
  seg.i_start = i_start;
  seg.i_end = i_end;
  for (size_t i = i_start; i < i_end; ++i) {
    if (seg.dropout[i])
      ++seg.n_dropouts_in_span;
    else
      ++seg.n_used;
  }
  // Decay over the span from the smoothed envelope.
  double s_first = std::numeric_limits<double>::quiet_NaN(), s_last = s_first;
  for (size_t i = i_start; i < i_end; ++i)
    if (std::isfinite(sm[i])) {
      if (!std::isfinite(s_first)) s_first = sm[i];
      s_last = sm[i];
    }
  seg.decay_db = (s_first - s_last) * kDbPerNeper;
  if (i_end > i_start) {
    seg.t_start_s = t[i_start];
    seg.t_end_s = t[i_end - 1];
  }
  std::ostringstream why;
  why.precision(4);
  const std::string unit = env.from_db ? " dB" : " dB re 1 unit";
  if (seg.has_plateau)
    why << "drive off at " << seg.drive_off_s << " s (plateau " << best_c * kDbPerNeper << unit
        << ")";
  else
    why << "no plateau: decay from the first sample at " << t.front() << " s";
  if (seg.has_floor)
    why << "; floor " << seg.floor_log_amplitude * kDbPerNeper << unit << " from "
        << seg.floor_start_s << " s, fit ends " << options.floor_margin_db << " dB above it at "
        << seg.t_end_s << " s";
  else
    why << "; no noise floor reached (decay to the end, " << seg.t_end_s << " s)";
  why << "; " << seg.n_dropouts_in_span << " drop-outs left out of " << (i_end - i_start)
      << " samples; decay " << seg.decay_db << " dB";
  seg.why = why.str();
  if (seg.n_used < 8 ||
      !(seg.decay_db >= std::max(options.min_decay_db, 10.0 * seg.noise_sd_log * kDbPerNeper)))
    throw AnalysisError("ring-down: no decay to fit (" + seg.why + ")");
  return seg;
}

}  // namespace cvg_bench

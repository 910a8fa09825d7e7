#include "cvg_bench/core/single_mode/ringdown_segmentation.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/sample_median.h"
#include "cvg_bench/core/single_mode/ringdown_envelope.h"
#include "cvg_bench/core/single_mode/ringdown_models.h"
#include "cvg_bench/core/single_mode/ringdown_record_window.h"
#include "cvg_bench/core/single_mode/ringdown_straight_span.h"

namespace cvg_bench {
namespace {

double median(const std::vector<double>& v) {
  return sampleMedian(v);
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

struct FloorFit {
  bool ok = false;
  double floor_log = 0.0;  ///< ln of the floor's rms amplitude
  double line_end = 0.0;   ///< the decay's straight continuation at the record's end (ln A)
  double slope = 0.0;      ///< [1/s] of ln A
  double evidence = 0.0;   ///< n ln(SSE_line / SSE_floor)
  double tail_sd = std::numeric_limits<double>::quiet_NaN();  ///< scatter past the crossing
  double head_sd = std::numeric_limits<double>::quiet_NaN();  ///< scatter over the early decay
};

/// Residual sd of a straight line fitted to (u, v) over u in [lo, hi); NaN under 10 points.
double lineScatter(const std::vector<double>& u, const std::vector<double>& v, double lo,
                   double hi) {
  std::vector<int> k;
  for (size_t i = 0; i < u.size(); ++i)
    if (u[i] >= lo && u[i] < hi) k.push_back(static_cast<int>(i));
  if (k.size() < 10) return std::numeric_limits<double>::quiet_NaN();
  Eigen::MatrixXd X(k.size(), 2);
  Eigen::VectorXd Y(k.size());
  for (size_t i = 0; i < k.size(); ++i) X(i, 0) = 1.0, X(i, 1) = u[k[i]], Y(i) = v[k[i]];
  const Eigen::VectorXd c = X.colPivHouseholderQr().solve(Y);
  return std::sqrt((Y - X * c).squaredNorm() / static_cast<double>(k.size() - 2));
}

/// Fits ln A from sample a to the end with a straight decay plus an additive floor (the Rice mean
/// of ringdown_models.h) and with the straight decay alone, by Gauss-Newton on at most 600
/// samples (QR of the Jacobian).
FloorFit fitFloor(const std::vector<double>& t, const std::vector<double>& y,
                  const std::vector<bool>& skip, size_t a, double ref) {
  FloorFit out;
  const size_t n = t.size();
  const size_t stride = std::max<size_t>(1, (n - a) / 600);
  std::vector<double> u, v;
  const double t0 = t[a], ts = std::max(t.back() - t[a], 1e-300);
  for (size_t i = a; i < n; i += stride)
    if (!skip[i] && std::isfinite(y[i])) u.push_back((t[i] - t0) / ts), v.push_back(y[i] - ref);
  const int m = static_cast<int>(u.size());
  if (m < 12) return out;
  Eigen::MatrixXd X(m, 2);
  Eigen::VectorXd Y(m);
  for (int i = 0; i < m; ++i) X(i, 0) = 1.0, X(i, 1) = -u[i], Y(i) = v[i];
  const Eigen::VectorXd line = X.colPivHouseholderQr().solve(Y);
  const double sse0 = (Y - X * line).squaredNorm();
  auto resid = [&](const Eigen::Vector3d& p, Eigen::VectorXd& r) {
    r.resize(m);
    Eigen::VectorXd q(2);
    q << p(0), p(1);
    for (int i = 0; i < m; ++i)
      r(i) = v[i] - ringdownLogAmplitude("linear", q, u[i], std::exp(p(2)));
    return r.allFinite();
  };
  // Gauss-Newton from a floor near, above and below the tail's level; the lowest SSE wins.
  Eigen::Vector3d p_best(line(0), line(1), 0.2);
  double sse_best = std::numeric_limits<double>::infinity();
  for (const double start : {0.2, 0.8, -0.5}) {
    Eigen::Vector3d p(line(0), line(1), start);
    Eigen::VectorXd r, rp;
    if (!resid(p, r)) continue;
    double sse = r.squaredNorm();
    bool failed = false;
    for (int it = 0; it < 40 && !failed; ++it) {
      Eigen::MatrixXd J(m, 3);
      for (int k = 0; k < 3 && !failed; ++k) {
        Eigen::Vector3d pp = p;
        pp(k) += 1e-6;
        failed = !resid(pp, rp);
        J.col(k) = (r - rp) / 1e-6;
      }
      if (failed) break;
      const Eigen::Vector3d step = J.colPivHouseholderQr().solve(r);
      double lam = 1.0;
      bool moved = false, done = false;
      for (int h = 0; h < 12 && !moved; ++h, lam *= 0.5) {
        Eigen::Vector3d pn = p + lam * step;
        pn(2) = std::max(pn(2), -20.0);
        if (resid(pn, rp) && rp.squaredNorm() < sse) {
          done = (sse - rp.squaredNorm()) / sse < 1e-9;
          p = pn, r = rp, sse = rp.squaredNorm(), moved = true;
        }
      }
      if (!moved || done) break;
    }
    if (!failed && sse < sse_best) sse_best = sse, p_best = p;
  }
  if (!std::isfinite(sse_best)) return out;
  const Eigen::Vector3d& p = p_best;
  out.ok = true;
  out.floor_log = ref + p(2);
  out.slope = -p(1) / ts;
  out.line_end = ref + p(0) - p(1);
  out.evidence = m * std::log(std::max(sse0, 1e-300) / std::max(sse_best, 1e-300));
  // Scatter past the line's crossing of the floor, and over the first half before it.
  if (p(1) > 0.0) {
    const double u_cross = (p(0) - p(2)) / p(1);
    out.tail_sd = lineScatter(u, v, u_cross, 2.0);
    out.head_sd = lineScatter(u, v, -1.0, 0.5 * std::min(u_cross, 1.0));
  }
  return out;
}

}  // namespace

std::vector<std::string> RingdownSegmentationOptions::validate() const {
  std::vector<std::string> p;
  if (!(floor_margin_db >= 3.0 && floor_margin_db <= 40.0))
    p.push_back("floor_margin_db must be in [3, 40] dB");
  if (!(min_floor_margin_db >= 3.0 && min_floor_margin_db <= 40.0))
    p.push_back("min_floor_margin_db must be in [3, 40] dB");
  if (!(short_decay_db > 0.0)) p.push_back("short_decay_db must be > 0 dB");
  if (!(dropout_depth_db > 0.0)) p.push_back("dropout_depth_db must be > 0 dB");
  if (!(min_decay_db > 0.0)) p.push_back("min_decay_db must be > 0 dB");
  // The divisors split a window's sample count (a zero would divide by zero).
  for (const size_t d :
       {min_samples, smoothing.divisor, smoothing.peak_grid_points, noise_floor.tail_divisor,
        plateau.head_divisor, plateau.percentile_divisor, plateau.after_divisor,
        plateau.lag_divisor, settling.rate_window_divisor, tail.smooth_divisor, tail.run_divisor})
    if (d < 1) {
      p.push_back("min_samples and the segmentation's divisors must be >= 1");
      break;
    }
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

namespace {

/// The smoothed envelope's peak, read on a grid of at most peak_grid_points samples.
struct EnvelopePeak {
  double level = -std::numeric_limits<double>::infinity();  ///< ln A
  size_t i = 0;
};

/// Step 1: drop-outs against the running median (window 11), robust scale from differences; sets
/// seg's dropout and noise_sd_log.
void markDropouts(const std::vector<double>& y, size_t n,
                  const RingdownSegmentationOptions& options, RingdownSegment* seg) {
  const RingdownSegmentationOptions::Dropouts& o = options.dropouts;
  std::vector<bool>& dropout = seg->dropout;
  const std::vector<double> med = runningMedian(y, dropout, o.median_half);
  std::vector<double> d;
  // Scale from the first half (plateau and early decay): the floor's log noise is far larger.
  for (size_t i = 1; i < std::max<size_t>(n / 2, o.min_scale_samples); ++i)
    if (!dropout[i] && !dropout[i - 1]) d.push_back(std::fabs(y[i] - y[i - 1]));
  seg->noise_sd_log = d.empty() ? 0.0 : kGaussianSdPerMad * median(d) / std::sqrt(2.0);
  // Depth: 3 dB, or 6 local robust sd (MAD about the running median over 21 samples), so that
  // the Rice dips of additive noise near the floor are not taken for drop-outs.
  const double depth0 =
      std::max(o.depth_sd * seg->noise_sd_log, options.dropout_depth_db / kDbPerNeper);
  std::vector<double> dev(n, 0.0);
  for (size_t i = 0; i < n; ++i)
    dev[i] = std::isfinite(med[i]) && !dropout[i] ? std::fabs(y[i] - med[i]) : 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (dropout[i] || !std::isfinite(med[i])) continue;
    std::vector<double> w;
    for (size_t j = i >= o.local_mad_half ? i - o.local_mad_half : 0;
         j <= std::min(n - 1, i + o.local_mad_half); ++j)
      if (!dropout[j]) w.push_back(dev[j]);
    const double local = kGaussianSdPerMad * median(w);
    if (y[i] < med[i] - std::max(depth0, o.local_sd * local)) dropout[i] = true;
  }
}

/// The peak of the smoothed envelope sm; throws AnalysisError under min_samples usable samples.
EnvelopePeak smoothedPeak(const std::vector<double>& sm, size_t n,
                          const RingdownSegmentationOptions& options) {
  // A subsampled grid of the smoothed envelope (<= 1500 points) for the peak below.
  const size_t stride = std::max<size_t>(1, n / options.smoothing.peak_grid_points);
  std::vector<size_t> idx;
  for (size_t i = 0; i < n; i += stride)
    if (std::isfinite(sm[i])) idx.push_back(i);
  if (idx.size() < options.min_samples)
    throw AnalysisError("ring-down: fewer than " + std::to_string(options.min_samples) +
                        " usable envelope samples");
  double peak_sm = -std::numeric_limits<double>::infinity();
  size_t i_peak = 0;
  for (size_t i : idx)
    if (sm[i] > peak_sm) peak_sm = sm[i], i_peak = i;
  EnvelopePeak peak;
  peak.level = peak_sm;
  peak.i = i_peak;
  return peak;
}

/// The level of the record's last tenth and the decay's last stretch [a, b) above it (a, b = n
/// when the smoothed envelope does not fall that far after the peak).
struct LastStretch {
  double tail_level = 0.0;  ///< median smoothed level of the last tenth (ln A)
  double total = 0.0;       ///< the peak above it
  size_t a = 0, b = 0;
};

LastStretch lastStretch(const std::vector<double>& sm, size_t n, const EnvelopePeak& peak,
                        const RingdownSegmentationOptions::NoiseFloor& o) {
  const size_t tail_a = n - std::max<size_t>(o.min_tail_samples, n / o.tail_divisor);
  std::vector<double> tail;
  for (size_t i = tail_a; i < n; ++i)
    if (std::isfinite(sm[i])) tail.push_back(sm[i]);
  const double tail_level = tail.empty() ? peak.level : median(tail);
  const double total = peak.level - tail_level;
  // The decay's last stretch: from 25 dB (or 3/4 of the drop) to 10 dB (or 1/4) above the tail.
  const double hi =
      tail_level + std::min(o.stretch_top_db / kDbPerNeper, o.stretch_top_fraction * total);
  const double lo =
      tail_level + std::min(o.stretch_bottom_db / kDbPerNeper, o.stretch_bottom_fraction * total);
  size_t a = n, b = n;
  for (size_t i = peak.i; i < n; ++i) {
    if (!std::isfinite(sm[i])) continue;
    if (a == n && sm[i] <= hi) a = i;
    if (sm[i] <= lo) {
      b = i;
      break;
    }
  }
  LastStretch out;
  out.tail_level = tail_level;
  out.total = total;
  out.a = a;
  out.b = b;
  return out;
}

/// What step 2 hands on: the span's end (n when no floor ends it) and the margin above a floor.
struct FloorCut {
  size_t i_end = 0;
  double margin_db = 0.0;
};

/// Step 2: a confirmed floor (seg's has_floor, floor_log_amplitude, floor_start_s) or a suspected
/// one (suspected_floor_log_amplitude) ends the span margin_db above it.
FloorCut readFloor(const RingdownEnvelope& env, const std::vector<double>& sm, size_t n,
                   const EnvelopePeak& peak, const RingdownSegmentationOptions& options,
                   RingdownSegment* seg) {
  const auto& t = env.t_s;
  const auto& y = env.log_amplitude;
  const double peak_sm = peak.level;
  const size_t i_peak = peak.i;
  size_t i_end = n;
  double margin_db = options.floor_margin_db;
  const RingdownSegmentationOptions::NoiseFloor& o = options.noise_floor;
  const LastStretch ls = lastStretch(sm, n, peak, o);
  const size_t a = ls.a, b = ls.b;
  if (ls.total > (options.floor_margin_db + options.min_decay_db) / kDbPerNeper && a < n && b < n &&
      b > a + o.min_stretch_samples) {
    const FloorFit ff = fitFloor(t, y, seg->dropout, a, ls.tail_level);
    const double excess = ff.floor_log - ff.line_end;
    const bool scatters = ff.tail_sd > o.scatter;  // false when NaN
    const bool confirmed = ff.ok && ff.slope < 0.0 && excess > o.excess_db / kDbPerNeper &&
                           scatters &&
                           (ff.evidence > o.evidence || ff.tail_sd > o.scatter_ratio * ff.head_sd);
    // A decay that rises less than margin + short_decay_db above its floor keeps
    // short_decay_db of decay: the margin shrinks to what is left, down to min_floor_margin_db
    // (the fit holds the floor; D008 of the development set: 16 dB above a floor, 3 dB left).
    if (ff.ok) {
      const double above_db = (peak_sm - ff.floor_log) * kDbPerNeper;
      margin_db = std::max(std::min(options.floor_margin_db, above_db - options.short_decay_db),
                           std::min(options.floor_margin_db, options.min_floor_margin_db));
    }
    if (ff.ok && ff.slope < 0.0 && !confirmed && excess > 0.0 && scatters) {
      // Not confirmed as a floor, but the best line-plus-floor puts one above the line's end:
      // a record that ends in the bend towards its floor. The span stops the margin above that
      // level all the same (no floor is claimed; the fit below it would bend without a model).
      seg->suspected_floor_log_amplitude = ff.floor_log;
      const double cut = ff.floor_log + margin_db / kDbPerNeper;
      for (size_t i = i_peak; i < n; ++i)
        if (std::isfinite(sm[i]) && sm[i] <= cut) {
          i_end = i;
          break;
        }
    }
    if (confirmed) {
      const double floor_log = ff.floor_log;
      seg->has_floor = true;
      seg->floor_log_amplitude = floor_log;
      const double cut = floor_log + margin_db / kDbPerNeper;
      // The span ends at the first smoothed sample after the peak at or below the cut.
      for (size_t i = i_peak; i < n; ++i)
        if (std::isfinite(sm[i]) && sm[i] <= cut) {
          i_end = i;
          break;
        }
      const double reach = floor_log + o.reach_db / kDbPerNeper;
      seg->floor_start_s = t.back();
      for (size_t i = i_end; i < n; ++i)
        if (std::isfinite(sm[i]) && sm[i] <= reach) {
          seg->floor_start_s = t[i];
          break;
        }
    }
  }
  FloorCut out;
  out.i_end = i_end;
  out.margin_db = margin_db;
  return out;
}

/// What the switch-off reading of step 3 looks at: the smoothed envelope up to the span's end
/// i_end, the head of n_head samples and its median level c0.
struct SwitchOffInput {
  const std::vector<double>& t;
  const std::vector<double>& sm;
  const std::vector<bool>& dropout;
  size_t n, n_head, i_end;
  double c0;
  const RingdownSegmentationOptions::Plateau& o;
};

/// The switch-off read with a threshold delta below the plateau: the crossing, the decay rate
/// after it, whether the stretch before it falls steadily and whether it is a plateau.
struct SwitchOff {
  double delta = 0.0;
  size_t i_cross = 0;
  double s_after = 0.0;
  bool falling = false, has_plateau = false;
};

/// The first smoothed sample before i_end more than delta below the 5th percentile of the
/// smoothed samples [0, upto) (c0 when none), which goes to *level; 0 when none.
size_t crossingBelow(const SwitchOffInput& in, double delta, size_t upto, double* level) {
  const std::vector<double>& sm = in.sm;
  std::vector<double> h;
  for (size_t i = 0; i < upto; ++i)
    if (std::isfinite(sm[i])) h.push_back(sm[i]);
  std::sort(h.begin(), h.end());
  *level = h.empty() ? in.c0 : h[h.size() / in.o.percentile_divisor];
  for (size_t i = 0; i < in.i_end; ++i)
    if (std::isfinite(sm[i]) && sm[i] < *level - delta) return i;
  return size_t{0};
}

/// The switch-off's crossing with threshold delta.
size_t switchOffCrossing(const SwitchOffInput& in, double delta) {
  const std::vector<double>& sm = in.sm;
  // The crossing is taken below the head's 5th percentile: a plateau that beats (two close modes
  // driven together) dips below its median every beat period.
  double c_low = in.c0;
  size_t i_cross = crossingBelow(in, delta, in.n_head, &c_low);
  // A plateau shorter than the head is followed by decay samples that lower that percentile (the
  // drive-off then lands up to 3 dB into the decay and the span past a fast first stage). The
  // head up to its last sample at or above the median gives an earlier crossing; it is taken when
  // the envelope does not come back above that level before the first crossing (a beating plateau
  // does).
  size_t last_up = 0;
  for (size_t i = 0; i < in.n_head; ++i)
    if (std::isfinite(sm[i]) && sm[i] >= in.c0) last_up = i;
  double c_short = in.c0;
  const size_t i_short = crossingBelow(in, delta, last_up + 1, &c_short);
  bool back = false;
  for (size_t i = i_short; i < i_cross && !back; ++i)
    back = std::isfinite(sm[i]) && sm[i] >= c_short;
  if (i_short < i_cross && !back) i_cross = i_short, c_low = c_short;
  return i_cross;
}

/// Whether the envelope before the crossing falls steadily: 90 % of its differences over a tenth
/// of the stretch negative and its mean rate 0.3 or more of s_after (a beating plateau falls and
/// rises).
bool fallsSteadily(const SwitchOffInput& in, size_t i_cross, double s_after) {
  const std::vector<double>& sm = in.sm;
  const double s_before = -slopeOver(in.t, sm, in.dropout, 0, i_cross);
  const size_t lag = std::max<size_t>(1, i_cross / in.o.lag_divisor);
  size_t down = 0, all = 0;
  for (size_t i = 0; i + lag < i_cross; ++i)
    if (std::isfinite(sm[i]) && std::isfinite(sm[i + lag])) ++all, down += sm[i + lag] < sm[i];
  return all > 0 && down >= in.o.falling_share * all && s_before >= in.o.rate_ratio * s_after;
}

SwitchOff readSwitchOff(const SwitchOffInput& in, double delta) {
  const std::vector<double>& t = in.t;
  const size_t i_cross = switchOffCrossing(in, delta);
  const size_t m_after = std::min(
      in.i_end, i_cross + std::max<size_t>(in.o.min_after_samples, in.n / in.o.after_divisor));
  const double s_after = -slopeOver(t, in.sm, in.dropout, i_cross, m_after);
  // A plateau does not fall steadily at 0.3 or more of the rate after the crossing (a record that
  // starts inside a fast first stage of the decay has no plateau; its median level over the first
  // twentieth is no drive level).
  const bool falling = fallsSteadily(in, i_cross, s_after);
  SwitchOff r;
  r.delta = delta, r.i_cross = i_cross, r.s_after = s_after, r.falling = falling;
  r.has_plateau = s_after > 0.0 && i_cross > in.o.min_cross_index &&
                  t[i_cross] - t.front() > in.o.delay * delta / s_after && !falling;
  return r;
}

/// Detector settling: a lock-in or video filter rounds the corner at switch-off, so the decay rate
/// starts near zero and rises over a few filter time constants while the true rate may already be
/// falling (damping that grows with the amplitude, a fast first stage). The local rate (over
/// n / 80 samples) peaks once the filter has nearly caught up; the span starts at the drive-off
/// plus twice the time to that peak, where the filter's transient has decayed (a 2-pole filter
/// leaves ~1 dB at the corner, 0.25 dB after 2.5 time constants, 0.03 dB after 5). At most the
/// first 3 dB of decay are skipped. Returns the span's start.
size_t settledStart(const std::vector<double>& t, const std::vector<double>& sm,
                    const std::vector<bool>& dropout, size_t n, size_t i_start, size_t i_end,
                    double drive_off_s, const RingdownSegmentationOptions::Settling& o) {
  if (!(i_end > i_start + o.min_span)) return i_start;
  const double s0 = sm[i_start];
  size_t a3 = i_end, a13 = i_end;
  for (size_t i = i_start; i < i_end; ++i) {
    if (!std::isfinite(sm[i])) continue;
    if (a3 == i_end && sm[i] <= s0 - o.skip_db / kDbPerNeper) a3 = i;
    if (sm[i] <= s0 - o.rate_end_db / kDbPerNeper) {
      a13 = i;
      break;
    }
  }
  if (!(a3 < i_end && a13 > a3 + o.min_rate_samples)) return i_start;
  // Time of the peak local rate within the first 3 dB (window centre).
  const size_t w = std::max<size_t>(o.min_rate_window, n / o.rate_window_divisor);
  double peak = slopeOver(t, sm, dropout, a3, a13);  // negative: ln A falls
  double t_peak = drive_off_s;
  for (size_t i = i_start; i + w < a3; ++i) {
    const double sl = slopeOver(t, sm, dropout, i, i + w);
    if (sl < peak) peak = sl, t_peak = 0.5 * (t[i] + t[i + w - 1]);
  }
  const double t_skip = drive_off_s + o.time_factor * std::max(0.0, t_peak - drive_off_s);
  size_t i_new = i_start;
  while (i_new < a3 && t[i_new] < t_skip) ++i_new;
  return i_new;
}

/// Step 4's span [i_start, i_end): its counts, its times and its decay from the smoothed
/// envelope.
void setSmoothedSpan(const std::vector<double>& t, const std::vector<double>& sm, size_t i_start,
                     size_t i_end, RingdownSegment* seg) {
  seg->i_start = i_start;
  seg->i_end = i_end;
  for (size_t i = i_start; i < i_end; ++i) {
    if (seg->dropout[i])
      ++seg->n_dropouts_in_span;
    else
      ++seg->n_used;
  }
  // Decay over the span from the smoothed envelope.
  double s_first = std::numeric_limits<double>::quiet_NaN(), s_last = s_first;
  for (size_t i = i_start; i < i_end; ++i)
    if (std::isfinite(sm[i])) {
      if (!std::isfinite(s_first)) s_first = sm[i];
      s_last = sm[i];
    }
  seg->decay_db = (s_first - s_last) * kDbPerNeper;
  if (i_end > i_start) {
    seg->t_start_s = t[i_start];
    seg->t_end_s = t[i_end - 1];
  }
}

/// Step 4's sentence: the plateau (at best_c) or none, the floor confirmed, suspected or none,
/// the drop-outs and the decay.
std::string segmentWhy(const RingdownEnvelope& env, const RingdownSegment& seg, double best_c,
                       double margin_db) {
  const auto& t = env.t_s;
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
        << seg.floor_start_s << " s, fit ends " << margin_db << " dB above it at " << seg.t_end_s
        << " s";
  else if (std::isfinite(seg.suspected_floor_log_amplitude))
    why << "; the decay bends towards a floor near "
        << seg.suspected_floor_log_amplitude * kDbPerNeper << unit
        << " (too little of it in the record to confirm one): fit ends " << margin_db
        << " dB above that level at " << seg.t_end_s << " s";
  else
    why << "; no noise floor reached (decay to the end, " << seg.t_end_s << " s)";
  why << "; " << seg.n_dropouts_in_span << " drop-outs left out of " << (seg.i_end - seg.i_start)
      << " samples; decay " << seg.decay_db << " dB";
  return why.str();
}

/// Steps 1-4 of the header on a window that holds one ring-down.
RingdownSegment segmentWindow(const RingdownEnvelope& env,
                              const RingdownSegmentationOptions& options) {
  const auto problems = options.validate();
  if (!problems.empty()) throw InputError("ring-down segmentation: " + problems.front());
  const size_t n = env.size();
  if (n < options.min_samples)
    throw InputError("ring-down envelope has " + std::to_string(n) + " samples (< " +
                     std::to_string(options.min_samples) + ")");
  const auto& t = env.t_s;
  const auto& y = env.log_amplitude;
  RingdownSegment seg;
  seg.dropout.assign(n, false);
  for (size_t i = 0; i < n; ++i) seg.dropout[i] = !std::isfinite(y[i]);

  // 1. Drop-outs against the running median (window 11), robust scale from differences.
  markDropouts(y, n, options, &seg);
  const int half =
      std::max(options.smoothing.min_half, static_cast<int>(n / options.smoothing.divisor));
  const std::vector<double> sm = runningMedian(y, seg.dropout, half);
  const EnvelopePeak peak = smoothedPeak(sm, n, options);

  // 2. Noise floor: from 25 dB above the level of the record's last tenth to the end, a straight
  // decay plus an additive floor beats the straight decay, with the floor above its continuation.
  const FloorCut floor_cut = readFloor(env, sm, n, peak, options, &seg);
  const size_t i_end = floor_cut.i_end;
  const double margin_db = floor_cut.margin_db;

  // 3. Drive switch-off: the plateau level c0 is the median of the smoothed envelope over the first
  // twentieth (a running median keeps the corner sharp); the decay starts where the envelope first
  // falls delta = max(6 sd, 0.1 dB) below it. A plateau exists when that crossing comes later than
  // three times the time the decay takes to fall by delta.
  const size_t n_head = std::min(
      n, std::max<size_t>(options.plateau.min_head_samples, n / options.plateau.head_divisor));
  std::vector<double> head;
  for (size_t i = 0; i < n_head; ++i)
    if (std::isfinite(sm[i])) head.push_back(sm[i]);
  const double c0 = median(head);
  const double delta_noise = std::max(options.plateau.switch_off_sd * seg.noise_sd_log,
                                      options.plateau.switch_off_min_db / kDbPerNeper);
  const SwitchOffInput in{t, sm, seg.dropout, n, n_head, i_end, c0, options.plateau};
  // A drive level that creeps by a few tenths of a dB (an oscillator's amplitude loop on a real
  // export, D060 of the development set: 0.6 dB over 1.6 s) crosses a noise-sized threshold on the
  // plateau, where nothing decays after it: then the switch-off is read 1 dB below the plateau.
  SwitchOff so = readSwitchOff(in, delta_noise);
  if (!so.has_plateau && !so.falling) {
    const SwitchOff wide =
        readSwitchOff(in, std::max(delta_noise, options.plateau.wide_switch_off_db / kDbPerNeper));
    if (wide.has_plateau) so = wide;
  }
  const double delta = so.delta;
  const size_t i_cross = so.i_cross;
  const double s_after = so.s_after;
  seg.has_plateau = so.has_plateau;
  seg.drive_off_s = seg.has_plateau ? t[i_cross] - delta / s_after : t.front();
  seg.plateau_log_amplitude = c0;
  const double best_c = c0;
  size_t i_start = seg.has_plateau ? i_cross : 0;
  // Detector settling: the first decibels, while the detector's filter catches up, are skipped.
  i_start = settledStart(t, sm, seg.dropout, n, i_start, i_end, seg.drive_off_s, options.settling);

  // 4. Refusal: too short a span, too little decay.
  seg.floor_margin_db = margin_db;
  if (i_end <= i_start + options.min_samples)
    throw AnalysisError("ring-down: no decay above the noise floor");
  setSmoothedSpan(t, sm, i_start, i_end, &seg);
  seg.why = segmentWhy(env, seg, best_c, margin_db);
  if (seg.n_used < options.min_samples ||
      !(seg.decay_db >=
        std::max(options.min_decay_db, options.min_decay_sd * seg.noise_sd_log * kDbPerNeper)))
    throw AnalysisError("ring-down: no decay to fit (" + seg.why + ")");
  return seg;
}

}  // namespace

namespace {

/// Level [dB] near sample i: median of the finite, non-skipped samples within 2 of it.
double levelNear(const RingdownEnvelope& env, const std::vector<bool>& skip, size_t i) {
  std::vector<double> w;
  for (size_t k = i >= 2 ? i - 2 : 0; k < std::min(env.size(), i + 3); ++k)
    if (!skip[k] && std::isfinite(env.log_amplitude[k])) w.push_back(env.log_amplitude[k]);
  return median(w) * kDbPerNeper;
}

/// The span's counts, times and decay after its ends moved.
void setSpan(const RingdownEnvelope& env, size_t i_start, size_t i_end, RingdownSegment* seg) {
  seg->i_start = i_start, seg->i_end = i_end;
  seg->n_used = seg->n_dropouts_in_span = 0;
  for (size_t i = i_start; i < i_end; ++i)
    seg->dropout[i] ? ++seg->n_dropouts_in_span : ++seg->n_used;
  seg->t_start_s = env.t_s[i_start];
  seg->t_end_s = env.t_s[i_end - 1];
  seg->decay_db = levelNear(env, seg->dropout, i_start) - levelNear(env, seg->dropout, i_end - 1);
}

/// The straight stretch (ringdown_straight_span.h) corrects the span where the plateau-and-floor
/// reading of steps 2-3 does not hold on a real export: a start on a plateau that creeps or
/// wanders (the level falls at under half the decay rate up to the stretch), and an end past a
/// floor that wanders (the stretch ends in a floor's scatter before the span does). Smooth bends
/// (a damping law, two stages) and faster falls (a detection loss) are left to the models.
void correctWithStraightSpan(const RingdownEnvelope& env, double margin_db,
                             const RingdownSegmentationOptions::StraightSpanRules& o,
                             RingdownSegment* seg, std::ostringstream* why) {
  const StraightSpan ss = findStraightSpan(env.t_s, env.log_amplitude, seg->dropout);
  if (!ss.ok || ss.span_db < o.min_correct_db) return;
  why->precision(4);
  size_t a = seg->i_start, b = seg->i_end;
  if (ss.i_start > a && ss.i_start + o.min_gap_samples < b) {
    const double fall = levelNear(env, seg->dropout, a) - levelNear(env, seg->dropout, ss.i_start);
    const double expected = -ss.slope_db_s * (env.t_s[ss.i_start] - env.t_s[a]);
    // The lowest level before the stretch against its line extrapolated back: a detector's
    // switch-off transient undershoots and comes back; a decay (fast first stage, damping law)
    // stays above the line of its slower part.
    double under = 0.0;
    const double c0 = levelNear(env, seg->dropout, ss.i_start);
    for (size_t i = a; i < ss.i_start; ++i)
      under = std::max(under, c0 + ss.slope_db_s * (env.t_s[i] - env.t_s[ss.i_start]) -
                                  levelNear(env, seg->dropout, i));
    if (under > o.transient_dip_db && ss.i_start - a <= (b - a) * o.transient_max_percent / 100) {
      *why << "; the level dips " << under << " dB below the decay's line before "
           << env.t_s[ss.i_start] << " s and comes back (a detector's switch-off transient): "
           << "the span starts at " << env.t_s[ss.i_start] << " s";
      a = ss.i_start;
    } else if (fall < o.creep_ratio * expected) {
      *why << "; the level falls " << fall << " dB from " << env.t_s[a] << " s to "
           << env.t_s[ss.i_start] << " s where the decay rate gives " << expected
           << " dB (drive still on or settling): the span starts at " << env.t_s[ss.i_start]
           << " s";
      a = ss.i_start;
    }
  }
  // Past the stretch, up to the span's end: a floor (or a detector's tail) stops falling; a
  // slowing decay or a beat still falls at over flat_fraction of the rate on the whole. Only
  // where no floor was confirmed or suspected: one already ends the span 10 dB above it (on the
  // generator's reporting base 99417733 the cut there took 5 beats of 100 out of their span; on
  // the real development set 15 of its 17 cuts were on records without a confirmed floor).
  if (!seg->has_floor && !std::isfinite(seg->suspected_floor_log_amplitude) &&
      ss.i_end + o.min_gap_samples < b && ss.i_end > a + o.min_gap_samples) {
    std::vector<double> tt, yy;
    for (size_t i = ss.i_end; i < b; ++i)
      if (!seg->dropout[i] && std::isfinite(env.log_amplitude[i]))
        tt.push_back(env.t_s[i]), yy.push_back(env.log_amplitude[i] * kDbPerNeper);
    if (tt.size() >= o.min_gap_samples) {
      std::vector<bool> keep(tt.size(), false);
      const double post = slopeOver(tt, yy, keep, 0, tt.size());
      // (The stretch's own reading of its end, flat over 30 % of its length past it, was tried
      // as a second trigger on 29 Nov: D053 of the development set right, one of the generator's
      // 30 beats without a floor cut at a dip on base 41000000; not kept.)
      if (post > StraightSpanOptions().flat_fraction * ss.slope_db_s) {
        // The floor's level: the median of the last third of that stretch. The span ends where
        // the level first comes within margin_db of it, and not before the straight stretch's
        // end (a beat's dip can end the stretch long before its envelope reaches the floor).
        std::vector<double> last(yy.end() - yy.size() / 3, yy.end());
        const double floor_db = median(last);
        size_t j = ss.i_end;
        while (j < b && !(levelNear(env, seg->dropout, j) <= floor_db + margin_db)) ++j;
        if (j < b) {
          *why << "; the decay meets a floor near " << floor_db << " dB (from "
               << env.t_s[ss.i_end - 1] << " s to " << env.t_s[b - 1] << " s the level falls at "
               << post << " dB/s against " << ss.slope_db_s << " dB/s): the span ends " << margin_db
               << " dB above it at " << env.t_s[j] << " s";
          b = std::max(j, a + 9);
        }
      }
    }
  }
  if (a != seg->i_start || b != seg->i_end) setSpan(env, a, b, seg);
}

/// A tail that bends into a floor nobody confirmed: over the span's last quarter the level falls
/// at under half the rate of its middle half while its sample-to-sample scatter grows by half
/// (additive noise taking over as the signal sinks into it). A damping law slows the decay
/// without the scatter growing (the relative noise stays), so it keeps its tail. The span then
/// ends where the smoothed level leaves the line of its first three quarters by more than the
/// tolerance for good (docs/validation_ringdown_real.md, "tails").
void trimFloorTail(const RingdownEnvelope& env, const RingdownSegmentationOptions::Tail& o,
                   RingdownSegment* seg, std::ostringstream* why) {
  std::vector<size_t> idx;
  for (size_t i = seg->i_start; i < seg->i_end; ++i)
    if (!seg->dropout[i] && std::isfinite(env.log_amplitude[i])) idx.push_back(i);
  const size_t n = idx.size();
  if (n < o.min_samples) return;
  std::vector<double> t(n), y(n);
  for (size_t k = 0; k < n; ++k)
    t[k] = env.t_s[idx[k]], y[k] = env.log_amplitude[idx[k]] * kDbPerNeper;
  const std::vector<bool> none(n, false);
  const std::vector<double> sm =
      runningMedian(y, none, std::max<int>(o.min_smooth_half, n / o.smooth_divisor));
  const size_t q1 = n / 4, q2 = n / 2, q3 = 3 * n / 4;
  const double s_mid = slopeOver(t, sm, none, q1, q3);
  const double s_end = slopeOver(t, sm, none, q3, n);
  if (!(s_mid < 0.0) || !(s_end > o.slowing_ratio * s_mid)) return;
  auto roughness = [&](size_t a, size_t b) {
    std::vector<double> d;
    for (size_t k = a + 1; k < b; ++k) d.push_back(std::fabs(y[k] - y[k - 1]));
    return kGaussianSdPerMad * median(d) / std::sqrt(2.0);
  };
  const double r_mid = roughness(q1, q3), r_end = roughness(q3, n);
  if (!(r_end > o.roughness_growth * r_mid)) return;
  // The line of the first three quarters; the tail leaves it for good where `run` consecutive
  // smoothed levels lie above it by more than the tolerance.
  Eigen::MatrixXd X(q3, 2);
  Eigen::VectorXd Y(q3);
  for (size_t k = 0; k < q3; ++k) X(k, 0) = 1.0, X(k, 1) = t[k] - t[0], Y(k) = sm[k];
  const Eigen::Vector2d c = X.colPivHouseholderQr().solve(Y);
  const double tol = std::max(o.tolerance_db, o.tolerance_sd * r_mid);
  const size_t run = std::max<size_t>(o.min_run, n / o.run_divisor);
  size_t cut = n, above = 0;
  for (size_t k = q2; k < n; ++k) {
    if (sm[k] - c(0) - c(1) * (t[k] - t[0]) > tol) {
      if (++above >= run) {
        cut = k + 1 - above;
        break;
      }
    } else {
      above = 0;
    }
  }
  if (cut >= n) return;
  const double kept_db = -c(1) * (t[cut - 1] - t[0]);
  if (kept_db < o.min_kept_db) return;
  why->precision(4);
  *why << "; from " << t[cut] << " s the level leaves the decay's line upwards (over its last "
       << "quarter it falls at " << s_end << " dB/s against " << s_mid << " dB/s, its scatter "
       << r_end << " dB against " << r_mid << " dB: a floor taking over): the span ends there";
  setSpan(env, seg->i_start, idx[cut - 1] + 1, seg);
}

}  // namespace

RingdownSegment segmentRingdown(const RingdownEnvelope& env,
                                const RingdownSegmentationOptions& options) {
  const RingdownWindow w = findRingdownWindow(env.t_s, env.log_amplitude);
  RingdownEnvelope sub;
  sub.frequency_hz = env.frequency_hz;
  sub.from_db = env.from_db;
  sub.t_s.assign(env.t_s.begin() + w.first, env.t_s.begin() + w.last);
  sub.log_amplitude.assign(env.log_amplitude.begin() + w.first, env.log_amplitude.begin() + w.last);
  RingdownSegment seg;
  std::string refusal;
  try {
    seg = segmentWindow(sub, options);
  } catch (const AnalysisError& e) {
    refusal = e.what();
  }
  std::ostringstream why;
  why << w.why;
  std::vector<bool> dropout(env.size(), true);
  if (refusal.empty()) {
    // Back to the record's sample numbers; samples outside the window take no part in any fit.
    std::copy(seg.dropout.begin(), seg.dropout.end(), dropout.begin() + w.first);
    seg.dropout = std::move(dropout);
    seg.i_start += w.first;
    seg.i_end += w.first;
    why << (w.why.empty() ? "" : "; ") << seg.why;
    correctWithStraightSpan(env, options.floor_margin_db, options.straight_span, &seg, &why);
    if (!seg.has_floor && !std::isfinite(seg.suspected_floor_log_amplitude))
      trimFloorTail(env, options.tail, &seg, &why);
  } else {
    // The plateau-and-floor reading found no decay: a straight stretch of 10 dB (min_fallback_db)
    // or more is one.
    std::string window_why = w.why;
    for (size_t i = w.first; i < w.last; ++i) dropout[i] = !std::isfinite(env.log_amplitude[i]);
    StraightSpan ss = findStraightSpan(env.t_s, env.log_amplitude, dropout);
    if (!ss.ok || ss.span_db < options.straight_span.min_fallback_db) {
      // None in the window either: the whole record, from each of its drive-on stretches (a
      // decay followed by a re-excitation, or by a clipped stretch the window took for one).
      std::vector<bool> all(env.size());
      for (size_t i = 0; i < env.size(); ++i) all[i] = !std::isfinite(env.log_amplitude[i]);
      StraightSpanOptions every;
      every.all_peaks = true;
      const StraightSpan whole = findStraightSpan(env.t_s, env.log_amplitude, all, every);
      if (!whole.ok || whole.span_db < options.straight_span.min_fallback_db)
        throw AnalysisError(refusal + (w.why.empty() ? "" : " [" + w.why + "]"));
      ss = whole;
      dropout = std::move(all);
      window_why = "the window read (" + (w.why.empty() ? std::string("the whole record") : w.why) +
                   ") holds no decay; the whole record is read from each drive-on stretch";
    }
    seg.dropout = std::move(dropout);
    seg.drive_off_s = env.t_s[ss.i_start];
    setSpan(env, ss.i_start, ss.i_end, &seg);
    why.str("");
    why.precision(4);
    why << window_why << (window_why.empty() ? "" : "; ") << "no plateau or floor read (" << refusal
        << "); a straight decay of " << ss.span_db << " dB from " << seg.t_start_s << " s to "
        << seg.t_end_s << " s, ending in " << ss.endName();
  }
  seg.why = why.str();
  return seg;
}

}  // namespace cvg_bench

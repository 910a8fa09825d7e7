#include "cvg_bench/core/single_mode/ringdown_record_window.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "cvg_bench/core/common/sample_median.h"
#include "cvg_bench/core/single_mode/ringdown_envelope.h"
#include "cvg_bench/core/single_mode/ringdown_segmentation.h"

namespace cvg_bench {
namespace {

/// Median of the finite values of y[a, b) (clipped to the record); NaN when none.
double medianOf(const std::vector<double>& y, long a, long b) {
  std::vector<double> w;
  for (long i = std::max(0L, a); i < std::min<long>(b, y.size()); ++i)
    if (std::isfinite(y[i])) w.push_back(y[i]);
  if (w.empty()) return std::numeric_limits<double>::quiet_NaN();
  const size_t m = w.size() / 2;
  std::nth_element(w.begin(), w.begin() + m, w.end());
  return w[m];
}

struct Step {
  size_t i0 = 0;       ///< first sample of the step (of its ramp, for a slow one)
  size_t i = 0;        ///< first sample after the step
  double left = 0.0;   ///< level before [dB]
  double right = 0.0;  ///< level after [dB]
  double sharp = 0.0;  ///< jump over the local sd of sample-to-sample differences
};

/// Sharp steps of the level y_db at half-width h (step 1 of the header), in time order.
std::vector<Step> stepsAtScale(const std::vector<double>& y_db, long h, double min_jump,
                               const RingdownWindowOptions& o) {
  std::vector<Step> steps;
  const long n = static_cast<long>(y_db.size());
  for (long i = 2 * h; i + 2 * h <= n; ++i) {
    const double L = medianOf(y_db, i - h, i), R = medianOf(y_db, i, i + h);
    const double jump = std::fabs(R - L);
    if (!(jump >= min_jump)) continue;
    const double L2 = medianOf(y_db, i - 2 * h, i - h), R2 = medianOf(y_db, i + h, i + 2 * h);
    if (!(std::fabs(L - L2) < jump / o.step_side_divisor &&
          std::fabs(R2 - R) < jump / o.step_side_divisor))
      continue;
    // Local scatter of the differences over step_scatter_half samples each side, the jump itself
    // left out.
    std::vector<double> d;
    for (long k = std::max(1L, i - o.step_scatter_half);
         k < std::min(n, i + o.step_scatter_half + 1); ++k)
      if (k != i && std::isfinite(y_db[k]) && std::isfinite(y_db[k - 1]))
        d.push_back(std::fabs(y_db[k] - y_db[k - 1]));
    double sd = 0.0;
    if (!d.empty()) {
      std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
      sd = kGaussianSdPerMad * d[d.size() / 2];
    }
    const double sharp = jump / std::max(sd, 1e-12);
    if (sharp < o.step_min_sharpness) continue;
    // Keep the largest jump of a cluster of adjacent candidates.
    if (!steps.empty() && static_cast<long>(steps.back().i) + h >= i) {
      if (jump > std::fabs(steps.back().right - steps.back().left))
        steps.back() = {size_t(i), size_t(i), L, R, sharp};
      continue;
    }
    steps.push_back({static_cast<size_t>(i), static_cast<size_t>(i), L, R, sharp});
  }
  return steps;
}

/// Steps of step 1 of the header: sharp ones over step_half samples, and rising ramps of up to
/// ramp_scale * step_half samples that raise the level by end_step_db or more (a drive toggled
/// on through a detector's filter, D197 of the development set: 60 dB over ~24 samples, which a
/// 3-sample comparison reads as a slope). A ramp's i0 is its first sample, i the first after it.
std::vector<Step> findSteps(const std::vector<double>& y_db, const RingdownWindowOptions& o) {
  const long h = std::max(1, o.step_half);
  std::vector<Step> steps = stepsAtScale(y_db, h, o.step_db, o);
  for (const int scale : o.ramp_scales) {
    const long H = h * scale;
    if (scale > o.ramp_scale) break;
    for (Step r : stepsAtScale(y_db, H, o.end_step_db, o)) {
      // Only rises: a fall of 20 dB over 10-30 samples is as often the decay itself (a fast first
      // stage, a short record) as a step (the development set's D201, D204: -60 dB "ramps").
      if (!(r.right > r.left)) continue;
      // The ramp's ends: the last sample at the left level and the first at the right one (within
      // ramp_end_tolerance of the jump), searched within H samples of the step.
      const double tol = o.ramp_end_tolerance * std::fabs(r.right - r.left);
      size_t a = r.i, b = r.i;
      while (a > 0 && r.i - a < size_t(H) &&
             !(std::isfinite(y_db[a - 1]) && std::fabs(y_db[a - 1] - r.left) <= tol))
        --a;
      while (b < y_db.size() && b - r.i < size_t(H) &&
             !(std::isfinite(y_db[b]) && std::fabs(y_db[b] - r.right) <= tol))
        ++b;
      // Sharp steps found within the ramp are part of it: the ramp replaces them when it changes
      // the level further (a 3-sample comparison sees only part of a ramp's height).
      r.i0 = a, r.i = std::max(b, a + 1);
      const double jump = std::fabs(r.right - r.left);
      bool larger_known = false;
      for (const Step& s : steps)
        larger_known =
            larger_known || (s.i + h >= a && s.i <= b + h && std::fabs(s.right - s.left) >= jump);
      if (larger_known) continue;
      steps.erase(std::remove_if(steps.begin(), steps.end(),
                                 [&](const Step& s) { return s.i + h >= a && s.i <= b + h; }),
                  steps.end());
      steps.push_back(r);
    }
  }
  std::sort(steps.begin(), steps.end(), [](const Step& x, const Step& y) { return x.i < y.i; });
  return steps;
}

/// How far the smoothed level falls after its highest point in [a, b) [dB]; 0 when undefined.
double fallDb(const std::vector<double>& sm, size_t a, size_t b) {
  double top = -std::numeric_limits<double>::infinity(), fall = 0.0;
  for (size_t i = a; i < std::min(b, sm.size()); ++i) {
    if (!std::isfinite(sm[i])) continue;
    top = std::max(top, sm[i]);
    fall = std::max(fall, top - sm[i]);
  }
  return fall;
}

/// The record's level in dB, smoothed, and the drive level (the smoothed level's peak).
struct Levels {
  std::vector<double> y_db;                               ///< ln A in dB (NaN where not finite)
  std::vector<double> sm;                                 ///< running median of y_db
  size_t i_peak = 0;                                      ///< where sm peaks
  double top = -std::numeric_limits<double>::infinity();  ///< the peak of sm [dB]
};

/// The levels of the record y (ln A).
Levels readLevels(const std::vector<double>& y, const RingdownWindowOptions& o) {
  const size_t n = y.size();
  std::vector<double> y_db(n);
  std::vector<bool> skip(n);
  for (size_t i = 0; i < n; ++i) {
    y_db[i] = std::isfinite(y[i]) ? y[i] * kDbPerNeper : std::numeric_limits<double>::quiet_NaN();
    skip[i] = !std::isfinite(y[i]);
  }
  Levels lv;
  lv.sm = runningMedian(y_db, skip, std::max<int>(o.min_smooth_half, n / o.smooth_divisor));
  lv.y_db = std::move(y_db);
  const std::vector<double>& sm = lv.sm;
  size_t i_peak = 0;
  double top = -std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < n; ++i)
    if (std::isfinite(sm[i]) && sm[i] > top) top = sm[i], i_peak = i;
  lv.i_peak = i_peak;
  lv.top = top;
  return lv;
}

/// Step 3: a record that starts under the drive level is read from its last rise to near it;
/// returns whether it started under.
bool readStartUnderDrive(const std::vector<double>& t, const Levels& lv,
                         const RingdownWindowOptions& o, RingdownWindow* w,
                         std::ostringstream* why) {
  const size_t n = lv.sm.size();
  const std::vector<double>& sm = lv.sm;
  const double top = lv.top;
  const double head = medianOf(sm, 0, std::max<long>(o.min_head_samples, n / o.head_divisor));
  const bool started_under = top - head > o.start_below_db;
  if (started_under) {
    size_t j = lv.i_peak;
    while (j > 0 &&
           !(std::isfinite(sm[j - 1]) && sm[j - 1] < top - o.start_rise_fraction * o.near_top_db))
      --j;
    w->first = j;
    *why << "the record starts " << top - head << " dB under the drive level (floor before the "
         << "drive or its ramp-up): read from " << t[j] << " s";
  }
  return started_under;
}

/// A ring-down kept when the drive came on again after it (2b).
struct Candidate {
  size_t first, last;
  std::string why;
};

/// Steps 2 and 4: the steps after the peak move the window's start (switch-off, drive on again)
/// or end it (any other large or sharp step); returns the ring-downs the drive's coming on again
/// ended.
std::vector<Candidate> readSteps(const std::vector<double>& t, const Levels& lv,
                                 const RingdownWindowOptions& o, RingdownWindow* w,
                                 std::ostringstream* why) {
  const std::vector<double>& sm = lv.sm;
  const size_t i_peak = lv.i_peak;
  const double top = lv.top;
  std::vector<Candidate> earlier;
  // The drive level is first reached here; a re-excitation may lie between it and the peak.
  size_t i_first_top = i_peak;
  for (size_t i = 0; i < i_peak; ++i)
    if (std::isfinite(sm[i]) && sm[i] >= top - o.near_top_db) {
      i_first_top = i;
      break;
    }
  for (const Step& s : findSteps(lv.y_db, o)) {
    if (s.i <= w->first) continue;
    const double jump = s.right - s.left;
    const bool comes_on_again =
        s.i > i_first_top && s.right >= top - o.near_top_db && s.left < top - o.near_top_db;
    if (s.i <= i_peak && !comes_on_again) continue;
    if (s.left >= top - o.near_top_db && jump < 0.0) {
      w->first = s.i;
      *why << (why->tellp() > 0 ? "; " : "") << "a step of " << jump << " dB at switch-off ("
           << t[s.i] << " s): the decay is read after it";
    } else if (comes_on_again) {
      const size_t end = s.i0 > static_cast<size_t>(o.step_half) ? s.i0 - o.step_half : s.i0;
      if (end > w->first) earlier.push_back({w->first, end, why->str()});
      w->first = s.i;
      *why << (why->tellp() > 0 ? "; " : "") << "the drive comes on again at " << t[s.i]
           << " s: the last ring-down is read";
    } else if (std::fabs(jump) >= o.end_step_db || s.sharp >= o.end_step_sharpness) {
      w->last = s.i0 > static_cast<size_t>(o.step_half) ? s.i0 - o.step_half : s.i0;
      *why << (why->tellp() > 0 ? "; " : "") << "a step of " << (jump > 0 ? "+" : "") << jump
           << " dB in " << std::max<size_t>(o.step_half, s.i - s.i0) << " samples at " << t[s.i0]
           << " s after the decay began (the mode leaves the detector's band, or the detector "
              "changes range or stops): the record is read up to "
           << t[w->last - 1] << " s";
      break;
    }
  }
  return earlier;
}

/// Step 2b: the last ring-down is read unless one before a re-excitation falls more than
/// earlier_burst_margin_db further (a short pulse of the drive, or a burst that ends in a step out
/// of the band, leaves only a stub of decay after it; the decay before it is the measurement).
void preferEarlierBurst(const std::vector<double>& t, const Levels& lv,
                        const RingdownWindowOptions& o, const std::vector<Candidate>& earlier,
                        RingdownWindow* w, std::ostringstream* why) {
  const std::vector<double>& sm = lv.sm;
  // From step_half samples in: the smoothed level at a step still holds the level before it.
  const double last_fall = fallDb(sm, w->first + o.step_half, w->last);
  const Candidate* best = nullptr;
  double best_fall = last_fall + o.earlier_burst_margin_db;
  for (const Candidate& c : earlier) {
    const double f = fallDb(sm, c.first + o.step_half, c.last);
    if (f > best_fall) best = &c, best_fall = f;
  }
  if (best) {
    const size_t last_first = w->first;
    w->first = best->first;
    w->last = best->last;
    why->str(best->why);
    why->seekp(0, std::ios_base::end);
    *why << (why->tellp() > 0 ? "; " : "") << "the ring-down before the drive came on again "
         << "falls " << best_fall << " dB, the last one (from " << t[last_first] << " s) "
         << last_fall << " dB: the record is read from " << t[w->first] << " s up to "
         << t[w->last - 1] << " s";
  }
}

/// Step 6: a noiseless tail: from some sample to the window's end the local roughness (median
/// |second difference| over 2 roughness_half + 1 samples) stays under tail_roughness_db,
/// tail_below_peak_db or more below the peak, over a tail_divisor-th of the window at least, while
/// as many samples before it are tail_roughness_ratio times rougher. No instrument records that
/// after a measured decay; exports append it (a fitted or padded curve).
void cutNoiselessTail(const std::vector<double>& t, const Levels& lv,
                      const RingdownWindowOptions& o, RingdownWindow* w, std::ostringstream* why) {
  const std::vector<double>& y_db = lv.y_db;
  const std::vector<double>& sm = lv.sm;
  const size_t n = sm.size();
  std::vector<double> e2(n, std::numeric_limits<double>::quiet_NaN()), rough(n, 0.0);
  for (size_t i = 1; i + 1 < n; ++i) e2[i] = std::fabs(y_db[i + 1] - 2.0 * y_db[i] + y_db[i - 1]);
  for (size_t i = 0; i < n; ++i)
    rough[i] = medianOf(e2, long(i) - o.roughness_half, long(i) + o.roughness_half + 1);
  size_t k = w->last;
  while (k > std::max(w->first, lv.i_peak) + 1 &&
         (!std::isfinite(rough[k - 1]) || rough[k - 1] <= o.tail_roughness_db))
    --k;
  const size_t tenth = std::max<size_t>(o.min_tail_samples, (w->last - w->first) / o.tail_divisor);
  const double inside = medianOf(rough, k, w->last);
  const double before = medianOf(rough, long(k) - long(tenth), k);
  if (w->last - k >= tenth && k > tenth && std::isfinite(sm[k]) &&
      sm[k] < lv.top - o.tail_below_peak_db && before >= o.tail_roughness_ratio * inside) {
    *why << (why->tellp() > 0 ? "; " : "") << "from " << t[k] << " s the level is noiseless "
         << "(roughness " << inside << " dB against " << before << " dB before it: a curve the "
         << "export appended, not a measurement): the record is read up to there";
    w->last = k;
  }
}

/// Step 5: a long plateau (over plateau_fraction of what follows the switch-off) is cut to that
/// fraction before it: the segmentation reads the drive level from the window's head, and a long
/// plateau that wanders or creeps over the drive-off threshold hides the switch-off.
void cutLongPlateau(const std::vector<double>& t, const Levels& lv, const RingdownWindowOptions& o,
                    RingdownWindow* w, std::ostringstream* why) {
  const std::vector<double>& sm = lv.sm;
  size_t i_off = w->first;
  for (size_t i = w->first; i < w->last; ++i)
    if (std::isfinite(sm[i]) && sm[i] >= lv.top - o.off_below_db) i_off = i;
  const size_t keep = static_cast<size_t>(o.plateau_fraction * double(w->last - i_off));
  if (i_off > w->first + std::max<size_t>(keep, o.min_plateau_samples)) {
    w->first = i_off - std::max<size_t>(keep, o.min_plateau_samples);
    *why << (why->tellp() > 0 ? "; " : "") << "the drive level is last held at " << t[i_off]
         << " s: read from " << t[w->first] << " s";
  }
}

}  // namespace

RingdownWindow findRingdownWindow(const std::vector<double>& t, const std::vector<double>& y,
                                  const RingdownWindowOptions& o) {
  const size_t n = y.size();
  RingdownWindow w;
  w.last = n;
  if (n < o.min_record_samples || t.size() != n) return w;
  const Levels lv = readLevels(y, o);
  if (!std::isfinite(lv.top)) return w;
  std::ostringstream why;
  why.precision(4);
  // 3. A record that starts under the drive level.
  const bool started_under = readStartUnderDrive(t, lv, o, &w, &why);
  // 2 and 4. Steps after the peak. Each time the drive comes on again the ring-down so far is
  // kept as a candidate (2b below).
  const std::vector<Candidate> earlier = readSteps(t, lv, o, &w, &why);
  // 2b. The last ring-down unless an earlier one falls further.
  preferEarlierBurst(t, lv, o, earlier, &w, &why);
  // 6. A noiseless tail appended by the export.
  cutNoiselessTail(t, lv, o, &w, &why);
  // 5. A long plateau, only in a record that started under the drive level: on the generator's
  // beats the envelope comes back within off_below_db of the peak after the switch-off, and the
  // cut took the plateau and the first beats (base 99530119: 3 of 20 beats without a floor).
  if (w.last > w.first && started_under) cutLongPlateau(t, lv, o, &w, &why);
  // A window too short to hold a ring-down (a min_window_divisor-th of the record,
  // min_window_samples samples) is no window.
  if (w.last < w.first + std::max<size_t>(o.min_window_samples, n / o.min_window_divisor))
    w.first = 0, w.last = n, why.str("");
  w.why = why.str();
  return w;
}

}  // namespace cvg_bench

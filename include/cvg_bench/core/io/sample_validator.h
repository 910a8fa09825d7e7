// Screening of raw f, g samples for the uniform (FIR) demodulator. Each problem is rejected and
// COUNTED by reason (SampleCounters, what the ROS node publishes in its diagnostics; rate-limiting
// of log messages is the node's job). Nothing is ever silently bridged with a phase error: the
// reference phase is omega * t of each accepted sample's own timestamp.
//
// With dt = 1 / sample_rate_hz and d = t - t_last (t_last = last accepted timestamp), tol =
// interval_tolerance * dt, a sample is:
//   non_finite            t, f or g NaN/Inf                                   -> dropped
//   out_of_range          |f| or |g| > max_abs_signal (a corrupted sample)    -> dropped, and the
//                         next accepted sample RESTARTS the filter (state cleared)
//   duplicate_timestamp   |d| <= tol                                          -> dropped
//   non_monotonic         -gap_periods * dt <= d < -tol (out-of-order sample) -> dropped
//   backward jump         d < -gap_periods * dt (bag loop, clock reset)       -> RESET, kept
//   accepted              |d - dt| <= tol
//   missing samples       |d - m dt| <= tol, 2 <= m <= gap_periods            -> m-1 samples are
//                         filled from the current envelope (see Demodulator), counted
//   gap                   d > gap_periods * dt                                -> RESTART, kept
//   off_grid              any other d (timestamp not on the sampling grid)    -> dropped
// A batch of >= 8 samples in which fewer than half of the intervals between consecutive samples
// are within tol of dt is rejected whole as a sample-rate mismatch (configured rate wrong, or the
// data are irregular and belong to the windowed least-squares path). An empty batch is counted.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace cvg_bench {

/// Counts by reason since construction (or resetCounters()).
struct SampleCounters {
  uint64_t accepted = 0;               ///< samples passed to the filter
  uint64_t non_finite = 0;             ///< t, f or g NaN/Inf
  uint64_t out_of_range = 0;           ///< |f| or |g| above max_abs_signal
  uint64_t duplicate_timestamp = 0;    ///< same timestamp as the previous accepted sample
  uint64_t non_monotonic = 0;          ///< small step back in time (out-of-order sample)
  uint64_t off_grid = 0;               ///< interval not a whole number of sample periods
  uint64_t missing_filled = 0;         ///< missing samples filled from the envelope
  uint64_t gaps = 0;                   ///< intervals longer than gap_periods: filter restarted
  uint64_t backward_resets = 0;        ///< large jumps back in time: demodulator reset
  uint64_t rate_mismatch_batches = 0;  ///< batches rejected for a sample-rate mismatch
  uint64_t rate_mismatch_samples = 0;  ///< samples in those batches
  uint64_t empty_batches = 0;          ///< push() calls with no samples
  uint64_t restarts = 0;  ///< filter restarts of any cause (gap, reset, fill impossible)

  /// Total samples dropped (not passed to the filter).
  uint64_t rejected() const {
    return non_finite + out_of_range + duplicate_timestamp + non_monotonic + off_grid +
           rate_mismatch_samples;
  }
  /// name -> count, for diagnostics.
  std::map<std::string, uint64_t> asMap() const;
};

struct SampleValidatorOptions {
  /// Nominal (configured) sample rate [Hz], > 0.
  double sample_rate_hz = 0.0;
  /// Timestamp tolerance as a fraction of the sample period, (0, 0.5). The uniform path assumes
  /// timestamps on the grid within this tolerance (phase error <= omega * tol / rate).
  double interval_tolerance = 0.01;
  /// k: an interval longer than k sample periods is a gap (filter restart); a backward jump by
  /// more than k periods resets the demodulator. >= 2.
  double gap_periods = 10.0;
  /// Largest accepted |f|, |g| [signal units]; a larger sample is a corrupted one (> 0).
  double max_abs_signal = 1e30;

  std::vector<std::string> validate() const;
};

/// What happens before an accepted run of samples.
enum class RunStart {
  kContinue,      ///< the run continues the previous accepted sample on the grid
  kFillMissing,   ///< `missing` samples are absent between the previous accepted sample and it
  kRestartFirst,  ///< first sample since construction/reset
  kRestartGap,    ///< after a gap longer than gap_periods
  kRestartBad,    ///< after a dropped out-of-range sample: the filter state is cleared
  kResetBackward  ///< after a large jump back in time
};

/// A run of consecutive accepted samples [begin, end) of a batch (all on-grid intervals inside).
struct AcceptedRun {
  size_t begin = 0, end = 0;
  RunStart start = RunStart::kContinue;
  int missing = 0;          ///< for kFillMissing: samples absent before `begin`
  double previous_t = 0.0;  ///< timestamp of the previous accepted sample (kFillMissing)
};

class SampleValidator {
 public:
  /// InputError listing every problem of options.validate().
  explicit SampleValidator(const SampleValidatorOptions& options);

  /// Classifies a batch (timestamps t, signals f, g of length n) and updates the counters and the
  /// last accepted timestamp. Returns the accepted runs in order; empty for an empty or rejected
  /// batch. The caller counts missing_filled / restarts (it knows whether a fill was possible).
  std::vector<AcceptedRun> screen(const double* t, const double* f, const double* g, size_t n);

  /// Forget the last accepted timestamp (the next sample starts anew); counters are kept.
  void reset();
  const SampleCounters& counters() const { return counters_; }
  SampleCounters& counters() { return counters_; }
  void resetCounters() { counters_ = SampleCounters(); }
  const SampleValidatorOptions& options() const { return options_; }
  bool hasLast() const { return has_last_; }
  double lastTime() const { return last_t_; }

 private:
  bool restart_pending_ = false;  ///< an out-of-range sample was dropped since the last run
  SampleValidatorOptions options_;
  double dt_, tol_;
  SampleCounters counters_;
  bool has_last_ = false;
  double last_t_ = 0.0;
};

}  // namespace cvg_bench

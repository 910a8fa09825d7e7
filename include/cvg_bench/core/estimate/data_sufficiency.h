// Refuses records that cannot carry the answer, before any fit: exact rank alone does not see them,
// because measurement noise makes every regressor matrix full rank (docs/paper.md, (2.7) and
// (3.4)).
//
// Free decay (section 2): enough samples for the model's parameters; a decay signal above the
// noise in the record as a whole and in each coordinate pair (q1, p1) of f and (q2, p2) of g (the
// noise is the robust scale of the second differences, which the slow decay leaves untouched).
// Forced sweep (section 3): enough points, at three or more distinct excitation frequencies: the
// stationary equations (3.4) separate the detuning terms from the controls only across frequencies.
#pragma once

#include <string>

#include "cvg_bench/core/io/records.h"

namespace cvg_bench {

/// Required signal-to-noise power ratio of a coordinate pair (amplitude RMS 3x the noise RMS).
constexpr double kMinSignalToNoisePower = 9.0;
/// Required distinct excitation frequencies of a sweep.
constexpr int kMinDistinctFrequencies = 3;

struct DataSufficiency {
  bool sufficient = true;
  std::string reason;  ///< empty when sufficient; else what is missing, with the figures
  double snr_f = 0.0;  ///< free decay: signal/noise power of (q1, p1)
  double snr_g = 0.0;  ///< free decay: signal/noise power of (q2, p2)
  /// Free decay with one silent coordinate pair: only the f-g coupling terms are undetermined; the
  /// estimate goes ahead and its identifiability analysis (collinearity.h) reports them as not
  /// identified with the combinations the record does determine (Q from the envelope).
  bool coupling_only = false;
};

/// n_params: parameters of the model to be fitted (residual degrees of freedom must reach it).
DataSufficiency assessFreeDecay(const SlowRecord& record, int n_params);
DataSufficiency assessSweep(const SweepRecord& record, int n_params);

/// Throws AnalysisError with the reason when the record is insufficient (not for coupling_only).
void requireSufficientData(const SlowRecord& record, int n_params);
void requireSufficientData(const SweepRecord& record, int n_params);

}  // namespace cvg_bench

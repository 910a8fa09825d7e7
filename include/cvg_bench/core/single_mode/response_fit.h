// Output-error fit of one mode's stationary response over every drive level and both sweep
// directions at once (docs/response.md): Ceres on the branch-following model of response_model.h,
// started from per-drive-level Lorentzians (variable projection over f0 and width); intervals from
// a jackknife over whole sweeps (residuals along a sweep are correlated) or, with fewer than 5
// sweeps, a sandwich with a Bartlett kernel within each sweep.
#pragma once

#include <complex>
#include <map>
#include <string>
#include <vector>

#include "cvg_bench/core/io/response_record.h"
#include "cvg_bench/core/single_mode/one_mode_value.h"
#include "cvg_bench/core/single_mode/response_model.h"

namespace cvg_bench {

struct ResponseFitOptions {
  ResponseKind kind = ResponseKind::kDisplacement;
  double confidence = 0.95;
  bool intervals = true;  ///< false: point estimate only (no jackknife refits)
  /// Also refit with a free drive factor per level (ResponseFit::rss_free_level_gains).
  bool level_gain_check = false;
  int min_sweeps_for_jackknife = 5;
  /// Relative singular value (column-scaled Jacobian) under which a direction counts as not
  /// determined by the data.
  double rank_tolerance = 1e-9;
  /// Refuse a fit whose width interval reaches zero (requireResponseResonance). explain's
  /// candidate fits turn it off and check the selected one only: a rival model's misfit must not
  /// refuse a record the selected model describes.
  bool require_resonance = true;
};

/// A linear Lorentzian fitted to one drive level alone (the initialiser and the adequacy
/// reference).
struct ResponseLevelFit {
  double drive = 0.0, f0_hz = 0.0, width_hz = 0.0, peak_u = 0.0, rss = 0.0;
  int n_points = 0;
};

struct ResponseFit {
  ResponseTerms terms;
  ResponseKind kind = ResponseKind::kDisplacement;
  ResponseParams params;    ///< in the input's units
  bool conjugated = false;  ///< the lock-in's y runs the other way: the fit used x - iy
  std::map<std::string, ResponseValue>
      derived;                              ///< f0_hz, width_hz, Q, backbone..., width_growth...
  std::vector<std::string> not_determined;  ///< what these data cannot determine
  std::string interval_method;
  int interval_dof = 0;  ///< degrees of freedom of the intervals' Student t
  double rss = 0.0;      ///< sum of |Z - model|^2 over the points (input units^2)
  double sigma = 0.0;    ///< sqrt(rss / (2 n - k))
  /// RSS of the same model with a free drive factor per drive level (0 when not computed): how
  /// much the levels' sizes miss the amplitude law.
  double rss_free_level_gains = 0.0;
  int n_points = 0, n_sweeps = 0, n_params = 0, n_drive_levels = 0, jumps = 0;
  double residual_lag1 = 0.0;               ///< lag-1 correlation of the residuals along the sweeps
  std::vector<std::complex<double>> model;  ///< the fitted response per point (file's x + iy)
  std::vector<double> u;                    ///< squared resonant amplitude per point
  std::vector<ResponseLevelFit> levels;
  std::vector<std::string> notes;
  bool converged = false;
};

/// AnalysisError "no resonance determined by these data" when the width's interval reaches zero
/// (noise only, or the mode outside the swept band); needs the intervals.
void requireResponseResonance(const ResponseFit& fit);

/// Points of a record as the fit reads them (sweeps split by splitSweeps).
ResponseData responseDataOf(const ResponseRecord& record, ResponseKind kind);

/// Fits `terms` to `data`. AnalysisError when no resonance can be fitted (e.g. fewer than 8
/// points, no peak in the band).
ResponseFit fitResponse(const ResponseData& data, const ResponseTerms& terms,
                        const ResponseFitOptions& options);

}  // namespace cvg_bench

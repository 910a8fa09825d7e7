// What makes the ellipse grow (issue #25, "the growing ellipse and a named cause for it"): the
// selected model's quadrature rate k' ((5.8), by the chain rule of its averaged equations,
// orbit_rates_chain_rule.h) at a state of the record, split into the shares of its parameter
// groups. A group is the parameters of one term with one meaning (ModelTerm::parameterMeaning: the
// frequency split h_c, h_s; the damping anisotropy b_c, b_s; ...); its share is what k' loses when
// the group is set to 0 (exact for the linear terms, whose k' is linear in them). Shares with a
// delta-method interval each; groups whose shares the record cannot tell apart (|correlation| over
// `merge_correlation`, e.g. n and h_c at 0.9999 on one swing at one azimuth) are reported as their
// sum, so nothing the data cannot determine is named alone.
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/estimate/estimate.h"
#include "cvg_bench/core/estimate/uncertainty/derived_uncertainty.h"

namespace cvg_bench {

/// One group's share of the model's d|k|/dt [amplitude/s] (positive: the ellipse widens).
struct QuadratureShare {
  std::vector<std::string> parameters;  ///< e.g. {"h_c", "h_s"}; a merged group holds several
  std::string meaning;                  ///< e.g. "frequency split"; merged: joined by " + "
  ParameterEstimate widening;           ///< its share of d|k|/dt with the parameters' interval
  bool determined = false;              ///< the interval excludes 0
};

struct QuadratureGrowthOptions {
  /// Shares whose delta-method correlation exceeds this in magnitude are merged: one record
  /// cannot apportion k' between them (their sum is what it determines). Set by hand, for the
  /// case it is made for: the Florence record's n, h_c pair correlates at 0.99987.
  double merge_correlation = 0.99;
};

struct QuadratureGrowth {
  bool valid = false;
  std::string why_not;
  double r = 0.0, k = 0.0, theta_rad = 0.0;  ///< the state it is evaluated at
  ParameterEstimate measured_widening;       ///< the record's d|k|/dt (sign(k) k'), given
  ParameterEstimate predicted_widening;      ///< the model's d|k|/dt at the state
  std::vector<QuadratureShare> shares;       ///< largest |share| first
  /// The determined shares that carry the widening (same sign as the model's), largest first,
  /// as meanings; empty when none is determined alone.
  std::vector<std::string> named;
  std::string summary;  ///< one sentence for the text report
};

/// The model's k' split into shares at (r, k, theta); `measured_k_rate` [amplitude/s] is the
/// record's measured k' (orbit_reading.h), compared in the summary. Invalid (why_not) without a
/// covariance or at a travelling wave (r = |k|).
QuadratureGrowth explainQuadratureGrowth(const UncertainParameters& params, double r, double k,
                                         double theta_rad, const ParameterEstimate& measured_k_rate,
                                         const QuadratureGrowthOptions& options = {});

}  // namespace cvg_bench

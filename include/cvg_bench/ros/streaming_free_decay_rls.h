// Continuous block recursive least squares (2.12) over a stream of slow states, as the identifier
// node runs it in `rls` mode: every new sample completes one block of (2.8) (samples i-1, i, i+1,
// from the core's forEachFreeDecayBlock), the first blocks are accumulated in the core's
// IncrementalQr until they determine every parameter (initialisation by (2.9)), then each block is
// one BlockRecursiveLeastSquares update. Only the core's estimators are called; this class only
// feeds them. Intervals: the paper's sigma-hat^2 P with Student-t (2.11) (docs/paper.md item 10:
// too wide for free decay; the batch `identify` service gives the honest ones).
#pragma once

#include <Eigen/Core>
#include <deque>
#include <string>

#include "cvg_bench/core/estimate/estimate.h"
#include "cvg_bench/core/estimate/identification.h"
#include "cvg_bench/core/estimate/least_squares_solver.h"
#include "cvg_bench/core/estimate/recursive_least_squares.h"
#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {

class StreamingFreeDecayRls {
 public:
  /// options.model must not contain time-varying terms (cm_rate): InputError.
  explicit StreamingFreeDecayRls(const IdentificationOptions& options);

  /// Adds a sample at t_s [s, any origin, strictly increasing: InputError otherwise].
  void add(double t_s, const Eigen::Vector4d& q);
  void reset();

  bool initialized() const { return rls_.initialized(); }
  long numBlocks() const { return blocks_; }
  /// The running estimate (values, paper intervals, sigma, dof); AnalysisError before
  /// initialisation. omega_rad_s > 0 fills the derived quantities.
  Estimate estimate(double omega_rad_s) const;

 private:
  IdentificationOptions options_;
  ResonatorModel model_;
  IncrementalQr qr_;
  BlockRecursiveLeastSquares rls_;
  SlowRecord last3_;
  long blocks_ = 0;
  int init_blocks_ = 0;
};

}  // namespace cvg_bench

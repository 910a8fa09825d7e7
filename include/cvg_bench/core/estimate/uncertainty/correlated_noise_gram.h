// The errors-in-variables meat of the free-decay regression (2.7)-(2.8) when the noise on the slow
// samples is serially correlated (docs/paper.md item 10 assumes it white): with eps_m the noise of
// sample m (the same correlation rho_l on each of q1, p1, q2, p2 between samples l apart, channels
// independent), D' Omega D = sigma_q^2 sum_{m,m'} rho_|m-m'| W_m W_m' with the per-sample
// sensitivities W_m of free_decay_noise_propagation.h.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "cvg_bench/core/estimate/least_squares_solver.h"

namespace cvg_bench {

/// rho_l of the noise on one slow variable: AR(1) (rho_l = ar1^l) when ar1 != 0, else the finite
/// list lags = rho_1 .. rho_L (a demodulator's, demodulator_noise.h), 0 beyond.
struct NoiseCorrelation {
  std::vector<double> lags;
  double ar1 = 0.0;
  double at(int lag) const;
  bool white() const;
  std::string describe() const;  ///< e.g. "AR(1) rho = 0.9" or "rho_1 = 0.41, 6 lags"
};

class CorrelatedSensitivityGram {
 public:
  CorrelatedSensitivityGram(int k, NoiseCorrelation rho);
  /// W_m' (4 x k) of the next sample in time order; first: it starts a record.
  void add(const RegressionBlockMatrix& w_t, bool first);
  /// sum_{m,m'} rho_|m-m'| W_m W_m' (k x k).
  Eigen::MatrixXd sum() const;

 private:
  int k_;
  NoiseCorrelation rho_;
  Eigen::MatrixXd s_;
  Eigen::MatrixXd filtered_;           // AR(1): F_m = W_m' + rho F_{m-1} (4 x k)
  std::vector<Eigen::MatrixXd> ring_;  // finite lags: the last L W_m'
  long in_record_ = 0;
};

}  // namespace cvg_bench

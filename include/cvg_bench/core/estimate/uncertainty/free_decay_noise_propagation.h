// The honest covariance of the free-decay regression (2.7)-(2.8) (docs/paper.md item 10):
// neighbouring equations share samples, and the noisy samples enter both y and D-bar. Linearized in
// white sample noise eps_m (covariance sigma_q^2 I), the equation errors are
//   e_i = sum_m A_im eps_m,  A_i,i+1 = 2 I - w_i,i+1 G_i+1,  A_i,i = -w_ii G_i,
//   A_i,i-1 = -2 I - w_i,i-1 G_i-1,  G = d(D(q) z)/dq (ResonatorModel::regressorJacobian),
// w the quadrature weights of D-bar_i, so D' Omega D = sigma_q^2 sum_m W_m W_m' with
// W_m = sum_i D-bar_i' A_im (telescopes: small inside a record, O(1) at its ends). Per sample,
// W_m' = U_m - G_m' V_m with U_m = 2 (D-bar_{m-1} - D-bar_{m+1}) and V_m = sum_i w_im D-bar_i, so
// G_m is evaluated once per sample; ||s I - w G||_F^2 = 4 s^2 - 2 s w tr G + w^2 ||G||_F^2 gives
// the noise gain sum ||A_im||_F^2 that turns the residual sum of squares into sigma_q^2.
#pragma once

#include <Eigen/Core>
#include <functional>

#include "cvg_bench/core/estimate/free_decay_regression.h"
#include "cvg_bench/core/estimate/internal/block_gram_accumulator.h"

namespace cvg_bench {

class FreeDecayNoisePropagation {
 public:
  /// z: the estimate at which G is evaluated (its size = model.numParameters()).
  FreeDecayNoisePropagation(const ResonatorModel& model, const Eigen::VectorXd& z);
  /// The blocks of forEachValidatedFreeDecayBlock, in order, record after record.
  void add(const RegressionBlock& b);
  /// sum_m W_m W_m' (k x k) over the samples of all complete records.
  Eigen::MatrixXd sensitivityGram() { return gram_.sum(); }
  /// sum over equations i and samples m of ||A_im||_F^2.
  double noiseGain() const { return noise_gain_; }
  /// Called with W_m' (4 x k) of every finished sample in time order; first: the record's first
  /// (for correlated noise, correlated_noise_gram.h).
  using SampleSink = std::function<void(const RegressionBlockMatrix&, bool first)>;
  void setSampleSink(SampleSink sink) { sink_ = std::move(sink); }

 private:
  /// U_m, V_m (4 x k, column-major) and the sums of s^2, s w, w^2 over the sample's blocks.
  struct SampleTerms {
    double u[4 * kMaxModelParameters], v[4 * kMaxModelParameters];
    double s2 = 0.0, sw = 0.0, w2 = 0.0;
  };
  void clear(SampleTerms& a);
  void finish(SampleTerms& a, const Eigen::Vector4d& q, double t);

  const ResonatorModel& model_;
  Eigen::VectorXd z_;
  int k_;
  SampleTerms terms_[3];  // slots by sample index mod 3
  long in_record_ = 0;
  BlockGramAccumulator gram_;
  RegressionBlockMatrix w_;  // W_m' of the sample being finished
  SlowContext ctx_;
  double noise_gain_ = 0.0;
  SampleSink sink_;
  bool next_first_ = true;
};

}  // namespace cvg_bench

#include "cvg_bench/core/estimate/uncertainty/free_decay_noise_propagation.h"

#include <cstring>
#include <string>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/internal/simd_vector4.h"

namespace cvg_bench {
namespace {

using simd::load4;
using simd::store4;
using simd::V4;

/// Block i's D-bar_i (columns of 4) into the terms of samples i-1 (u -= 2 D, v += w0 D),
/// i (v += w1 D) and i+1 (u = 2 D, v = w2 D: its first block).
CVG_HOT_CLONES
void foldBlock(const double* d, int k, double w0, double w1, double w2, double* prev_u,
               double* prev_v, double* mid_v, double* next_u, double* next_v) {
  for (int c = 0; c < 4 * k; c += 4) {
    const V4 dc = load4(d + c);
    store4(prev_u + c, load4(prev_u + c) - 2.0 * dc);
    store4(prev_v + c, load4(prev_v + c) + w0 * dc);
    store4(mid_v + c, load4(mid_v + c) + w1 * dc);
    store4(next_u + c, 2.0 * dc);
    store4(next_v + c, w2 * dc);
  }
}

/// W' = U - G' V column by column; gt = G' column-major (gt + 4 r = row r of G).
CVG_HOT_CLONES
void sensitivityColumns(const double* u, const double* v, const double* gt, int k, double* w) {
  const V4 g0 = load4(gt), g1 = load4(gt + 4), g2 = load4(gt + 8), g3 = load4(gt + 12);
  for (int c = 0; c < 4 * k; c += 4) {
    const V4 x = load4(u + c) - v[c] * g0 - v[c + 1] * g1 - v[c + 2] * g2 - v[c + 3] * g3;
    store4(w + c, x);
  }
}

}  // namespace

FreeDecayNoisePropagation::FreeDecayNoisePropagation(const ResonatorModel& model,
                                                     const Eigen::VectorXd& z)
    : model_(model),
      z_(z),
      k_(model.numParameters()),
      gram_(model.numParameters()),
      w_(4, model.numParameters()) {
  if (z.size() != k_)
    throw InputError("noise propagation: " + std::to_string(z.size()) + " values for " +
                     std::to_string(k_) + " parameters");
}

void FreeDecayNoisePropagation::clear(SampleTerms& a) {
  std::memset(a.u, 0, sizeof(double) * 4 * k_);
  std::memset(a.v, 0, sizeof(double) * 4 * k_);
  a.s2 = a.sw = a.w2 = 0.0;
}

// Sample complete: G at (q, t), W_m' into the Gram sum, its share of sum ||A_im||^2.
void FreeDecayNoisePropagation::finish(SampleTerms& a, const Eigen::Vector4d& q, double t) {
  ctx_.t_s = t;
  Eigen::Matrix4d g;
  model_.regressorJacobian(q, ctx_, z_, g);
  const Eigen::Matrix4d gt = g.transpose();
  sensitivityColumns(a.u, a.v, gt.data(), k_, w_.data());
  gram_.add(w_);
  if (sink_) sink_(w_, next_first_);
  next_first_ = false;
  noise_gain_ += 4.0 * a.s2 - 2.0 * a.sw * g.trace() + a.w2 * g.squaredNorm();
}

void FreeDecayNoisePropagation::add(const RegressionBlock& b) {
  // Block i = in_record_ + 1 of the record uses samples i-1, i, i+1.
  SampleTerms& prev = terms_[in_record_ % 3];
  SampleTerms& mid = terms_[(in_record_ + 1) % 3];
  SampleTerms& next = terms_[(in_record_ + 2) % 3];
  if (in_record_ == 0) {  // samples 0 and 1 of the record start here
    clear(prev);
    clear(mid);
  }
  const double w0 = b.weights[0], w1 = b.weights[1], w2 = b.weights[2];
  foldBlock(b.d->data(), k_, w0, w1, w2, prev.u, prev.v, mid.v, next.u, next.v);
  prev.s2 += 4.0;
  prev.sw -= 2.0 * w0;
  prev.w2 += w0 * w0;
  mid.w2 += w1 * w1;
  next.s2 = 4.0;
  next.sw = 2.0 * w2;
  next.w2 = w2 * w2;
  finish(prev, b.q_prev, b.t_prev);  // sample i-1 appears in no later block
  ++in_record_;
  if (b.last_in_record) {
    finish(mid, b.q, b.abscissa);
    finish(next, b.q_next, b.t_next);
    in_record_ = 0;
    next_first_ = true;
  }
}

}  // namespace cvg_bench

#include "cvg_bench/core/estimate/internal/block_gram_accumulator.h"

#include <cstring>
#include <string>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/internal/simd_vector4.h"

namespace cvg_bench {
namespace {

using simd::load4;
using simd::store4;
using simd::V4;

constexpr int kBatchBlocks = 64;

/// partial(i, j) += sum_s X_s(:, i) .* X_s(:, j) over 2 x 2 tiles of the lower triangle (tiles on
/// the diagonal also fill one upper entry, which is never read).
CVG_HOT_CLONES
void accumulateTiles(const double* batch, int blocks, int kpad, double* partial) {
  for (int jt = 0; jt < kpad; jt += 2) {
    for (int it = jt; it < kpad; it += 2) {
      V4 a00 = {0.0, 0.0, 0.0, 0.0}, a10 = a00, a01 = a00, a11 = a00;
      for (int s = 0; s < blocks; ++s) {
        const double* xs = batch + static_cast<long>(s) * kpad * 4;
        const V4 xi0 = load4(xs + 4 * it), xi1 = load4(xs + 4 * (it + 1));
        const V4 xj0 = load4(xs + 4 * jt), xj1 = load4(xs + 4 * (jt + 1));
        a00 += xi0 * xj0;
        a10 += xi1 * xj0;
        a01 += xi0 * xj1;
        a11 += xi1 * xj1;
      }
      const V4* sums[4] = {&a00, &a10, &a01, &a11};
      const int rows[4] = {it, it + 1, it, it + 1}, cols[4] = {jt, jt, jt + 1, jt + 1};
      for (int t = 0; t < 4; ++t) {
        double* p = partial + (static_cast<long>(rows[t]) * kpad + cols[t]) * 4;
        store4(p, load4(p) + *sums[t]);
      }
    }
  }
}

}  // namespace

BlockGramAccumulator::BlockGramAccumulator(int k) : k_(k), kpad_(k + (k % 2)) {
  if (k < 1 || k > kMaxModelParameters)
    throw InputError("Gram accumulator: 1.." + std::to_string(kMaxModelParameters) +
                     " columns, got " + std::to_string(k));
  batch_.assign(static_cast<size_t>(kBatchBlocks) * kpad_ * 4, 0.0);
  partial_.assign(static_cast<size_t>(kpad_) * kpad_ * 4, 0.0);
}

void BlockGramAccumulator::add(const RegressionBlockMatrix& x) {
  // The padding column stays zero (written once by the constructor).
  std::memcpy(batch_.data() + static_cast<size_t>(in_batch_) * kpad_ * 4, x.data(),
              sizeof(double) * 4 * k_);
  if (++in_batch_ == kBatchBlocks) flush();
}

void BlockGramAccumulator::flush() {
  if (in_batch_ == 0) return;
  accumulateTiles(batch_.data(), in_batch_, kpad_, partial_.data());
  in_batch_ = 0;
}

Eigen::MatrixXd BlockGramAccumulator::sum() {
  flush();
  Eigen::MatrixXd s(k_, k_);
  for (int j = 0; j < k_; ++j) {
    for (int i = j; i < k_; ++i) {
      const double* p = partial_.data() + (static_cast<size_t>(i) * kpad_ + j) * 4;
      s(i, j) = s(j, i) = (p[0] + p[1]) + (p[2] + p[3]);
    }
  }
  return s;
}

}  // namespace cvg_bench

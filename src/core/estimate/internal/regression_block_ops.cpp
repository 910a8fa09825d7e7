#include "cvg_bench/core/estimate/internal/regression_block_ops.h"

#include <cstring>

#include "cvg_bench/core/estimate/internal/simd_vector4.h"

namespace cvg_bench {
namespace {

using simd::load4;
using simd::store4;
using simd::V4;

CVG_HOT_CLONES
void weightedSum3(double w0, const double* a, double w1, const double* b, double w2,
                  const double* c, int n, double* out) {
  for (int i = 0; i < n; i += 4) {
    store4(out + i, w0 * load4(a + i) + w1 * load4(b + i) + w2 * load4(c + i));
  }
}

CVG_HOT_CLONES
void residual(const double* d, const double* z, int k, const double* y, double* r) {
  V4 acc0 = load4(y), acc1 = {0.0, 0.0, 0.0, 0.0};
  int c = 0;
  for (; c + 1 < k; c += 2) {  // two chains
    acc0 -= z[c] * load4(d + 4 * c);
    acc1 -= z[c + 1] * load4(d + 4 * (c + 1));
  }
  if (c < k) acc0 -= z[c] * load4(d + 4 * c);
  store4(r, acc0 + acc1);
}

}  // namespace

void weightedBlockSum(double w0, const RegressionBlockMatrix& a, double w1,
                      const RegressionBlockMatrix& b, double w2, const RegressionBlockMatrix& c,
                      RegressionBlockMatrix& out) {
  weightedSum3(w0, a.data(), w1, b.data(), w2, c.data(), static_cast<int>(4 * a.cols()),
               out.data());
}

Eigen::Vector4d blockResidual(const RegressionBlockMatrix& d, const Eigen::VectorXd& z,
                              const Eigen::Vector4d& y) {
  Eigen::Vector4d r;
  residual(d.data(), z.data(), static_cast<int>(d.cols()), y.data(), r.data());
  return r;
}

}  // namespace cvg_bench

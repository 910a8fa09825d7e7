#include "cvg_bench/core/householder_panel_update.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "cvg_bench/core/simd_vector4.h"

namespace cvg_bench {
namespace {

using simd::load4;
using simd::V4;

constexpr int kPanel = 4;

__attribute__((always_inline)) inline void store4(double* p, const V4& v) {
  std::memcpy(p, &v, sizeof(v));
}
__attribute__((always_inline)) inline double sum4(const V4& v) {
  return (v[0] + v[1]) + (v[2] + v[3]);
}

__attribute__((always_inline)) inline double dot(const double* x, const double* y, int rows4) {
  V4 acc = {0.0, 0.0, 0.0, 0.0};
  for (int r = 0; r < rows4; r += 4) acc += load4(x + r) * load4(y + r);
  return sum4(acc);
}

/// P reflectors (vectors a[0..P) in B, scalars v0, beta) applied to the columns [c_begin, c_end).
template <int P>
__attribute__((always_inline)) inline void applyPanel(const double* const* a, const double* v0,
                                                      const double* beta,
                                                      const double (*gram)[kPanel], double* r,
                                                      int ldr, int row0, double* b, int ldb,
                                                      int rows4, int c_begin, int c_end) {
  for (int c = c_begin; c < c_end; ++c) {
    double* bc = b + static_cast<long>(c) * ldb;
    V4 acc[P];
    for (int i = 0; i < P; ++i) acc[i] = V4{0.0, 0.0, 0.0, 0.0};
    for (int k = 0; k < rows4; k += 4) {
      const V4 x = load4(bc + k);
      for (int i = 0; i < P; ++i) acc[i] += load4(a[i] + k) * x;
    }
    double s[P];
    double* rc = r + static_cast<long>(c) * ldr + row0;
    for (int i = 0; i < P; ++i) {
      double t = v0[i] * rc[i] + sum4(acc[i]);
      for (int l = 0; l < i; ++l) t -= s[l] * gram[i][l];
      s[i] = beta[i] * t;
      rc[i] -= v0[i] * s[i];
    }
    for (int k = 0; k < rows4; k += 4) {
      V4 x = load4(bc + k);
      for (int i = 0; i < P; ++i) x -= s[i] * load4(a[i] + k);
      store4(bc + k, x);
    }
  }
}

template <int P>
__attribute__((always_inline)) inline void panelStep(double* r, int ldr, double* b, int ldb,
                                                     int rows4, int kk, int j0) {
  const double* a[kPanel];
  double v0[kPanel] = {0.0, 0.0, 0.0, 0.0}, beta[kPanel] = {0.0, 0.0, 0.0, 0.0};
  double gram[kPanel][kPanel] = {};
  for (int i = 0; i < P; ++i) {
    const int j = j0 + i;
    double* aj = b + static_cast<long>(j) * ldb;
    a[i] = aj;
    const double sigma = dot(aj, aj, rows4);
    if (sigma == 0.0) continue;  // nothing to annihilate: identity (beta = 0)
    double& rjj = r[static_cast<long>(j) * ldr + j];
    const double norm = std::sqrt(rjj * rjj + sigma);
    const double alpha = rjj >= 0.0 ? -norm : norm;
    v0[i] = rjj - alpha;
    beta[i] = 2.0 / (v0[i] * v0[i] + sigma);
    rjj = alpha;
    // This reflector on the rest of the panel.
    applyPanel<1>(&a[i], &v0[i], &beta[i], gram, r, ldr, j, b, ldb, rows4, j + 1, j0 + P);
  }
  for (int i = 1; i < P; ++i)
    for (int l = 0; l < i; ++l) gram[i][l] = dot(a[i], a[l], rows4);
  applyPanel<P>(a, v0, beta, gram, r, ldr, j0, b, ldb, rows4, j0 + P, kk);
}

}  // namespace

CVG_HOT_CLONES
void householderPanelUpdate(double* r, int ldr, double* b, int ldb, int rows4, int kk) {
  for (int j0 = 0; j0 < kk; j0 += kPanel) {
    switch (std::min(kPanel, kk - j0)) {
      case 4:
        panelStep<4>(r, ldr, b, ldb, rows4, kk, j0);
        break;
      case 3:
        panelStep<3>(r, ldr, b, ldb, rows4, kk, j0);
        break;
      case 2:
        panelStep<2>(r, ldr, b, ldb, rows4, kk, j0);
        break;
      default:
        panelStep<1>(r, ldr, b, ldb, rows4, kk, j0);
        break;
    }
  }
}

}  // namespace cvg_bench

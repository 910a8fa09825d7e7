#include "cvg_bench/core/estimate/internal/householder_panel_update.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "cvg_bench/core/estimate/internal/simd_vector4.h"

namespace cvg_bench {
namespace {

using simd::load4;
using simd::store4;
using simd::V4;

constexpr int kPanel = 4;

__attribute__((always_inline)) inline double sum4(const V4& v) {
  return (v[0] + v[1]) + (v[2] + v[3]);
}

__attribute__((always_inline)) inline double dot(const double* x, const double* y, int rows4) {
  V4 acc = {0.0, 0.0, 0.0, 0.0};
  for (int r = 0; r < rows4; r += 4) acc += load4(x + r) * load4(y + r);
  return sum4(acc);
}

/// P reflectors (vectors a[0..P) in B, scalars v0, beta) applied to NC adjacent columns from c
/// (two columns share the loads of the reflector vectors).
template <int P, int NC>
__attribute__((always_inline)) inline void applyToColumns(const double* const* a, const double* v0,
                                                          const double* beta,
                                                          const double (*gram)[kPanel], double* r,
                                                          int ldr, int row0, double* b, int ldb,
                                                          int rows4, int c) {
  double* bc[NC];
  V4 acc[NC][P];
  for (int n = 0; n < NC; ++n) {
    bc[n] = b + static_cast<long>(c + n) * ldb;
    for (int i = 0; i < P; ++i) acc[n][i] = V4{0.0, 0.0, 0.0, 0.0};
  }
  for (int k = 0; k < rows4; k += 4) {
    V4 x[NC];
    for (int n = 0; n < NC; ++n) x[n] = load4(bc[n] + k);
    for (int i = 0; i < P; ++i) {
      const V4 ai = load4(a[i] + k);
      for (int n = 0; n < NC; ++n) acc[n][i] += ai * x[n];
    }
  }
  double s[NC][P];
  for (int n = 0; n < NC; ++n) {
    double* rc = r + static_cast<long>(c + n) * ldr + row0;
    for (int i = 0; i < P; ++i) {
      double t = v0[i] * rc[i] + sum4(acc[n][i]);
      for (int l = 0; l < i; ++l) t -= s[n][l] * gram[i][l];
      s[n][i] = beta[i] * t;
      rc[i] -= v0[i] * s[n][i];
    }
  }
  for (int k = 0; k < rows4; k += 4) {
    V4 x[NC];
    for (int n = 0; n < NC; ++n) x[n] = load4(bc[n] + k);
    for (int i = 0; i < P; ++i) {
      const V4 ai = load4(a[i] + k);
      for (int n = 0; n < NC; ++n) x[n] -= s[n][i] * ai;
    }
    for (int n = 0; n < NC; ++n) store4(bc[n] + k, x[n]);
  }
}

/// The P reflectors applied to the columns [c_begin, c_end).
template <int P>
__attribute__((always_inline)) inline void applyPanel(const double* const* a, const double* v0,
                                                      const double* beta,
                                                      const double (*gram)[kPanel], double* r,
                                                      int ldr, int row0, double* b, int ldb,
                                                      int rows4, int c_begin, int c_end) {
  int c = c_begin;
  for (; c + 2 <= c_end; c += 2)
    applyToColumns<P, 2>(a, v0, beta, gram, r, ldr, row0, b, ldb, rows4, c);
  if (c < c_end) applyToColumns<P, 1>(a, v0, beta, gram, r, ldr, row0, b, ldb, rows4, c);
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

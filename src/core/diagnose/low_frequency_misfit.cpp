#include "cvg_bench/core/diagnose/low_frequency_misfit.h"

#include <Eigen/Dense>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "cvg_bench/core/common/number_text.h"
#include "cvg_bench/core/diagnose/model_diagnosis.h"
#include "cvg_bench/core/diagnose/parallel_tasks.h"
#include "cvg_bench/core/estimate/least_squares_solver.h"
#include "cvg_bench/core/estimate/uncertainty/fitted_residual_ar1.h"

namespace cvg_bench {
namespace {

/// Legendre polynomials P_0..P_K of s = 2 (t - t_0) / T - 1 (Bonnet's recurrence).
Eigen::MatrixXd legendreBasis(const std::vector<double>& t, int degree) {
  const long n = static_cast<long>(t.size());
  Eigen::MatrixXd b(n, degree + 1);
  const double t0 = t.front(), span = t.back() - t.front();
  for (long i = 0; i < n; ++i) {
    const double s = span > 0.0 ? 2.0 * (t[i] - t0) / span - 1.0 : 0.0;
    b(i, 0) = 1.0;
    if (degree >= 1) b(i, 1) = s;
    for (int k = 1; k < degree; ++k)
      b(i, k + 1) = ((2.0 * k + 1.0) * s * b(i, k) - k * b(i, k - 1)) / (k + 1.0);
  }
  return b;
}

/// Prais-Winsten AR(1) whitening of row i: w_0 = sqrt(1 - rho^2) x_0, w_i = x_i - rho x_{i-1}.
template <typename Row>
auto praisWinstenRow(const Row& x, long i, double rho) {
  return i == 0 ? (std::sqrt(1.0 - rho * rho) * x(0)).eval() : (x(i) - rho * x(i - 1)).eval();
}

/// Least squares of y on the columns of b, both Prais-Winsten whitened at rho (rho = 0: as they
/// are), row by row: the factor of [b | y] folded in chunks (IncrementalQr), the coefficients by
/// the column-pivoted QR of its triangle, the residual sum by a second pass; nothing of size n is
/// copied. Returns the coefficients; *rss0 = |y_w|^2, *rss1 = |y_w - b_w coef|^2, *rank.
Eigen::VectorXd whitenedLeastSquares(const Eigen::MatrixXd& b, const Eigen::VectorXd& y, double rho,
                                     double* rss0, double* rss1, int* rank) {
  const long n = b.rows(), k = b.cols();
  auto brow = [&](long i) { return b.row(i); };
  auto yval = [&](long i) { return Eigen::Matrix<double, 1, 1>(y[i]); };
  IncrementalQr qr(static_cast<int>(k));
  constexpr long kChunk = 4096;
  Eigen::MatrixXd a(kChunk, k);
  Eigen::VectorXd v(kChunk);
  double ss = 0.0;
  for (long r0 = 0; r0 < n; r0 += kChunk) {
    const long len = std::min(kChunk, n - r0);
    for (long i = 0; i < len; ++i) {
      a.row(i) = praisWinstenRow(brow, r0 + i, rho);
      v[i] = praisWinstenRow(yval, r0 + i, rho)(0);
      ss += v[i] * v[i];
    }
    qr.addRows(a.topRows(len), v.head(len));
  }
  const Eigen::MatrixXd& ra = qr.rAug();
  const Eigen::MatrixXd r = ra.topLeftCorner(k, k).triangularView<Eigen::Upper>();
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> small(r);
  const Eigen::VectorXd coef = small.solve(Eigen::VectorXd(ra.col(k).head(k)));
  double res = 0.0;
  for (long i = 0; i < n; ++i) {
    const double e = praisWinstenRow(yval, i, rho)(0) - praisWinstenRow(brow, i, rho).dot(coef);
    res += e * e;
  }
  *rss0 = ss;
  *rss1 = res;
  *rank = static_cast<int>(small.rank());
  return coef;
}

Eigen::VectorXd knownWhitened(const Eigen::VectorXd& x, const ResidualNoiseModel& known) {
  return known.ar.empty() ? x : whiten(x, 1, known);
}

}  // namespace

double lowFrequencyPValue(const std::vector<double>& x, const std::vector<double>& t,
                          const ResidualNoiseModel& known, const LowFrequencyOptions& options,
                          double* rho_used, bool* capped) {
  const int k = std::min(12, std::max(1, options.degree)) + 1;
  const long n = static_cast<long>(x.size());
  if (rho_used) *rho_used = 0.0;
  if (capped) *capped = false;
  if (n < 4 * k || static_cast<long>(t.size()) != n) return 1.0;
  Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(x.data(), n);
  Eigen::MatrixXd b = legendreBasis(t, k - 1);
  y = knownWhitened(y, known);
  for (int j = 0; j < k; ++j) b.col(j) = knownWhitened(b.col(j), known);
  // The first p filtered values lack their full past (not whitened): conditional on them.
  const long skip = static_cast<long>(known.ar.size());
  if (n - skip < 4 * k) return 1.0;
  if (skip > 0) {
    y = y.tail(n - skip).eval();
    b = b.bottomRows(n - skip).eval();
  }
  // AR(1) of what the smooth basis leaves (Yule-Walker lag-1 correlation).
  double rss0 = 0.0, rss1 = 0.0;
  int rank = 0;
  const Eigen::VectorXd coef = whitenedLeastSquares(b, y, 0.0, &rss0, &rss1, &rank);
  const long m = y.size();
  double c0 = 0.0, c1 = 0.0, previous = 0.0;
  for (long i = 0; i < m; ++i) {
    const double u = y[i] - b.row(i).dot(coef);
    c0 += u * u;
    if (i > 0) c1 += u * previous;
    previous = u;
  }
  double rho = c0 > 0.0 ? c1 / c0 : 0.0;
  // Removing the smooth part removes slow noise too: the lag-1 correlation of u understates
  // rho; corrected by its expectation under that projection (fitted_residual_ar1.h).
  const Eigen::MatrixXd gram_inv =
      (b.transpose() * b).completeOrthogonalDecomposition().pseudoInverse();
  rho = std::max(-0.5, fittedResidualAr1(b, gram_inv, 1, rho));
  if (rho > options.rho_ceiling) {
    rho = options.rho_ceiling;
    if (capped) *capped = true;
  }
  if (rho_used) *rho_used = rho;
  whitenedLeastSquares(b, y, rho, &rss0, &rss1, &rank);
  if (!(rss1 > 0.0) || rank < 1 || m - rank < 1) return rss0 > 0.0 ? 0.0 : 1.0;
  const double f = ((rss0 - rss1) / rank) / (rss1 / static_cast<double>(m - rank));
  return fUpperTail(f, rank, static_cast<int>(m - rank));
}

LowFrequencyMisfitTest lowFrequencyMisfit(const std::vector<BlockResidual>& blocks,
                                          const ResidualNoiseModel& known,
                                          const LowFrequencyOptions& options) {
  LowFrequencyMisfitTest r;
  const char* names[6] = {"radial", "tangential", "q1", "p1", "q2", "p2"};
  std::vector<std::vector<double>> seq(6);
  std::vector<double> t;
  for (const auto& b : blocks) {
    if (!std::isfinite(b.abscissa)) continue;
    t.push_back(b.abscissa);
    seq[0].push_back(b.radial);
    seq[1].push_back(b.tangential);
    for (int c = 0; c < 4; ++c) seq[2 + c].push_back(b.e[c]);
  }
  // The sequences are independent: tested several at a time, combined in their order.
  double ps[6], rhos[6];
  bool cappeds[6];
  runTasks(6, options.threads, [&](size_t s) {
    rhos[s] = 0.0;
    cappeds[s] = false;
    ps[s] = lowFrequencyPValue(seq[s], t, known, options, &rhos[s], &cappeds[s]);
  });
  double best = 1.0;
  for (int s = 0; s < 6; ++s) {
    const double rho = rhos[s];
    const bool capped = cappeds[s];
    const double p = ps[s];
    r.rho_max = std::max(r.rho_max, rho);
    r.rho_capped = r.rho_capped || capped;
    if (p < best || r.worst.empty()) {
      best = std::min(best, p);
      r.worst = std::string(names[s]) + ": p = " + numberText(p, 3) + " (AR(1) rho " +
                numberText(rho, 3) + (capped ? ", capped" : "") + ")";
    }
  }
  r.p_value = std::min(1.0, 6.0 * best);
  std::ostringstream d;
  d << "GLS F-test of Legendre P_0..P_" << options.degree
    << " in time on the trajectory residuals (radial, tangential, 4 components; Bonferroni over "
       "6), noise "
    << (known.ar.empty() ? "" : "the record's known correlation, then ")
    << "AR(1) fitted after the smooth part is removed (rho <= "
    << numberText(options.rho_ceiling, 3) << ")";
  r.description = d.str();
  return r;
}

}  // namespace cvg_bench

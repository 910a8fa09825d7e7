#include "cvg_bench/core/diagnose/low_frequency_misfit.h"

#include <Eigen/Dense>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "cvg_bench/core/diagnose/model_diagnosis.h"
#include "cvg_bench/core/estimate/fitted_residual_ar1.h"

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

/// Prais-Winsten AR(1) whitening: w_0 = sqrt(1 - rho^2) x_0, w_t = x_t - rho x_{t-1}.
Eigen::MatrixXd praisWinsten(const Eigen::MatrixXd& x, double rho) {
  Eigen::MatrixXd w(x.rows(), x.cols());
  if (x.rows() == 0) return w;
  w.row(0) = std::sqrt(1.0 - rho * rho) * x.row(0);
  for (long i = 1; i < x.rows(); ++i) w.row(i) = x.row(i) - rho * x.row(i - 1);
  return w;
}

Eigen::VectorXd knownWhitened(const Eigen::VectorXd& x, const ResidualNoiseModel& known) {
  return known.ar.empty() ? x : whiten(x, 1, known);
}

std::string num(double v) {
  std::ostringstream s;
  s.precision(3);
  s << v;
  return s.str();
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
  y = y.tail(n - skip).eval();
  b = b.bottomRows(n - skip).eval();
  // AR(1) of what the smooth basis leaves (Yule-Walker lag-1 correlation).
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(b);
  const Eigen::VectorXd u = y - b * qr.solve(y);
  const long m = y.size();
  const double c0 = u.squaredNorm();
  double rho = c0 > 0.0 ? u.head(m - 1).dot(u.tail(m - 1)) / c0 : 0.0;
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
  const Eigen::VectorXd w = praisWinsten(y, rho);
  const Eigen::MatrixXd wb = praisWinsten(b, rho);
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> wqr(wb);
  const double rss0 = w.squaredNorm();
  const double rss1 = (w - wb * wqr.solve(w)).squaredNorm();
  const int rank = static_cast<int>(wqr.rank());
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
  double best = 1.0;
  for (int s = 0; s < 6; ++s) {
    double rho = 0.0;
    bool capped = false;
    const double p = lowFrequencyPValue(seq[s], t, known, options, &rho, &capped);
    r.rho_max = std::max(r.rho_max, rho);
    r.rho_capped = r.rho_capped || capped;
    if (p < best || r.worst.empty()) {
      best = std::min(best, p);
      r.worst = std::string(names[s]) + ": p = " + num(p) + " (AR(1) rho " + num(rho) +
                (capped ? ", capped" : "") + ")";
    }
  }
  r.p_value = std::min(1.0, 6.0 * best);
  std::ostringstream d;
  d << "GLS F-test of Legendre P_0..P_" << options.degree
    << " in time on the trajectory residuals (radial, tangential, 4 components; Bonferroni over "
       "6), noise "
    << (known.ar.empty() ? "" : "the record's known correlation, then ")
    << "AR(1) fitted after the smooth part is removed (rho <= " << num(options.rho_ceiling) << ")";
  r.description = d.str();
  return r;
}

}  // namespace cvg_bench

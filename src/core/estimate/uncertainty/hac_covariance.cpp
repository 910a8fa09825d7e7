#include "cvg_bench/core/estimate/uncertainty/hac_covariance.h"

#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <string>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/least_squares_solver.h"

namespace cvg_bench {
namespace {

constexpr double kRankTolerance = 1e-10;  // relative singular-value cut of the equilibrated J
// Andrews' AR(1) plug-in diverges as rho -> 1; beyond this the fitted rho is capped (his advice),
// and the VAR(1) prewhitening's singular values too so that I - A stays invertible (Andrews and
// Monahan 1992). A numerical clamp from the literature, not a threshold tuned here: it stays a
// constant (the HAC functions take no options struct).
constexpr double kMaxPluginRho = 0.97;
constexpr long kChunkRows = 4096;  // window sums folded into the meat per GEMM

void checkInput(const Eigen::MatrixXd& j, const Eigen::VectorXd& e, int block_size) {
  if (block_size < 1) throw InputError("HAC covariance: block size must be >= 1");
  if (j.rows() != e.size())
    throw InputError("HAC covariance: " + std::to_string(j.rows()) + " Jacobian rows but " +
                     std::to_string(e.size()) + " residuals");
  if (j.rows() % block_size != 0)
    throw InputError("HAC covariance: " + std::to_string(j.rows()) +
                     " rows are not a multiple of the block size " + std::to_string(block_size));
  if (j.cols() < 1 || j.rows() <= j.cols())
    throw InputError("HAC covariance: needs more rows than the " + std::to_string(j.cols()) +
                     " parameters, got " + std::to_string(j.rows()));
  if (j.rows() / block_size < 2) throw InputError("HAC covariance: needs at least 2 time steps");
  if (!j.allFinite() || !e.allFinite())
    throw InputError("HAC covariance: non-finite Jacobian or residuals");
}

/// h_t = sum over the rows of block t of (J r_pinv)' e: the scores in the coordinates where the
/// bread is the identity (J r_pinv = Q of J = QR at full rank), nb x p.
Eigen::MatrixXd blockScores(const Eigen::MatrixXd& j, const Eigen::MatrixXd& r_pinv,
                            const Eigen::VectorXd& e, int block_size) {
  const Eigen::MatrixXd weighted = e.asDiagonal() * (j * r_pinv);
  if (block_size == 1) return weighted;
  const long nb = j.rows() / block_size;
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(nb, j.cols());
  for (long t = 0; t < nb; ++t)
    h.row(t) = weighted.middleRows(t * block_size, block_size).colwise().sum();
  return h;
}

/// Andrews (1991) eq. (6.4): AR(1) fitted to each score column, unit weights; bandwidth
/// S_T = 1.1447 (alpha(1) T)^(1/3) for the Bartlett kernel.
double andrewsBandwidth(const Eigen::MatrixXd& h) {
  const long n = h.rows();
  double num = 0.0, den = 0.0;
  for (Eigen::Index a = 0; a < h.cols(); ++a) {
    const auto lagged = h.col(a).head(n - 1);
    const auto current = h.col(a).tail(n - 1);
    const double sxx = lagged.squaredNorm();
    if (!(sxx > 0.0)) continue;
    const double rho = std::clamp(current.dot(lagged) / sxx, -kMaxPluginRho, kMaxPluginRho);
    const double s2 = (current - rho * lagged).squaredNorm() / static_cast<double>(n - 1);
    num += 4.0 * rho * rho * s2 * s2 / (std::pow(1.0 - rho, 6) * std::pow(1.0 + rho, 2));
    den += s2 * s2 / std::pow(1.0 - rho, 4);
  }
  const double alpha = den > 0.0 ? num / den : 0.0;
  return 1.1447 * std::cbrt(alpha * static_cast<double>(n));
}

/// sum_{|l| <= lag} (1 - |l| / (lag + 1)) Gamma_l. The Bartlett window is a box convolved with
/// itself, so the sum equals (1 / (lag + 1)) sum_t B_t B_t' over all (partial) window sums
/// B_t = h_t + ... + h_{t+lag}, t = -lag .. nb - 1: O(nb p^2) whatever the lag.
Eigen::MatrixXd bartlettLongRunCovariance(const Eigen::MatrixXd& h, int lag) {
  const long nb = h.rows();
  const Eigen::Index p = h.cols();
  Eigen::MatrixXd prefix(nb + 1, p);  // prefix.row(t) = h_0 + ... + h_{t-1}
  prefix.row(0).setZero();
  for (long t = 0; t < nb; ++t) prefix.row(t + 1) = prefix.row(t) + h.row(t);
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(p, p);
  Eigen::MatrixXd windows(kChunkRows, p);
  long filled = 0;
  const auto fold = [&]() {
    meat.selfadjointView<Eigen::Lower>().rankUpdate(windows.topRows(filled).transpose());
    filled = 0;
  };
  for (long t = -lag; t < nb; ++t) {
    windows.row(filled++) = prefix.row(std::min(t + lag + 1, nb)) - prefix.row(std::max(t, 0L));
    if (filled == kChunkRows) fold();
  }
  fold();
  meat.triangularView<Eigen::StrictlyUpper>() = meat.transpose();
  return meat / static_cast<double>(lag + 1);
}

/// Andrews-Monahan (1992) prewhitening: VAR(1) h_t = A h_{t-1} + u_t fitted by QR, singular
/// values of A capped at kMaxPluginRho so that I - A stays invertible. Returns A (p x p).
Eigen::MatrixXd fitVar1(const Eigen::MatrixXd& h) {
  const long n = h.rows();
  const Eigen::MatrixXd a_t = h.topRows(n - 1).colPivHouseholderQr().solve(h.bottomRows(n - 1));
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a_t.transpose(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd capped = svd.singularValues().cwiseMin(kMaxPluginRho);
  return svd.matrixU() * capped.asDiagonal() * svd.matrixV().transpose();
}

/// Long-run covariance of the scores. Lag given: plain Newey-West on h. Lag chosen: prewhitened
/// (u_t = h_t - A h_{t-1}), Andrews' lag for u, recoloured (I - A)^-1 S_u (I - A)^-T; under
/// AR(1) rho = 0.9 this lifts 95% coverage from ~0.92 to ~0.95 at n = 2000 (hac_covariance_test).
Eigen::MatrixXd longRunCovariance(const Eigen::MatrixXd& h, int given_lag, long max_lag,
                                  int* lag_used) {
  if (given_lag >= 0) {
    *lag_used = static_cast<int>(std::min<long>(given_lag, max_lag));
    return bartlettLongRunCovariance(h, *lag_used);
  }
  const long n = h.rows();
  const Eigen::MatrixXd a = fitVar1(h);
  const Eigen::MatrixXd u = h.bottomRows(n - 1) - h.topRows(n - 1) * a.transpose();
  const long chosen = static_cast<long>(std::ceil(andrewsBandwidth(u))) - 1;
  *lag_used = static_cast<int>(std::clamp(chosen, 0L, std::min(max_lag, n - 2)));
  const Eigen::MatrixXd recolor =
      (Eigen::MatrixXd::Identity(a.rows(), a.cols()) - a).partialPivLu().inverse();
  return recolor * bartlettLongRunCovariance(u, *lag_used) * recolor.transpose();
}

double residualCorrelation(const Eigen::VectorXd& e, int shift) {
  const long n = e.size();
  const double s = e.squaredNorm();
  if (!(s > 0.0) || n <= shift) return 0.0;
  return e.tail(n - shift).dot(e.head(n - shift)) / s;
}

}  // namespace

HacCovariance hacCovarianceBlocked(const Eigen::MatrixXd& jacobian,
                                   const Eigen::VectorXd& residuals, int block_size, int lag) {
  checkInput(jacobian, residuals, block_size);
  const long n = jacobian.rows();
  const long nb = n / block_size;
  const LeastSquaresSolution ls = solveLeastSquares(jacobian, residuals, kRankTolerance);
  const Eigen::MatrixXd h = blockScores(jacobian, ls.r_pinv, residuals, block_size);

  HacCovariance out;
  const Eigen::MatrixXd meat = longRunCovariance(h, lag, nb - 1, &out.lag);
  const double small_sample = static_cast<double>(n) / static_cast<double>(n - ls.rank);
  out.covariance = small_sample * ls.r_pinv * meat * ls.r_pinv.transpose();
  out.rho1 = residualCorrelation(residuals, block_size);

  const double sigma2 = residuals.squaredNorm() / static_cast<double>(n - ls.rank);
  double ratio_sum = 0.0;
  int counted = 0;
  for (Eigen::Index i = 0; i < jacobian.cols(); ++i) {
    const double iid = sigma2 * ls.unscaled_covariance(i, i);
    if (iid > 0.0) {
      ratio_sum += out.covariance(i, i) / iid;
      ++counted;
    }
  }
  out.variance_inflation = counted > 0 ? ratio_sum / counted : 1.0;
  out.method = "HAC Newey-West, Bartlett, lag " + std::to_string(out.lag) +
               (lag < 0 ? " (Andrews AR(1)) after VAR(1) prewhitening" : " (given)");
  if (block_size > 1)
    out.method += ", blocks of " + std::to_string(block_size) + " rows per time step";
  return out;
}

HacCovariance hacCovarianceFromScores(const Eigen::MatrixXd& scores, const Eigen::MatrixXd& r_pinv,
                                      long n_rows, int rank, int lag) {
  const long nb = scores.rows();
  if (nb < 3 || scores.cols() != r_pinv.rows() || r_pinv.rows() != r_pinv.cols() || n_rows <= rank)
    throw InputError("HAC covariance: " + std::to_string(nb) + " score rows of " +
                     std::to_string(scores.cols()) + " for a " + std::to_string(r_pinv.rows()) +
                     "-parameter factor and " + std::to_string(n_rows) + " rows");
  if (!scores.allFinite()) throw InputError("HAC covariance: non-finite scores");
  HacCovariance out;
  const Eigen::MatrixXd h = scores * r_pinv;  // h_t = r_pinv' g_t: unit bread coordinates
  const Eigen::MatrixXd meat = longRunCovariance(h, lag, nb - 1, &out.lag);
  const double small_sample = static_cast<double>(n_rows) / static_cast<double>(n_rows - rank);
  out.covariance = small_sample * r_pinv * meat * r_pinv.transpose();
  out.method = "HAC Newey-West, Bartlett, lag " + std::to_string(out.lag) +
               (lag < 0 ? " (Andrews AR(1)) after VAR(1) prewhitening" : " (given)") +
               " of the per-step scores";
  return out;
}

HacCovariance hacCovariance(const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& residuals,
                            int lag) {
  return hacCovarianceBlocked(jacobian, residuals, 1, lag);
}

}  // namespace cvg_bench

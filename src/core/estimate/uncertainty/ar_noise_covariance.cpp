#include "cvg_bench/core/estimate/uncertainty/ar_noise_covariance.h"

#include <Eigen/Dense>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <sstream>

namespace cvg_bench {
namespace {

// The tuned settings are ArNoiseOptions' fields (ar_noise_covariance.h); what stays here is
// numerical: the impulse response's length cap and tail, and the repair of a non-stationary fit.

/// A non-stationary block AR fit (arNoiseCovarianceLocal) is shrunk by this factor per round, at
/// most kStationaryShrinkRounds rounds, until its autocorrelation is finite (a numerical repair).
constexpr double kStationaryShrink = 0.9;
constexpr int kStationaryShrinkRounds = 40;

ArNoiseCovariance arNoiseCovarianceModel(const Eigen::MatrixXd& J, const Eigen::VectorXd& r,
                                         const ArNoiseOptions& o);

/// Autocorrelations r_1..r_L of x (mean removed).
std::vector<double> autocorrelation(const Eigen::VectorXd& x, int lags) {
  const Eigen::VectorXd c = x.array() - x.mean();
  const double c0 = c.squaredNorm();
  std::vector<double> r(lags + 1, 0.0);
  r[0] = 1.0;
  if (!(c0 > 0.0)) return r;
  const int n = static_cast<int>(c.size());
  for (int l = 1; l <= lags && l < n; ++l) r[l] = c.head(n - l).dot(c.tail(n - l)) / c0;
  return r;
}

/// AR(p) coefficients of x by least squares (QR of the lagged matrix); innovation variance out.
std::vector<double> fitAr(const Eigen::VectorXd& x, int p, double& innovation_var) {
  const int n = static_cast<int>(x.size());
  if (p == 0) {
    innovation_var = x.squaredNorm() / n;
    return {};
  }
  Eigen::MatrixXd X(n - p, p);
  for (int i = p; i < n; ++i)
    for (int k = 0; k < p; ++k) X(i - p, k) = x(i - 1 - k);
  const Eigen::VectorXd y = x.tail(n - p);
  const Eigen::VectorXd a = X.colPivHouseholderQr().solve(y);
  innovation_var = (y - X * a).squaredNorm() / (n - p);
  return std::vector<double>(a.data(), a.data() + p);
}

/// Autocorrelation rho_0..rho_L of an AR(p) process: from its impulse response (psi weights),
/// rho_l = sum_k psi_k psi_{k+l} / sum_k psi_k^2, summed until psi decays below 1e-9.
std::vector<double> arAutocorrelation(const std::vector<double>& a, int max_lag) {
  const int p = static_cast<int>(a.size());
  std::vector<double> psi{1.0};
  const int cap = 200000;
  while (static_cast<int>(psi.size()) < cap) {
    const int j = static_cast<int>(psi.size());
    double v = 0.0;
    for (int k = 1; k <= p && k <= j; ++k) v += a[k - 1] * psi[j - k];
    psi.push_back(v);
    if (j > 4 * p + 20) {  // stop once the tail is negligible
      double tail = 0.0;
      for (int k = std::max(0, j - p - 4); k <= j; ++k) tail += std::fabs(psi[k]);
      if (tail < 1e-9) break;
    }
  }
  const int m = static_cast<int>(psi.size());
  double s0 = 0.0;
  for (double v : psi) s0 += v * v;
  std::vector<double> rho(max_lag + 1, 0.0);
  for (int l = 0; l <= max_lag && l < m; ++l) {
    double s = 0.0;
    for (int k = 0; k + l < m; ++k) s += psi[k] * psi[k + l];
    rho[l] = s / s0;
  }
  return rho;
}

/// Step 4 of the header: each parameter keeps the larger of its standard errors under `out` and
/// under the cluster sandwich of B contiguous blocks of the scores.
void blockCheck(const Eigen::MatrixXd& J, const Eigen::VectorXd& r, const Eigen::MatrixXd& jtj_inv,
                const ArNoiseOptions& o, ArNoiseCovariance& out) {
  const int n = static_cast<int>(J.rows()), p = static_cast<int>(J.cols());
  const int B = std::min(o.check_blocks, n / o.check_block_min_samples);
  if (B < p + o.check_min_df || out.rank < p) return;
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(p, p);
  for (int b = 0; b < B; ++b) {
    const int lo = b * n / B, hi = (b + 1) * n / B;
    const Eigen::VectorXd s = J.middleRows(lo, hi - lo).transpose() * r.segment(lo, hi - lo);
    meat += s * s.transpose();
  }
  meat *= static_cast<double>(B) / (B - p);
  const Eigen::MatrixXd cb = jtj_inv * meat * jtj_inv;
  Eigen::VectorXd sd(p);
  for (int k = 0; k < p; ++k) {
    const double a = std::sqrt(std::max(0.0, out.covariance(k, k)));
    const double b = std::sqrt(std::max(0.0, cb(k, k)));
    sd(k) = std::max(a, b);
    if (b > a) ++out.blocks_won;
  }
  if (out.blocks_won == 0) return;
  for (int i = 0; i < p; ++i)
    for (int j = 0; j < p; ++j) {
      const double a = std::sqrt(std::max(1e-300, out.covariance(i, i) * out.covariance(j, j)));
      out.covariance(i, j) = (i == j ? 1.0 : out.covariance(i, j) / a) * sd(i) * sd(j);
    }
  out.student_df = std::min(out.student_df, static_cast<double>(B - p));
  std::ostringstream m;
  m << "; block check (cluster sandwich of the scores over " << B << " contiguous blocks, the "
    << "larger std kept per parameter): " << out.blocks_won << " of " << p
    << " parameters from the blocks, Student df " << B - p;
  out.method += m.str();
}

}  // namespace

ArNoiseCovariance arNoiseCovariance(const Eigen::MatrixXd& J, const Eigen::VectorXd& r,
                                    bool block_check, const ArNoiseOptions& options) {
  ArNoiseCovariance out = arNoiseCovarianceModel(J, r, options);
  if (!block_check) return out;
  Eigen::MatrixXd jtj_inv = Eigen::MatrixXd::Zero(J.cols(), J.cols());
  if (out.rank == J.cols()) {
    Eigen::HouseholderQR<Eigen::MatrixXd> hq(J);
    const Eigen::MatrixXd R = hq.matrixQR().topRows(J.cols()).triangularView<Eigen::Upper>();
    const Eigen::MatrixXd Rinv =
        R.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(J.cols(), J.cols()));
    jtj_inv = Rinv * Rinv.transpose();
  }
  blockCheck(J, r, jtj_inv, options, out);
  return out;
}

namespace {

ArNoiseCovariance arNoiseCovarianceModel(const Eigen::MatrixXd& J, const Eigen::VectorXd& r,
                                         const ArNoiseOptions& o) {
  ArNoiseCovariance out;
  const int n = static_cast<int>(J.rows()), p = static_cast<int>(J.cols());
  Eigen::HouseholderQR<Eigen::MatrixXd> hq(J);
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> cq(J);
  out.rank = static_cast<int>(cq.rank());
  // (J'J)^-1 = R^-1 R^-T from the QR (no normal equations); zero when rank-deficient.
  Eigen::MatrixXd Rinv = Eigen::MatrixXd::Zero(p, p);
  if (out.rank == p) {
    const Eigen::MatrixXd R = hq.matrixQR().topRows(p).triangularView<Eigen::Upper>();
    Rinv = R.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(p, p));
  }
  const Eigen::MatrixXd jtj_inv = Rinv * Rinv.transpose();
  const double sigma2 = r.squaredNorm() / std::max(1, n - p);
  out.crb = sigma2 * jtj_inv;
  out.covariance = out.crb;
  out.effective_n = n;
  out.student_df = n - p;

  const std::vector<double> rc = autocorrelation(r, o.ljung_box_lags);
  out.rho1 = rc[1];
  double q = 0.0;
  for (int l = 1; l <= o.ljung_box_lags && l < n; ++l) q += rc[l] * rc[l] / (n - l);
  q *= n * (n + 2.0);
  out.ljung_box_p = boost::math::cdf(
      boost::math::complement(boost::math::chi_squared(o.ljung_box_lags), std::max(q, 0.0)));
  out.correlated = std::fabs(out.rho1) > o.lag1_band_z / std::sqrt(static_cast<double>(n)) ||
                   out.ljung_box_p < o.ljung_box_level;
  std::ostringstream m;
  m.precision(3);
  if (!out.correlated || n < o.ar_min_samples_per_order * o.max_ar_order + o.ar_min_samples_extra) {
    m << "white-noise (Cramer-Rao) covariance of the weighted ln A residuals: no serial "
         "correlation detected (lag-1 "
      << out.rho1 << ", Ljung-Box p " << out.ljung_box_p << ")";
    out.method = m.str();
    return out;
  }
  // AR order by BIC on a common sample (the first max_ar_order values dropped).
  const Eigen::VectorXd x = r.array() - r.mean();
  const int max_order = o.max_ar_order;
  int best_p = 1;
  double best_bic = std::numeric_limits<double>::infinity();
  for (int k = 1; k <= max_order; ++k) {
    double v = 0.0;
    fitAr(x.tail(n - (max_order - k)), k, v);
    const double bic = (n - max_order) * std::log(std::max(v, 1e-300)) +
                       k * std::log(static_cast<double>(n - max_order));
    if (bic < best_bic) best_bic = bic, best_p = k;
  }
  double innov = 0.0;
  out.ar = fitAr(x, best_p, innov);
  // Stationarity guard: shrink the coefficients until the impulse response decays.
  const int max_lag = std::max(1, n / 2);
  std::vector<double> rho = arAutocorrelation(out.ar, max_lag);
  int L = 0;
  for (int l = 1; l <= max_lag; ++l) {
    if (std::fabs(rho[l]) < o.autocorrelation_cutoff) break;
    L = l;
  }
  double c = 1.0;
  for (int l = 1; l <= L; ++l) c += 2.0 * rho[l];
  bool ar1_fallback = false;
  if (!std::isfinite(c)) {
    // The AR fit degenerated (a residual series with exact repeats): the lag-1 AR model of the
    // sample correlation instead, so the interval is neither of zero width nor NaN.
    const double r1 = std::max(-0.99, std::min(0.99, std::isfinite(out.rho1) ? out.rho1 : 0.0));
    out.ar.assign(1, r1);
    rho.assign(max_lag + 1, 0.0);
    rho[0] = 1.0;
    L = 0;
    for (int l = 1; l <= max_lag && std::fabs(std::pow(r1, l)) >= o.autocorrelation_cutoff; ++l)
      rho[l] = std::pow(r1, l), L = l;
    c = (1.0 + r1) / (1.0 - r1);
    ar1_fallback = true;
  }
  out.long_run_factor = std::max(c, 1.0 / n);
  out.effective_n = n / std::max(out.long_run_factor, 1e-3);
  out.student_df = std::floor(out.effective_n) - p;
  // Meat: sum_{i,j} gamma_|i-j| J_i J_j', gamma_l = var(r) rho_l.
  const double var_r = x.squaredNorm() / std::max(1, n - p);
  Eigen::MatrixXd meat = J.transpose() * J;
  for (int l = 1; l <= L; ++l) {
    const Eigen::MatrixXd g = J.topRows(n - l).transpose() * J.bottomRows(n - l);
    meat += rho[l] * (g + g.transpose());
  }
  out.covariance = var_r * jtj_inv * meat * jtj_inv;
  out.covariance = 0.5 * (out.covariance + out.covariance.transpose());
  if (ar1_fallback) m << "AR(" << best_p << ") fit degenerate, lag-1 correlation used; ";
  m << "AR(" << best_p << ") noise model of the weighted ln A residuals (order by BIC; lag-1 "
    << out.rho1 << ", Ljung-Box p " << out.ljung_box_p << ", long-run variance factor "
    << out.long_run_factor << ", " << L << " lags): sandwich (J'J)^-1 J' Sigma_AR J (J'J)^-1";
  out.method = m.str();
  return out;
}

}  // namespace

ArNoiseCovariance arNoiseCovarianceLocal(const Eigen::MatrixXd& J, const Eigen::VectorXd& r,
                                         int blocks, const ArNoiseOptions& options) {
  ArNoiseCovariance out = arNoiseCovarianceModel(J, r, options);
  const int n = static_cast<int>(J.rows()), p = static_cast<int>(J.cols());
  const int B = std::max(1, std::min(blocks, n / options.local_block_min_samples));
  if (out.rank < p || B < 2) return out;
  // Per block: the variance and the autocorrelation of its own AR(p <= max_ar_order, BIC) model.
  std::vector<double> var(B);
  std::vector<std::vector<double>> rho(B);
  std::vector<int> lo(B + 1);
  for (int b = 0; b <= B; ++b) lo[b] = b * n / B;
  for (int b = 0; b < B; ++b) {
    const int m = lo[b + 1] - lo[b];
    // Not centred: the block mean of slow noise is noise, not an offset to remove.
    const Eigen::VectorXd x = r.segment(lo[b], m);
    var[b] = x.squaredNorm() / m;
    const int kmax = std::min(options.max_ar_order, m / options.local_samples_per_ar_order);
    int best_p = 0;
    double best_bic = std::numeric_limits<double>::infinity();
    for (int k = 0; k <= kmax; ++k) {
      double v = 0.0;
      fitAr(x.tail(m - (kmax - k)), k, v);
      const double bic =
          (m - kmax) * std::log(std::max(v, 1e-300)) + k * std::log(static_cast<double>(m - kmax));
      if (bic < best_bic) best_bic = bic, best_p = k;
    }
    double innov = 0.0;
    std::vector<double> a = fitAr(x, best_p, innov);
    rho[b] = arAutocorrelation(a, m / 2);
    // A least-squares AR fit may come out non-stationary (a step inside the block): shrink the
    // coefficients until its autocorrelation is finite.
    for (int shrink = 0; shrink < kStationaryShrinkRounds; ++shrink) {
      bool finite = true;
      for (double v : rho[b]) finite &= std::isfinite(v);
      if (finite) break;
      for (double& c : a) c *= kStationaryShrink;
      rho[b] = arAutocorrelation(a, m / 2);
    }
    int L = 0;
    for (int l = 1; l < static_cast<int>(rho[b].size()); ++l) {
      if (std::fabs(rho[b][l]) < options.autocorrelation_cutoff) break;
      L = l;
    }
    rho[b].resize(L + 1);
  }
  // Meat sum_b sum_{i,j in b} v_b rho_b(|i - j|) J_i J_j': block-diagonal, each block's
  // covariance that of its own stationary AR model (positive semi-definite, as the sum is); the
  // correlation across a block boundary (a few lags against hundreds of samples) is left out.
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(p, p);
  for (int b = 0; b < B; ++b) {
    const int m = lo[b + 1] - lo[b];
    const auto Jb = J.middleRows(lo[b], m);
    Eigen::MatrixXd mb = Jb.transpose() * Jb;
    for (int l = 1; l < static_cast<int>(rho[b].size()) && l < m; ++l) {
      const Eigen::MatrixXd c = Jb.topRows(m - l).transpose() * Jb.bottomRows(m - l);
      mb += rho[b][l] * (c + c.transpose());
    }
    meat += var[b] * mb;
  }
  Eigen::HouseholderQR<Eigen::MatrixXd> hq(J);
  const Eigen::MatrixXd R = hq.matrixQR().topRows(p).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd Rinv =
      R.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(p, p));
  const Eigen::MatrixXd jtj_inv = Rinv * Rinv.transpose();
  if (!meat.allFinite()) return arNoiseCovarianceModel(J, r, options);
  out.covariance = jtj_inv * meat * jtj_inv;
  out.covariance = 0.5 * (out.covariance + out.covariance.transpose());
  std::ostringstream m;
  m << "AR noise models fitted in " << B
    << " contiguous blocks (variance and correlation may change along the record): sandwich";
  out.method = m.str();
  return out;
}

std::vector<double> arWhiten(const std::vector<double>& ar, const std::vector<double>& e) {
  const int p = static_cast<int>(ar.size()), n = static_cast<int>(e.size());
  std::vector<double> w(n);
  if (p == 0) return e;
  const std::vector<double> rho = arAutocorrelation(ar, p);
  // Durbin-Levinson: phi[k] (order k predictor) and v[k] (its error variance / gamma_0).
  std::vector<std::vector<double>> phi(p);
  std::vector<double> v(p + 1, 1.0);
  for (int k = 1; k < p; ++k) {
    double num = rho[k];
    for (int j = 1; j < k; ++j) num -= phi[k - 1][j - 1] * rho[k - j];
    const double kk = v[k - 1] > 0.0 ? num / v[k - 1] : 0.0;
    phi[k].assign(k, 0.0);
    for (int j = 1; j < k; ++j) phi[k][j - 1] = phi[k - 1][j - 1] - kk * phi[k - 1][k - j - 1];
    phi[k][k - 1] = kk;
    v[k] = v[k - 1] * (1.0 - kk * kk);
  }
  // Innovation variance / gamma_0 of the AR model itself: 1 - sum a_k rho_k.
  double vp = 1.0;
  for (int k = 1; k <= p; ++k) vp -= ar[k - 1] * rho[k];
  vp = std::max(vp, 1e-12);
  for (int i = 0; i < n; ++i) {
    double pred = 0.0, var = vp;
    if (i < p) {
      for (int j = 1; j <= i; ++j) pred += phi[i][j - 1] * e[i - j];
      var = std::max(v[i], vp);
    } else {
      for (int k = 1; k <= p; ++k) pred += ar[k - 1] * e[i - k];
    }
    w[i] = (e[i] - pred) * std::sqrt(vp / var);
  }
  return w;
}

}  // namespace cvg_bench

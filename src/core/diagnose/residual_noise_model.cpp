#include "cvg_bench/core/diagnose/residual_noise_model.h"

#include <Eigen/Dense>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "cvg_bench/core/common/number_text.h"
#include "cvg_bench/core/estimate/uncertainty/fitted_residual_ar1.h"

namespace cvg_bench {
namespace {}  // namespace

ResidualNoiseModel noiseModelFromCorrelation(const std::vector<double>& rho, int max_order) {
  ResidualNoiseModel m;
  const int p = std::min<int>(max_order, static_cast<int>(rho.size()));
  if (p < 1) {
    m.description = "white (no correlation known)";
    return m;
  }
  // Levinson-Durbin on r_0 = 1, r_1..r_p.
  std::vector<double> a(p + 1, 0.0), prev(p + 1, 0.0);
  double err = 1.0;
  int order = 0;
  for (int k = 1; k <= p; ++k) {
    double acc = rho[k - 1];
    for (int j = 1; j < k; ++j) acc -= prev[j] * rho[k - j - 1];
    const double refl = acc / err;
    if (!std::isfinite(refl) || std::abs(refl) >= 1.0) break;
    a[k] = refl;
    for (int j = 1; j < k; ++j) a[j] = prev[j] - refl * prev[k - j];
    err *= (1.0 - refl * refl);
    prev = a;
    order = k;
  }
  m.ar.assign(prev.begin() + 1, prev.begin() + 1 + order);
  m.rho1 = rho[0];
  m.description = "the record's known noise correlation (rho_1 = " + numberText(rho[0], 3) + ", " +
                  std::to_string(rho.size()) + " lags) as AR(" + std::to_string(order) + ")";
  return m;
}

ResidualNoiseModel noiseModelFromResiduals(const Eigen::VectorXd& residuals, int channels,
                                           double min_rho) {
  ResidualNoiseModel m;
  channels = std::max(1, channels);
  const long n = residuals.size() / channels;
  double c0 = 0.0, c1 = 0.0, c2 = 0.0;
  for (int c = 0; c < channels && n > 8; ++c) {
    Eigen::VectorXd x(n);
    for (long i = 0; i < n; ++i) x[i] = residuals[i * channels + c];
    x.array() -= x.mean();
    c0 += x.squaredNorm();
    c1 += x.head(n - 1).dot(x.tail(n - 1));
    c2 += x.head(n - 2).dot(x.tail(n - 2));
  }
  double rho = 0.0;
  if (c0 > 0.0) {
    const double r1 = c1 / c0, r2 = c2 / c0;
    rho = 1.0 - r1 > 1e-9 ? (1.0 - r2) / (1.0 - r1) - 1.0 : 0.98;
    rho = std::min(0.98, std::max(-0.5, rho));
  }
  if (std::abs(rho) < min_rho) {
    m.description = "white (variogram-ratio AR(1) estimate rho = " + numberText(rho, 3) + ")";
    return m;
  }
  m.ar = {rho};
  m.rho1 = rho;
  m.description =
      "AR(1) fitted to the residuals (variogram ratio, rho = " + numberText(rho, 3) + ")";
  return m;
}

ResidualNoiseModel noiseModelFromDetrendedResiduals(const Eigen::VectorXd& residuals, int channels,
                                                    int degree, double ceiling, double min_rho) {
  ResidualNoiseModel m;
  channels = std::max(1, channels);
  const long n = residuals.size() / channels;
  degree = std::max(0, degree);
  double c0 = 0.0, c1 = 0.0;
  if (n > 4 * (degree + 1)) {
    // Legendre P_0..P_degree of the scaled sample index (Bonnet's recurrence).
    Eigen::MatrixXd b(n, degree + 1);
    for (long i = 0; i < n; ++i) {
      const double s = n > 1 ? 2.0 * i / (n - 1.0) - 1.0 : 0.0;
      b(i, 0) = 1.0;
      if (degree >= 1) b(i, 1) = s;
      for (int k = 1; k < degree; ++k)
        b(i, k + 1) = ((2.0 * k + 1.0) * s * b(i, k) - k * b(i, k - 1)) / (k + 1.0);
    }
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(b);
    for (int c = 0; c < channels; ++c) {
      Eigen::VectorXd x(n);
      for (long i = 0; i < n; ++i) x[i] = residuals[i * channels + c];
      x -= b * qr.solve(x);
      c0 += x.squaredNorm();
      c1 += x.head(n - 1).dot(x.tail(n - 1));
    }
  }
  double rho = c0 > 0.0 ? std::max(-0.5, c1 / c0) : 0.0;
  if (c0 > 0.0) {
    // The smooth part takes slow noise with it: lag-1 correlation corrected for the projection.
    Eigen::MatrixXd b(n, degree + 1);
    for (long i = 0; i < n; ++i) {
      const double s = n > 1 ? 2.0 * i / (n - 1.0) - 1.0 : 0.0;
      b(i, 0) = 1.0;
      if (degree >= 1) b(i, 1) = s;
      for (int k = 1; k < degree; ++k)
        b(i, k + 1) = ((2.0 * k + 1.0) * s * b(i, k) - k * b(i, k - 1)) / (k + 1.0);
    }
    const Eigen::MatrixXd gram_inv =
        (b.transpose() * b).completeOrthogonalDecomposition().pseudoInverse();
    rho = std::max(-0.5, fittedResidualAr1(b, gram_inv, 1, rho));
  }
  const bool capped = rho > ceiling;
  rho = std::min(rho, ceiling);
  if (std::abs(rho) < min_rho) {
    m.description = "white (AR(1) of the detrended residuals rho = " + numberText(rho, 3) + ")";
    return m;
  }
  m.ar = {rho};
  m.rho1 = rho;
  m.description = "AR(1) fitted to the residuals after Legendre P_0..P_" + std::to_string(degree) +
                  " in time are removed (rho = " + numberText(rho, 3) +
                  (capped ? ", capped: the fitted value exceeds the ceiling" : "") + ")";
  return m;
}

Eigen::VectorXd whiten(const Eigen::VectorXd& residuals, int channels,
                       const ResidualNoiseModel& model) {
  if (model.ar.empty()) return residuals;
  channels = std::max(1, channels);
  const long n = residuals.size() / channels;
  Eigen::VectorXd w = residuals;
  for (int c = 0; c < channels; ++c) {
    for (long i = 0; i < n; ++i) {
      double v = residuals[i * channels + c];
      for (size_t k = 1; k <= model.ar.size() && static_cast<long>(k) <= i; ++k)
        v -= model.ar[k - 1] * residuals[(i - static_cast<long>(k)) * channels + c];
      w[i * channels + c] = v;
    }
  }
  return w;
}

ResidualNoiseModel withDetrendedAr1(const ResidualNoiseModel& known,
                                    const Eigen::VectorXd& residuals, int channels) {
  const long per_channel = channels > 0 ? residuals.size() / channels : 0;
  if (per_channel < 16) return known;
  const long skip = channels * std::min<long>(static_cast<long>(known.ar.size()), per_channel / 2);
  const Eigen::VectorXd w = whiten(residuals, channels, known).tail(residuals.size() - skip);
  const ResidualNoiseModel extra = noiseModelFromDetrendedResiduals(w, channels);
  if (extra.ar.empty()) return known;
  const double b = extra.ar[0];
  ResidualNoiseModel m = known;
  m.ar.assign(known.ar.size() + 1, 0.0);
  for (size_t j = 0; j < m.ar.size(); ++j) {
    const double a_j = j < known.ar.size() ? known.ar[j] : 0.0;
    const double a_before = j == 0 ? -1.0 : known.ar[j - 1];
    m.ar[j] = a_j - b * a_before;
  }
  m.description = (known.ar.empty() ? std::string("white") : known.description) + "; then " +
                  extra.description + " of what it leaves";
  return m;
}

}  // namespace cvg_bench

#include "cvg_bench/core/demod/frequency_estimator.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <sstream>
#include <unsupported/Eigen/FFT>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace {

/// Largest number of samples per least-squares stage (longer spans are strided).
constexpr size_t kMaxFitSamples = 200000;

struct SineFit {
  double w = 0.0;
  Eigen::Matrix<double, 7, 1> theta;  // W, a_f, b_f, c_f, a_g, b_g, c_g
  double sigma = 0.0, std_w = 0.0;
};

/// Gauss-Newton on samples idx of (t, f, g) from the frequency w0 [rad/s].
SineFit fitSines(const std::vector<double>& t, const std::vector<double>& f,
                 const std::vector<double>& g, const std::vector<size_t>& idx, double w0,
                 int max_iter) {
  const size_t n = idx.size();
  double tmid = 0.0;
  for (size_t i : idx) tmid += t[i];
  tmid /= double(n);
  Eigen::VectorXd tau(n);
  for (size_t k = 0; k < n; ++k) tau[k] = t[idx[k]] - tmid;
  // Linear part for the start frequency.
  Eigen::MatrixXd a(n, 3), rhs(n, 2);
  for (size_t k = 0; k < n; ++k) {
    a(k, 0) = std::cos(w0 * tau[k]);
    a(k, 1) = std::sin(w0 * tau[k]);
    a(k, 2) = 1.0;
    rhs(k, 0) = f[idx[k]];
    rhs(k, 1) = g[idx[k]];
  }
  const Eigen::MatrixXd lin = a.colPivHouseholderQr().solve(rhs);
  SineFit fit;
  fit.theta << w0, lin(0, 0), lin(1, 0), lin(2, 0), lin(0, 1), lin(1, 1), lin(2, 1);
  Eigen::MatrixXd j(2 * n, 7);
  Eigen::VectorXd r(2 * n);
  auto evaluate = [&](const Eigen::Matrix<double, 7, 1>& th) {
    j.setZero();
    for (size_t k = 0; k < n; ++k) {
      const double c = std::cos(th[0] * tau[k]), s = std::sin(th[0] * tau[k]);
      r[k] = th[1] * c + th[2] * s + th[3] - f[idx[k]];
      r[n + k] = th[4] * c + th[5] * s + th[6] - g[idx[k]];
      j(k, 0) = tau[k] * (-th[1] * s + th[2] * c);
      j(k, 1) = c;
      j(k, 2) = s;
      j(k, 3) = 1.0;
      j(n + k, 0) = tau[k] * (-th[4] * s + th[5] * c);
      j(n + k, 4) = c;
      j(n + k, 5) = s;
      j(n + k, 6) = 1.0;
    }
    return r.squaredNorm();
  };
  double cost = evaluate(fit.theta);
  for (int it = 0; it < max_iter; ++it) {
    const Eigen::VectorXd step = j.colPivHouseholderQr().solve(-r);
    // Step halving keeps Gauss-Newton monotone far from the optimum.
    double lambda = 1.0, new_cost = cost;
    Eigen::Matrix<double, 7, 1> trial;
    for (int h = 0; h < 20; ++h, lambda *= 0.5) {
      trial = fit.theta + lambda * step;
      new_cost = evaluate(trial);
      if (new_cost <= cost) break;
    }
    if (!(new_cost <= cost)) {
      evaluate(fit.theta);
      break;
    }
    const double rel = std::abs(trial[0] - fit.theta[0]);
    fit.theta = trial;
    cost = new_cost;
    if (rel <= 1e-13 * std::abs(fit.theta[0])) break;
  }
  cost = evaluate(fit.theta);
  fit.w = fit.theta[0];
  fit.sigma = std::sqrt(cost / double(std::max<size_t>(1, 2 * n - 7)));
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(j);
  if (qr.rank() == 7) {
    const Eigen::MatrixXd rr = qr.matrixR().topLeftCorner(7, 7).triangularView<Eigen::Upper>();
    const Eigen::MatrixXd rinv =
        rr.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(7, 7));
    const Eigen::MatrixXd cov =
        qr.colsPermutation() * (rinv * rinv.transpose()) * qr.colsPermutation().transpose();
    fit.std_w = fit.sigma * std::sqrt(cov(0, 0));
  } else {
    fit.std_w = std::numeric_limits<double>::infinity();
  }
  return fit;
}

}  // namespace

std::vector<std::string> FrequencyEstimatorOptions::validate() const {
  std::vector<std::string> p;
  if (!(min_hz >= 0.0) || !std::isfinite(min_hz)) p.push_back("min_hz must be >= 0");
  if (!(max_hz >= 0.0) || !std::isfinite(max_hz)) p.push_back("max_hz must be >= 0");
  if (max_hz > 0.0 && max_hz <= min_hz) p.push_back("max_hz must be > min_hz");
  if (oversampling < 1 || oversampling > 64) p.push_back("oversampling must be 1..64");
  if (max_fft_samples < 1024) p.push_back("max_fft_samples must be >= 1024");
  if (max_iterations < 1) p.push_back("max_iterations must be >= 1");
  return p;
}

namespace {

/// Throws InputError unless t, f, g are finite, of one length >= 16, with increasing times.
void requireSignal(const std::vector<double>& t, const std::vector<double>& f,
                   const std::vector<double>& g) {
  const size_t n = t.size();
  if (f.size() != n || g.size() != n) throw InputError("frequency estimation: sizes differ");
  if (n < 16) throw InputError("frequency estimation needs at least 16 samples");
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(t[i]) || !std::isfinite(f[i]) || !std::isfinite(g[i]))
      throw InputError("frequency estimation: non-finite value at sample " + std::to_string(i));
    if (i > 0 && !(t[i] > t[i - 1]))
      throw InputError("frequency estimation: timestamps not increasing at sample " +
                       std::to_string(i));
  }
}

/// The record's time scales and the frequency band searched [Hz].
struct SearchBand {
  double dt = 0.0;    ///< median sampling interval [s]
  double span = 0.0;  ///< record length [s]
  double fmin = 0.0, fmax = 0.0;
};

SearchBand searchBand(const std::vector<double>& t, const FrequencyEstimatorOptions& o) {
  const size_t n = t.size();
  std::vector<double> d(n - 1);
  for (size_t i = 1; i < n; ++i) d[i - 1] = t[i] - t[i - 1];
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  SearchBand b;
  b.dt = d[d.size() / 2];
  b.span = t.back() - t.front();
  b.fmin = o.min_hz > 0.0 ? o.min_hz : 3.0 / b.span;
  b.fmax = o.max_hz > 0.0 ? o.max_hz : 0.5 / b.dt;
  if (!(b.fmax > b.fmin)) throw InputError("frequency estimation: record too short for the band");
  return b;
}

struct CoarsePeak {
  double omega_rad_s = 0.0;
  size_t nfft = 0;   ///< FFT length (zero-padded)
  size_t seg_n = 0;  ///< samples of the first segment transformed
};

/// Step 1: the FFT peak of f and g, resampled linearly onto a uniform grid over the first
/// segment, refined by a parabola through the log powers of the peak bin and its neighbours.
CoarsePeak coarsePeak(const std::vector<double>& t, const std::vector<double>& f,
                      const std::vector<double>& g, const SearchBand& band,
                      const FrequencyEstimatorOptions& o) {
  const size_t n = t.size();
  const double dt = band.dt;
  const size_t grid_n = static_cast<size_t>(std::floor(band.span / dt)) + 1;
  CoarsePeak peak;
  peak.seg_n = std::min(grid_n, size_t(o.max_fft_samples / o.oversampling));
  const size_t seg_n = peak.seg_n;
  size_t nfft = 1;
  while (nfft < seg_n * size_t(o.oversampling)) nfft <<= 1;
  peak.nfft = nfft;
  std::vector<double> uf(nfft, 0.0), ug(nfft, 0.0);
  double mf = 0.0, mg = 0.0;
  for (size_t k = 0, i = 0; k < seg_n; ++k) {
    const double tk = t.front() + k * dt;
    while (i + 2 < n && t[i + 1] < tk) ++i;
    const double w = std::clamp((tk - t[i]) / (t[i + 1] - t[i]), 0.0, 1.0);
    uf[k] = f[i] + w * (f[i + 1] - f[i]);
    ug[k] = g[i] + w * (g[i + 1] - g[i]);
    mf += uf[k];
    mg += ug[k];
  }
  for (size_t k = 0; k < seg_n; ++k) {
    uf[k] -= mf / seg_n;
    ug[k] -= mg / seg_n;
  }
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> ff, fg;
  fft.fwd(ff, uf);
  fft.fwd(fg, ug);
  const double df = 1.0 / (nfft * dt);
  const size_t k_lo = std::max<size_t>(1, static_cast<size_t>(std::ceil(band.fmin / df)));
  const size_t k_hi = std::min(nfft / 2 - 1, static_cast<size_t>(std::floor(band.fmax / df)));
  if (k_hi <= k_lo) throw InputError("frequency estimation: no FFT bin in the search band");
  auto power = [&](size_t k) { return std::norm(ff[k]) + std::norm(fg[k]); };
  size_t kp = k_lo;
  for (size_t k = k_lo; k <= k_hi; ++k)
    if (power(k) > power(kp)) kp = k;
  double shift = 0.0;
  if (kp > 0 && kp + 1 < nfft / 2) {
    const double lm = std::log(power(kp - 1) + 1e-300), l0 = std::log(power(kp) + 1e-300),
                 lp = std::log(power(kp + 1) + 1e-300);
    const double den = lm - 2.0 * l0 + lp;
    if (den < 0.0) shift = std::clamp(0.5 * (lm - lp) / den, -0.5, 0.5);
  }
  peak.omega_rad_s = 2.0 * M_PI * (kp + shift) * df;
  return peak;
}

/// Step 2: Gauss-Newton over spans growing 4x from the coarse segment to the whole record
/// (strided to kMaxFitSamples); *stages counts the spans fitted.
SineFit refineFrequency(const std::vector<double>& t, const std::vector<double>& f,
                        const std::vector<double>& g, const SearchBand& band,
                        const CoarsePeak& peak, const FrequencyEstimatorOptions& o, int* stages) {
  double w = peak.omega_rad_s;
  double fit_span = peak.seg_n * band.dt;
  SineFit fit;
  *stages = 0;
  for (;;) {
    fit_span = std::min(fit_span, band.span);
    std::vector<size_t> idx;
    const double t_end = t.front() + fit_span;
    const size_t count = std::upper_bound(t.begin(), t.end(), t_end) - t.begin();
    const size_t stride = std::max<size_t>(1, (count + kMaxFitSamples - 1) / kMaxFitSamples);
    for (size_t i = 0; i < count; i += stride) idx.push_back(i);
    fit = fitSines(t, f, g, idx, w, o.max_iterations);
    ++*stages;
    if (!std::isfinite(fit.w) || fit.w < 2.0 * M_PI * band.fmin * 0.5 ||
        fit.w > 2.0 * M_PI * band.fmax * 2)
      throw AnalysisError("frequency estimation diverged (coarse peak " +
                          std::to_string(peak.omega_rad_s) + " rad/s)");
    w = fit.w;
    if (fit_span >= band.span) break;
    fit_span *= 4.0;
  }
  return fit;
}

}  // namespace

FrequencyEstimate estimateFrequency(const std::vector<double>& t, const std::vector<double>& f,
                                    const std::vector<double>& g,
                                    const FrequencyEstimatorOptions& o) {
  throwIfInvalid("frequency estimator options", o.validate());
  requireSignal(t, f, g);
  const SearchBand band = searchBand(t, o);
  const CoarsePeak peak = coarsePeak(t, f, g, band, o);
  int stages = 0;
  const SineFit fit = refineFrequency(t, f, g, band, peak, o, &stages);

  FrequencyEstimate est;
  est.coarse_rad_s = peak.omega_rad_s;
  est.n_samples = t.size();
  est.omega_rad_s = fit.w;
  est.std_rad_s = fit.std_w;
  est.residual_rms = fit.sigma;
  est.amplitude = std::sqrt(fit.theta[1] * fit.theta[1] + fit.theta[2] * fit.theta[2] +
                            fit.theta[4] * fit.theta[4] + fit.theta[5] * fit.theta[5]);
  std::ostringstream m;
  m.precision(12);
  m << "estimated from the data: FFT peak of f,g (" << peak.nfft << " points, " << peak.seg_n
    << " samples) at " << est.coarse_rad_s << " rad/s, refined by nonlinear least squares of "
    << "common-frequency sinusoids in " << stages << " stage(s) to " << est.omega_rad_s << " +- "
    << est.std_rad_s << " rad/s (1 sigma)";
  est.method = m.str();
  return est;
}

}  // namespace cvg_bench

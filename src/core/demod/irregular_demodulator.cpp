#include "cvg_bench/core/demod/irregular_demodulator.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/demod/demodulator.h"

namespace cvg_bench {

std::vector<std::string> IrregularDemodulatorOptions::validate() const {
  std::vector<std::string> p;
  if (!(omega_rad_s > 0.0) || !std::isfinite(omega_rad_s))
    p.push_back("omega_rad_s (reference frequency) must be finite and > 0");
  if (!(output_rate_hz > 0.0) || !std::isfinite(output_rate_hz))
    p.push_back("output_rate_hz must be finite and > 0");
  if (!(window_s >= 0.0) || !std::isfinite(window_s)) p.push_back("window_s must be >= 0");
  if (min_samples < 0) p.push_back("min_samples must be >= 0 (0 = automatic)");
  if (fit_offset_slope && !fit_offset) p.push_back("fit_offset_slope needs fit_offset");
  if (omega_rad_s > 0.0 && output_rate_hz > 0.0 && window_s >= 0.0) {
    const double w = window_s > 0.0 ? window_s : 2.0 / output_rate_hz;
    if (w * omega_rad_s < 2.0 * M_PI)
      p.push_back("the window must span at least one period 2 pi / omega");
  }
  return p;
}

namespace {

/// The valid samples: non-finite ones and any not strictly after the last kept one are dropped
/// (and counted).
struct ScreenedSamples {
  std::vector<double> t, f, g;
};

ScreenedSamples screenSamples(const RawRecord& raw, SampleCounters* counters) {
  ScreenedSamples out;
  out.t.reserve(raw.size());
  for (size_t i = 0; i < raw.size(); ++i) {
    if (!std::isfinite(raw.t_s[i]) || !std::isfinite(raw.f[i]) || !std::isfinite(raw.g[i])) {
      ++counters->non_finite;
      continue;
    }
    if (!out.t.empty() && raw.t_s[i] <= out.t.back()) {
      ++(raw.t_s[i] == out.t.back() ? counters->duplicate_timestamp : counters->non_monotonic);
      continue;
    }
    out.t.push_back(raw.t_s[i]);
    out.f.push_back(raw.f[i]);
    out.g.push_back(raw.g[i]);
  }
  counters->accepted = out.t.size();
  return out;
}

int numColumns(const IrregularDemodulatorOptions& o) {
  return 2 + (o.fit_envelope_slope ? 2 : 0) + (o.fit_offset ? 1 : 0) + (o.fit_offset_slope ? 1 : 0);
}

/// Design matrix and right-hand sides (f, g) of the window of n samples from i0 centred on tc:
/// columns cos, sin of the reference phase, then the optional envelope slopes, offset and offset
/// slope (tau = (t - tc) / half, normalized for conditioning).
void windowSystem(const ScreenedSamples& x, size_t i0, long n, double tc, double half,
                  const IrregularDemodulatorOptions& o, Eigen::MatrixXd* a, Eigen::MatrixXd* rhs) {
  a->resize(n, numColumns(o));
  rhs->resize(n, 2);
  for (long r = 0; r < n; ++r) {
    const double ti = x.t[i0 + r], tau = (ti - tc) / half;
    const double ph = referencePhase(o.omega_rad_s, ti);
    const double c = std::cos(ph), s = std::sin(ph);
    int j = 0;
    (*a)(r, j++) = c;
    (*a)(r, j++) = s;
    if (o.fit_envelope_slope) {
      (*a)(r, j++) = tau * c;
      (*a)(r, j++) = tau * s;
    }
    if (o.fit_offset) (*a)(r, j++) = 1.0;
    if (o.fit_offset_slope) (*a)(r, j++) = tau;
    (*rhs)(r, 0) = x.f[i0 + r];
    (*rhs)(r, 1) = x.g[i0 + r];
  }
}

/// Solves one window by QR; appends q = (a_f, b_f, a_g, b_g) and its standard errors at tc.
/// False when the window is rank-deficient.
bool solveWindow(const Eigen::MatrixXd& a, const Eigen::MatrixXd& rhs, double tc,
                 IrregularDemodResult* res) {
  const int cols = static_cast<int>(a.cols());
  const long n = a.rows();
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  if (qr.rank() < cols || n <= cols) return false;
  const Eigen::MatrixXd x = qr.solve(rhs);
  const Eigen::Array2d rss = (a * x - rhs).colwise().squaredNorm().array();
  const Eigen::Array2d var = rss / double(n - cols);
  // diag((A^T A)^-1) for the first two columns: A P = Q R -> (A^T A)^-1 = P R^-1 R^-T P^T.
  const Eigen::MatrixXd r = qr.matrixR().topLeftCorner(cols, cols).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd rinv =
      r.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(cols, cols));
  const Eigen::MatrixXd cov_perm = rinv * rinv.transpose();
  const Eigen::MatrixXd cov = qr.colsPermutation() * cov_perm * qr.colsPermutation().transpose();
  res->record.t_s.push_back(tc);
  res->record.q.emplace_back(x(0, 0), x(1, 0), x(0, 1), x(1, 1));
  res->std_error.emplace_back(std::sqrt(var[0] * cov(0, 0)), std::sqrt(var[0] * cov(1, 1)),
                              std::sqrt(var[1] * cov(0, 0)), std::sqrt(var[1] * cov(1, 1)));
  res->n_samples.push_back(static_cast<int>(n));
  return true;
}

}  // namespace

IrregularDemodResult demodulateIrregular(const RawRecord& raw,
                                         const IrregularDemodulatorOptions& o) {
  throwIfInvalid("irregular demodulator options", o.validate());
  if (raw.t_s.size() != raw.f.size() || raw.t_s.size() != raw.g.size())
    throw InputError("raw record: t, f, g sizes differ");
  IrregularDemodResult res;
  const ScreenedSamples x = screenSamples(raw, &res.counters);
  const std::vector<double>& t = x.t;
  const double window = o.window_s > 0.0 ? o.window_s : 2.0 / o.output_rate_hz;
  const int min_samples = o.min_samples > 0 ? o.min_samples : numColumns(o) + 4;
  if (t.size() < 2) throw InputError("raw record " + raw.source + ": fewer than 2 valid samples");
  // One window per output time k / output_rate that fits inside the record.
  const double step = 1.0 / o.output_rate_hz, half = 0.5 * window;
  const long k0 = static_cast<long>(std::ceil((t.front() + half) / step - 1e-9));
  const long k1 = static_cast<long>(std::floor((t.back() - half) / step + 1e-9));
  Eigen::MatrixXd a, rhs(0, 2);
  for (long k = k0; k <= k1; ++k) {
    const double tc = k * step;
    const auto lo = std::lower_bound(t.begin(), t.end(), tc - half);
    const auto hi = std::upper_bound(t.begin(), t.end(), tc + half);
    const long n = hi - lo;
    if (n < min_samples) {
      ++res.n_too_few;
      res.skipped_window_times.push_back(tc);
      continue;
    }
    windowSystem(x, lo - t.begin(), n, tc, half, o, &a, &rhs);
    if (!solveWindow(a, rhs, tc, &res)) {
      ++res.n_rank_deficient;
      res.skipped_window_times.push_back(tc);
    }
  }
  if (res.record.t_s.empty()) {
    std::ostringstream m;
    m << "raw record " << raw.source << ": no demodulation window of " << window << " s has "
      << min_samples << " samples and a full-rank fit (" << res.n_too_few << " too few, "
      << res.n_rank_deficient << " rank-deficient)";
    throw InputError(m.str());
  }
  res.record.omega_rad_s = o.omega_rad_s;
  res.record.source = raw.source;
  res.record.metadata["mode"] = "free_decay";
  std::ostringstream d;
  d.precision(12);
  d << "windowed least squares, reference " << o.omega_rad_s << " rad/s, window " << window
    << " s, output " << o.output_rate_hz << " Hz, " << res.n_too_few + res.n_rank_deficient
    << " windows skipped";
  res.record.metadata["demodulation"] = d.str();
  return res;
}

}  // namespace cvg_bench

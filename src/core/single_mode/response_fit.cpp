// Output-error fit of one mode's response (response_fit.h). The fit runs in normalised units
// (response / its largest magnitude, drive / its largest level) and converts back at the end.
#include "cvg_bench/core/single_mode/response_fit.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/number_text.h"
#include "cvg_bench/core/estimate/dense_solver_options.h"
#include "cvg_bench/core/estimate/uncertainty/student_t.h"
#include "cvg_bench/core/single_mode/response_laws.h"

namespace cvg_bench {
namespace {

using cd = std::complex<double>;

// The fit's tuned thresholds are ResponseFitOptions' fields; what stays here is definitional.

/// Real parameters of the linear model with a background slope (f0, w, gain, bg0, bg1).
constexpr double kSlopeModelParams = 8.0;
/// Median of |e| / sigma for complex Gaussian noise of sigma per component: |e| is Rayleigh,
/// median sigma sqrt(2 ln 2) = 1.17741 sigma (rounded).
constexpr double kMedianAbsPerSigma = 1.1774;
/// Bartlett bandwidth within a sweep of m points: scale (m / points)^exponent point lags, rounded
/// up. The published rule 4 (m/100)^(2/9) of Newey and West (1994, Rev. Econ. Stud. 61, 631-653:
/// their pilot lag for the Bartlett kernel, commonly used as the lag itself), not a value tuned
/// here, so it stays a constant.
constexpr double kBartlettBandwidthScale = 4.0;
constexpr double kBartlettBandwidthPoints = 100.0;
constexpr double kBartlettBandwidthExponent = 2.0 / 9.0;
/// Gaussian kurtosis: 3 (sum d^2)^2 / sum d^4 is the effective number of deviations d.
constexpr double kGaussianKurtosis = 3.0;
/// Numerical settings (not tuned thresholds): refine's Levenberg-Marquardt stops, Ceres' relative
/// cost decrease, relative step and gradient norm.
constexpr double kRefineFunctionTolerance = 1e-12;
constexpr double kRefineParameterTolerance = 1e-12;
constexpr double kRefineGradientTolerance = 1e-14;
/// Numerical setting: jacobianAt's central-difference step, this fraction of each parameter's
/// magnitude (at least of 1e-3 |f0| for f0 and width, of 1e-6 for the others).
constexpr double kJacobianRelativeStep = 1e-6;

/// Parameter vector: f0, w0, Re a, Im a, Re b0, Im b0, [Re b1, Im b1], then the nonlinear terms'
/// coefficients in the registry's order (response_laws.h): [xi], [g].
struct Layout {
  bool slope = false;
  ResponseTerms terms;  ///< the nonlinear terms (its background_slope is not read: `slope`)
  bool has(const ResponseLaw& law) const { return terms.*law.flag; }
  bool nonlinear() const { return responseTermCount(terms) > 0; }
  int size() const { return 6 + (slope ? 2 : 0) + responseTermCount(terms); }
};

ResponseParams unpack(const double* x, const Layout& L, double f_ref) {
  ResponseParams p;
  p.f0_hz = x[0];
  p.width_hz = x[1];
  p.gain = cd(x[2], x[3]);
  p.bg0 = cd(x[4], x[5]);
  int k = 6;
  if (L.slope) {
    p.bg1 = cd(x[k], x[k + 1]);
    k += 2;
  }
  for (const ResponseLaw& law : responseLaws())
    if (L.has(law)) p.*law.coefficient = x[k++];
  p.f_ref_hz = f_ref;
  return p;
}

std::vector<double> pack(const ResponseParams& p, const Layout& L) {
  std::vector<double> x = {p.f0_hz,       p.width_hz,   p.gain.real(),
                           p.gain.imag(), p.bg0.real(), p.bg0.imag()};
  if (L.slope) {
    x.push_back(p.bg1.real());
    x.push_back(p.bg1.imag());
  }
  for (const ResponseLaw& law : responseLaws())
    if (L.has(law)) x.push_back(p.*law.coefficient);
  return x;
}

/// Re and Im of Z - model per point into r, scaled by Huber's sqrt(rho) / |e| beyond delta (> 0);
/// false on a non-finite residual.
bool stackResiduals(const std::vector<cd>& z, const std::vector<cd>& m, double huber_delta,
                    double* r) {
  for (size_t i = 0; i < m.size(); ++i) {
    cd e = z[i] - m[i];
    const double a = std::abs(e);
    if (huber_delta > 0.0 && a > huber_delta)
      e *= std::sqrt(2.0 * huber_delta / a - huber_delta * huber_delta / (a * a));
    r[2 * i] = e.real();
    r[2 * i + 1] = e.imag();
    if (!std::isfinite(r[2 * i]) || !std::isfinite(r[2 * i + 1])) return false;
  }
  return true;
}

struct OutputError {
  const ResponseData* data;
  Layout layout;
  double f_ref;
  BranchChoice choice = BranchChoice::kFollow;
  double huber_delta = 0.0;  ///< > 0: Huber weights on |Z - model| (points off the model's branch)
  bool operator()(double const* const* x, double* r) const {
    const ResponseParams p = unpack(x[0], layout, f_ref);
    if (!(p.f0_hz > 0.0) || !(p.width_hz > 0.0)) return false;
    const std::vector<cd> m = stationaryResponse(p, *data, nullptr, nullptr, choice);
    return stackResiduals(data->z, m, huber_delta, r);
  }
};

/// The model with a free real factor on the resonant part's drive of every level but the first
/// (log scale; the background keeps the drive as written): what the amplitude law would need to
/// fit the levels' sizes.
struct ScaledDriveError {
  const ResponseData* data;
  Layout layout;
  double f_ref;
  std::vector<int> level;  ///< level index per point (0 = the reference level)
  double huber_delta = 0.0;
  bool operator()(double const* const* x, double* r) const {
    const ResponseParams p = unpack(x[0], layout, f_ref);
    if (!(p.f0_hz > 0.0) || !(p.width_hz > 0.0)) return false;
    ResponseData d = *data;
    d.resonant_drive_factor.assign(d.size(), 1.0);
    for (size_t i = 0; i < d.size(); ++i)
      if (level[i] > 0) d.resonant_drive_factor[i] = std::exp(x[1][level[i] - 1]);
    const std::vector<cd> m = stationaryResponse(p, d);
    return stackResiduals(d.z, m, huber_delta, r);
  }
};

/// RSS of the model refitted with a free drive factor per level (from `start`, factors 1).
double rssWithFreeDriveScales(const ResponseData& d, const Layout& L, const ResponseParams& start,
                              const std::vector<int>& level, int n_levels, double huber_delta,
                              int max_iterations) {
  std::vector<double> x = pack(start, L), s(n_levels - 1, 0.0);
  auto* cost = new ceres::DynamicNumericDiffCostFunction<ScaledDriveError, ceres::CENTRAL>(
      new ScaledDriveError{&d, L, start.f_ref_hz, level, huber_delta});
  cost->AddParameterBlock(L.size());
  cost->AddParameterBlock(n_levels - 1);
  cost->SetNumResiduals(static_cast<int>(2 * d.size()));
  ceres::Problem problem;
  problem.AddResidualBlock(cost, nullptr, x.data(), s.data());
  ceres::Solver::Summary sum;
  ceres::Solve(denseSolverOptions({max_iterations}), &problem, &sum);
  ResponseData ds = d;
  ds.resonant_drive_factor.assign(ds.size(), 1.0);
  for (size_t i = 0; i < ds.size(); ++i)
    if (level[i] > 0) ds.resonant_drive_factor[i] = std::exp(s[level[i] - 1]);
  const ResponseParams p = unpack(x.data(), L, start.f_ref_hz);
  const std::vector<cd> m = stationaryResponse(p, ds);
  double rss = 0.0;
  for (size_t i = 0; i < m.size(); ++i) rss += std::norm(d.z[i] - m[i]);
  return rss;
}

/// Sum of rho(|Z - model|): squares, or Huber beyond delta (> 0).
double costOf(const ResponseParams& p, const ResponseData& d, double delta = 0.0) {
  const std::vector<cd> m = stationaryResponse(p, d);
  double s = 0.0;
  for (size_t i = 0; i < m.size(); ++i) {
    const double a = std::abs(d.z[i] - m[i]);
    s += delta > 0.0 && a > delta ? 2.0 * delta * a - delta * delta : a * a;
  }
  return std::isfinite(s) ? s : std::numeric_limits<double>::infinity();
}

/// Levenberg-Marquardt (Ceres, central differences) from `start`; returns the final parameters.
ResponseParams refine(const ResponseData& d, const Layout& L, const ResponseParams& start,
                      int max_iterations, bool* converged,
                      BranchChoice choice = BranchChoice::kFollow, double huber_delta = 0.0) {
  std::vector<double> x = pack(start, L);
  auto* cost = new ceres::DynamicNumericDiffCostFunction<OutputError, ceres::CENTRAL>(
      new OutputError{&d, L, start.f_ref_hz, choice, huber_delta});
  cost->AddParameterBlock(L.size());
  cost->SetNumResiduals(static_cast<int>(2 * d.size()));
  ceres::Problem problem;
  problem.AddResidualBlock(cost, nullptr, x.data());
  ceres::Solver::Summary s;
  ceres::Solve(denseSolverOptions({max_iterations, kRefineFunctionTolerance,
                                   kRefineParameterTolerance, kRefineGradientTolerance}),
               &problem, &s);
  if (converged) *converged = s.IsSolutionUsable();
  return unpack(x.data(), L, start.f_ref_hz);
}

/// Linear model at fixed f0, w: the complex gain and background by QR; returns the RSS.
double projectLinear(const ResponseData& d, const std::vector<int>& idx, double f0, double w,
                     bool slope, double f_ref, ResponseParams* out) {
  const int k = slope ? 3 : 2;
  Eigen::MatrixXcd A(idx.size(), k);
  Eigen::VectorXcd b(idx.size());
  for (size_t r = 0; r < idx.size(); ++r) {
    const int i = idx[r];
    const double f = d.frequency_hz[i];
    const cd S = d.kind == ResponseKind::kVelocity ? cd(f / f0, 0.0) : cd(1.0, 0.0);
    A(r, 0) = d.drive[i] * S / cd(f0 * f0 - f * f, f * w);
    A(r, 1) = d.drive[i];
    if (slope) A(r, 2) = d.drive[i] * (f - f_ref);
    b(r) = d.z[i];
  }
  const Eigen::VectorXcd beta = A.colPivHouseholderQr().solve(b);
  const double rss = (A * beta - b).squaredNorm();
  if (out) {
    out->f0_hz = f0;
    out->width_hz = w;
    out->gain = beta(0);
    out->bg0 = beta(1);
    out->bg1 = slope ? beta(2) : cd(0.0, 0.0);
    out->f_ref_hz = f_ref;
    out->backbone_hz_per_amp2 = out->width_growth_hz_per_amp2 = 0.0;
  }
  return std::isfinite(rss) ? rss : std::numeric_limits<double>::infinity();
}

/// Variable projection over a grid of f0 and w (then finer grids around the best cell; the grid's
/// sizes are ResponseFitOptions' grid_* fields).
double gridLinear(const ResponseData& d, const std::vector<int>& idx, bool slope, double f_ref,
                  const ResponseFitOptions& o, ResponseParams* best) {
  double fmin = std::numeric_limits<double>::infinity(), fmax = -fmin, step = fmax;
  for (size_t r = 0; r < idx.size(); ++r) {
    fmin = std::min(fmin, d.frequency_hz[idx[r]]);
    fmax = std::max(fmax, d.frequency_hz[idx[r]]);
    if (r > 0) {
      const double df = std::abs(d.frequency_hz[idx[r]] - d.frequency_hz[idx[r - 1]]);
      if (df > 0) step = std::min(step, df);
    }
  }
  const double span = std::max(fmax - fmin, 1e-9 * fmax);
  if (!std::isfinite(step)) step = span;
  double lo_f = fmin - o.grid_band_margin * span, hi_f = fmax + o.grid_band_margin * span;
  double lo_w = std::max(o.grid_min_width_steps * step, span * o.grid_min_width_band),
         hi_w = o.grid_max_width_bands * span;
  double best_rss = std::numeric_limits<double>::infinity();
  double bf = 0.5 * (fmin + fmax), bw = std::sqrt(lo_w * hi_w);
  for (int pass = 0; pass < o.grid_passes; ++pass) {
    const int nf = pass == 0 ? o.grid_first_frequencies : o.grid_later_frequencies,
              nw = pass == 0 ? o.grid_first_widths : o.grid_later_widths;
    for (int a = 0; a < nf; ++a) {
      const double f0 = lo_f + (hi_f - lo_f) * a / (nf - 1);
      if (!(f0 > 0)) continue;
      for (int b = 0; b < nw; ++b) {
        const double w = lo_w * std::pow(hi_w / lo_w, static_cast<double>(b) / (nw - 1));
        const double rss = projectLinear(d, idx, f0, w, slope, f_ref, nullptr);
        if (rss < best_rss) {
          best_rss = rss;
          bf = f0;
          bw = w;
        }
      }
    }
    const double df = (hi_f - lo_f) / (nf - 1), rw = std::pow(hi_w / lo_w, 1.0 / (nw - 1));
    // In width the zoom is rw^cells: lo_w = bw / (rw * rw), hi_w = bw * rw * rw for 2 cells, the
    // products in that order.
    double zoom_w = 1.0;
    hi_w = bw;
    for (int k = 0; k < o.grid_zoom_cells; ++k) zoom_w *= rw, hi_w *= rw;
    lo_f = bf - o.grid_zoom_cells * df;
    hi_f = bf + o.grid_zoom_cells * df;
    lo_w = bw / zoom_w;
  }
  return projectLinear(d, idx, bf, bw, slope, f_ref, best);
}

/// Noise scale of one component from second differences within sweeps (median, so jumps and the
/// peak's curvature do not count): |z[i+1] - 2 z[i] + z[i-1]| has the scale sqrt(6) sigma per
/// component, its median 1.1774 sqrt(6) sigma for complex Gaussian noise.
double noiseFromDifferences(const ResponseData& d) {
  std::vector<double> a;
  for (size_t i = 1; i + 1 < d.size(); ++i)
    if (d.sweep[i - 1] == d.sweep[i] && d.sweep[i + 1] == d.sweep[i])
      a.push_back(std::abs(d.z[i + 1] - 2.0 * d.z[i] + d.z[i - 1]));
  if (a.empty()) return 0.0;
  std::nth_element(a.begin(), a.begin() + a.size() / 2, a.end());
  return a[a.size() / 2] / (kMedianAbsPerSigma * std::sqrt(6.0));
}

double lag1Along(const ResponseData& d, const std::vector<cd>& m) {
  double num = 0, den = 0;
  for (size_t i = 0; i < d.size(); ++i) {
    const cd e = d.z[i] - m[i];
    den += std::norm(e);
    if (i > 0 && d.sweep[i] == d.sweep[i - 1])
      num += std::real(e * std::conj(d.z[i - 1] - m[i - 1]));
  }
  return den > 0 ? num / den : 0.0;
}

/// Derived quantities in the input's units: f0_hz, width_hz, Q and the nonlinear terms.
std::map<std::string, double> derivedOf(const ResponseParams& p, const Layout& L, double u_scale) {
  std::map<std::string, double> v = {
      {"f0_hz", p.f0_hz}, {"width_hz", p.width_hz}, {"Q", p.f0_hz / p.width_hz}};
  for (const ResponseLaw& law : responseLaws())
    if (L.has(law)) v[law.derived_key] = p.*law.coefficient / u_scale;
  return v;
}

ResponseData subset(const ResponseData& d, const std::vector<int>& idx) {
  ResponseData s;
  s.kind = d.kind;
  for (int i : idx) {
    s.frequency_hz.push_back(d.frequency_hz[i]);
    s.drive.push_back(d.drive[i]);
    s.z.push_back(d.z[i]);
    s.sweep.push_back(d.sweep[i]);
  }
  return s;
}

/// Numerical Jacobian (central differences) of the stacked residuals at x. A point whose root
/// changes branch under the step (a fold crossing it) has no derivative: its rows are left out
/// (zero), or they would make every column the same spike.
Eigen::MatrixXd jacobianAt(const ResponseData& d, const Layout& L, double f_ref,
                           const std::vector<double>& x, double fold_crossing_relative_u) {
  const OutputError fn{&d, L, f_ref, BranchChoice::kNearestData};
  const int n = static_cast<int>(2 * d.size());
  Eigen::MatrixXd J(n, L.size());
  std::vector<double> rp(n), rm(n), u0, up, um;
  std::vector<bool> crossed(d.size(), false);
  stationaryResponse(unpack(x.data(), L, f_ref), d, &u0, nullptr, BranchChoice::kNearestData);
  for (int j = 0; j < L.size(); ++j) {
    std::vector<double> xp = x, xm = x;
    const double h =
        kJacobianRelativeStep * std::max(std::abs(x[j]), j < 2 ? 1e-3 * std::abs(x[0]) : 1e-6);
    xp[j] += h;
    xm[j] -= h;
    const double* pp = xp.data();
    const double* pm = xm.data();
    if (!fn(&pp, rp.data()) || !fn(&pm, rm.data())) return Eigen::MatrixXd();
    for (int i = 0; i < n; ++i) J(i, j) = (rp[i] - rm[i]) / (2 * h);
    stationaryResponse(unpack(xp.data(), L, f_ref), d, &up, nullptr, BranchChoice::kNearestData);
    stationaryResponse(unpack(xm.data(), L, f_ref), d, &um, nullptr, BranchChoice::kNearestData);
    for (size_t i = 0; i < d.size(); ++i)
      if (std::abs(up[i] - um[i]) > fold_crossing_relative_u * u0[i]) crossed[i] = true;
  }
  for (size_t i = 0; i < d.size(); ++i)
    if (crossed[i]) J.middleRows(2 * i, 2).setZero();
  return J;
}

const char* const kParamNames[] = {"f0_hz", "width_hz", "gain", "gain", "background", "background"};

/// What fitResponse's steps share: the data in normalised units and the model's layout.
struct FitContext {
  ResponseData d;         ///< normalised (and conjugated when the lock-in's y runs the other way)
  size_t n = 0;           ///< number of points
  double zs = 0, ds = 0;  ///< the response's largest magnitude, the drive's largest level
  double f_ref = 0;       ///< middle of the swept band (the background slope's origin)
  std::vector<int> all;   ///< every point's index
  Layout L;
};

/// Step 1. Normalise: response by its largest magnitude, drive by its largest level.
void normalise(const ResponseData& data_in, const ResponseFitOptions& o, FitContext* c) {
  const size_t n = c->n;
  double zs = 0, ds = 0;
  for (size_t i = 0; i < n; ++i) {
    zs = std::max(zs, std::abs(data_in.z[i]));
    ds = std::max(ds, data_in.drive[i]);
  }
  if (!(zs > 0) || !(ds > 0)) throw AnalysisError("the response is zero everywhere");
  c->zs = zs;
  c->ds = ds;
  c->d = data_in;
  ResponseData& d = c->d;
  d.kind = o.kind;
  for (size_t i = 0; i < n; ++i) {
    d.z[i] /= zs;
    d.drive[i] /= ds;
  }
  c->all.resize(n);
  std::iota(c->all.begin(), c->all.end(), 0);
  c->f_ref = 0.5 * (*std::min_element(d.frequency_hz.begin(), d.frequency_hz.end()) +
                    *std::max_element(d.frequency_hz.begin(), d.frequency_hz.end()));
}

/// Step 2. The lock-in's phase convention: the response turns one way through the resonance.
/// Returns the linear fit (with a background slope) in the convention chosen.
ResponseParams choosePhaseConvention(const ResponseFitOptions& o, FitContext* c, ResponseFit* fit) {
  ResponseParams lin, lin_conj;
  const double rss_direct = gridLinear(c->d, c->all, true, c->f_ref, o, &lin);
  ResponseData dc = c->d;
  for (auto& z : dc.z) z = std::conj(z);
  const double rss_conj = gridLinear(dc, c->all, true, c->f_ref, o, &lin_conj);
  if (rss_conj < rss_direct) {
    fit->conjugated = true;
    c->d = dc;
    lin = lin_conj;
    fit->notes.push_back(
        "phase convention: the response's phase falls through the resonance with y as written "
        "taken as -Im (lock-in y = -quadrature); the fit used x - iy, results are independent of "
        "it");
  } else {
    fit->notes.push_back(
        "phase convention: x + iy with the phase of a displacement-like response falling by pi "
        "through the resonance (lock-in y = +quadrature)");
  }
  return lin;
}

/// Step 3. The layout: the nonlinear terms asked for, and a background slope in frequency only
/// where the data ask for it (F test, lag-1 deflated dof). `lin` becomes the linear fit without
/// a slope when none is needed.
void chooseLayout(const ResponseTerms& terms, const ResponseFitOptions& o, FitContext* c,
                  ResponseParams* lin, ResponseFit* fit) {
  const ResponseData& d = c->d;
  Layout& L = c->L;
  for (const ResponseLaw& law : responseLaws()) L.terms.*law.flag = terms.*law.flag;
  {
    ResponseParams no_slope;
    const double rss0 = gridLinear(d, c->all, false, c->f_ref, o, &no_slope);
    const double rss1 = projectLinear(d, c->all, lin->f0_hz, lin->width_hz, true, c->f_ref, lin);
    const double rho =
        std::max(0.0, std::min(o.slope_test_max_lag1, lag1Along(d, stationaryResponse(*lin, d))));
    const double dof =
        std::max(o.slope_test_min_dof, (2.0 * c->n - kSlopeModelParams) * (1 - rho) / (1 + rho));
    const double F = (rss0 - rss1) / 2.0 / (rss1 / dof);
    L.slope = terms.background_slope || F > o.slope_test_f;
    if (!L.slope) *lin = no_slope;
  }
  fit->notes.push_back(L.slope ? "background: constant + linear in frequency, per unit drive"
                               : "background: constant per unit drive (a slope was not needed)");
}

/// Step 4. The points of each drive level, keyed by the level's mean drive (driveLevels: levels
/// 1 % apart, a measured drive's noise stays within its level).
std::map<double, std::vector<int>> pointsByDriveLevel(const ResponseData& d, size_t n) {
  std::map<double, std::vector<int>> by_level;
  const std::vector<int> level_of = driveLevels(d.drive);
  std::map<int, std::vector<int>> members;
  for (size_t i = 0; i < n; ++i) members[level_of[i]].push_back(static_cast<int>(i));
  for (const auto& kv : members) {
    double sum = 0.0;
    for (int i : kv.second) sum += d.drive[i];
    by_level[sum / static_cast<double>(kv.second.size())] = kv.second;
  }
  return by_level;
}

/// Step 5. Per-drive-level Lorentzians (fit->levels): the nonlinear start and the adequacy
/// reference. Returns the |residual| of these free per-level fits (the noise scale).
std::vector<double> fitEachLevel(const FitContext& c,
                                 const std::map<double, std::vector<int>>& by_level,
                                 const ResponseFitOptions& o, ResponseFit* fit) {
  const ResponseData& d = c.d;
  std::vector<double> free_abs;
  for (const auto& kv : by_level) {
    if (kv.second.size() < o.min_level_points) continue;
    ResponseParams p;
    gridLinear(d, kv.second, c.L.slope, c.f_ref, o, &p);
    const ResponseData dl = subset(d, kv.second);
    Layout lin_layout;
    lin_layout.slope = c.L.slope;
    bool ok = false;
    const ResponseParams pr = refine(dl, lin_layout, p, o.level_fit_iterations, &ok);
    if (ok && costOf(pr, dl) < costOf(p, dl)) p = pr;
    const std::vector<cd> ml = stationaryResponse(p, dl);
    for (size_t i = 0; i < ml.size(); ++i) free_abs.push_back(std::abs(dl.z[i] - ml[i]));
    ResponseLevelFit lf;
    lf.rss = costOf(p, dl) * c.zs * c.zs;
    lf.drive = kv.first * c.ds;
    lf.f0_hz = p.f0_hz;
    lf.width_hz = p.width_hz;
    lf.peak_u = std::norm(kv.first * p.gain / cd(0.0, p.f0_hz * p.width_hz));
    lf.n_points = static_cast<int>(kv.second.size());
    fit->levels.push_back(lf);
  }
  return free_abs;
}

/// Step 6. Starts: the linear fit, and for nonlinear terms the per-level trend of f0 and width
/// in u (least squares over the levels' peaks).
std::vector<ResponseParams> startsOf(const FitContext& c, const ResponseParams& lin,
                                     const std::vector<ResponseLevelFit>& levels,
                                     const ResponseFitOptions& o) {
  const Layout& L = c.L;
  std::vector<ResponseParams> starts = {lin};
  if (L.nonlinear() && levels.size() >= 2) {
    double su = 0, sf = 0, sw = 0, suu = 0, suf = 0, suw = 0;
    const double m = static_cast<double>(levels.size());
    for (const auto& lf : levels) {
      su += lf.peak_u;
      sf += lf.f0_hz;
      sw += lf.width_hz;
      suu += lf.peak_u * lf.peak_u;
      suf += lf.peak_u * lf.f0_hz;
      suw += lf.peak_u * lf.width_hz;
    }
    const double den = m * suu - su * su;
    if (den > 0) {
      ResponseParams s = lin;
      const double xi = (m * suf - su * sf) / den, g = (m * suw - su * sw) / den;
      s.f0_hz = (sf - xi * su) / m;
      s.width_hz =
          std::max((sw - g * su) / m, o.min_start_width_fraction * levels.front().width_hz);
      projectLinear(c.d, c.all, s.f0_hz, s.width_hz, L.slope, c.f_ref, &s);
      if (L.terms.backbone) s.backbone_hz_per_amp2 = xi;
      if (L.terms.width_growth) s.width_growth_hz_per_amp2 = g;
      starts.push_back(s);
      if (L.terms.backbone) {  // the same trend read as a backbone of the other sign
        ResponseParams t = s;
        t.backbone_hz_per_amp2 = -xi;
        starts.push_back(t);
      }
    }
  }
  return starts;
}

/// Step 7. Noise scale: the smaller of the median |residual| of the free per-level fits (1.1774
/// sigma for complex Gaussian noise; inflated where a level is not a Lorentzian) and the second
/// differences' (which correlated noise lowers). Reorders `free_abs`.
double noiseScale(const ResponseData& d, size_t min_residuals, std::vector<double>* free_abs) {
  double noise = noiseFromDifferences(d);
  if (free_abs->size() >= min_residuals) {
    std::nth_element(free_abs->begin(), free_abs->begin() + free_abs->size() / 2, free_abs->end());
    noise = std::min(noise, (*free_abs)[free_abs->size() / 2] / kMedianAbsPerSigma);
  }
  return noise;
}

/// Step 8's Huber-weighted refinement of one start.
struct RobustRefiner {
  const ResponseData& d;
  const Layout& L;
  size_t n;
  double noise;
  const ResponseFitOptions& o;

  /// The Huber threshold follows the fit's own misfit: o.huber_noise_scales (3) of the larger of
  /// the noise and the median residual of the stage's start (a model that misses everywhere is not
  /// clipped everywhere, which would stall Levenberg-Marquardt).
  double deltaAt(const ResponseParams& p, BranchChoice c) const {
    const std::vector<cd> m = stationaryResponse(p, d, nullptr, nullptr, c);
    std::vector<double> a(n);
    for (size_t i = 0; i < n; ++i) a[i] = std::abs(d.z[i] - m[i]);
    std::nth_element(a.begin(), a.begin() + n / 2, a.end());
    return o.huber_noise_scales * std::max(noise, a[n / 2] / kMedianAbsPerSigma);
  }

  /// A stage refines with the threshold of its start's misfit, then again while the misfit keeps
  /// falling (at most o.max_huber_rounds), so a start far off is not clipped everywhere and a close
  /// one ends with the noise's threshold.
  ResponseParams robustRefine(ResponseParams t, BranchChoice c, bool* ok,
                              double* delta_used) const {
    double dl = deltaAt(t, c);
    *ok = false;
    for (int round = 0; round < o.max_huber_rounds; ++round) {
      bool ok_round = false;
      const ResponseParams p = refine(d, L, t, o.robust_fit_iterations, &ok_round, c, dl);
      if (!ok_round) break;
      *ok = true;
      t = p;
      const double next = deltaAt(t, c);
      *delta_used = dl;
      if (!(next < o.huber_shrink_for_another_round * dl)) break;
      dl = next;
    }
    return t;
  }
};

/// Step 8's outcome: the best refit and the Huber threshold it ended with.
struct BestFit {
  ResponseParams params;
  double delta = 0.0;
};

/// Step 8. Each start is refined three ways: on the smooth cost (the stable root nearest the
/// data), then following the branch in time order from there, and on the branch directly. A
/// point just past a fold sits on the other branch and its residual has no gradient that moves
/// the fold; points caught mid-transient near a fold (critical slowing down) are off any
/// stationary model. So the fit weighs points by Huber beyond 3 noise scales (from second
/// differences along the sweeps); candidates are compared on 3 noise scales. Sets
/// fit->converged when a refit converged.
BestFit refineStarts(const FitContext& c, const std::vector<ResponseParams>& starts,
                     const ResponseParams& lin, double noise, const ResponseFitOptions& o,
                     ResponseFit* fit) {
  const ResponseData& d = c.d;
  const Layout& L = c.L;
  const RobustRefiner rr{d, L, c.n, noise, o};
  double best_cost = std::numeric_limits<double>::infinity();
  ResponseParams best = lin;
  const double delta_compare = o.huber_noise_scales * noise;
  double delta = delta_compare;
  for (const ResponseParams& s : starts) {
    std::vector<ResponseParams> tries = {s};
    if (L.nonlinear()) {
      bool ok_smooth = false;
      double unused = 0.0;
      const ResponseParams sm = rr.robustRefine(s, BranchChoice::kNearestData, &ok_smooth, &unused);
      if (ok_smooth) tries.push_back(sm);
    }
    if (L.nonlinear()) {  // and the noise's threshold from the start (a fold's point clipped)
      bool ok_fixed = false;
      const ResponseParams sf = refine(d, L, s, o.robust_fit_iterations, &ok_fixed,
                                       BranchChoice::kNearestData, delta_compare);
      if (ok_fixed) tries.push_back(sf);
    }
    for (size_t k = 0; k < tries.size(); ++k) {
      bool ok = false;
      double used = delta_compare;
      const ResponseParams p = k + 1 == tries.size() && L.nonlinear()
                                   ? refine(d, L, tries[k], o.robust_fit_iterations, &ok,
                                            BranchChoice::kFollow, delta_compare)
                                   : rr.robustRefine(tries[k], BranchChoice::kFollow, &ok, &used);
      const double cost = costOf(p, d, delta_compare);
      if (ok && cost < best_cost) {
        best_cost = cost;
        best = p;
        delta = used;
        fit->converged = true;
      }
    }
  }
  return {best, delta};
}

/// Step 9. Statistics, model, parameters and point estimates in the input's units.
void fillPointEstimates(const FitContext& c, const ResponseParams& best, double delta,
                        const ResponseFitOptions& o, ResponseFit* fit) {
  const ResponseData& d = c.d;
  const Layout& L = c.L;
  const size_t n = c.n;
  const double zs = c.zs, ds = c.ds;
  std::vector<cd> m = stationaryResponse(best, d, &fit->u, &fit->jumps);
  fit->residual_lag1 = lag1Along(d, m);
  fit->n_points = static_cast<int>(n);
  fit->n_params = L.size();
  fit->n_sweeps = d.sweep.empty() ? 1 : *std::max_element(d.sweep.begin(), d.sweep.end()) + 1;
  fit->rss = costOf(best, d) * zs * zs;
  int far = 0;
  for (size_t i = 0; i < n; ++i) far += std::abs(d.z[i] - m[i]) > delta ? 1 : 0;
  fit->notes.push_back("Huber weights beyond " + std::to_string(delta * zs) + " (" +
                       printfGText(o.huber_noise_scales, 6) +
                       " scales of the noise or of the median misfit): " + std::to_string(far) +
                       " of " + std::to_string(n) + " points down-weighted");
  fit->sigma = std::sqrt(fit->rss / std::max(1, static_cast<int>(2 * n) - L.size()));
  for (auto& z : m) z = (fit->conjugated ? std::conj(z) : z) * zs;
  fit->model = m;
  for (auto& u : fit->u) u *= zs * zs;
  for (auto& l : fit->levels) l.peak_u *= zs * zs;  // normalised until the starts were made
  fit->params = best;
  fit->params.gain *= zs / ds;
  fit->params.bg0 *= zs / ds;
  fit->params.bg1 *= zs / ds;
  fit->params.backbone_hz_per_amp2 /= zs * zs;
  fit->params.width_growth_hz_per_amp2 /= zs * zs;
  const std::map<std::string, double> point = derivedOf(best, L, zs * zs);
  for (const auto& kv : point) fit->derived[kv.first].value = kv.second;
}

/// Step 10. The amplitude law's check: would a free drive factor per level fit much better?
void checkLevelGains(const FitContext& c, const std::map<double, std::vector<int>>& by_level,
                     const ResponseParams& best, const ResponseFitOptions& o, ResponseFit* fit) {
  std::vector<int> level(c.n, 0);
  int k = 0;
  for (const auto& kv : by_level) {
    for (int i : kv.second) level[i] = k;
    ++k;
  }
  fit->rss_free_level_gains = std::min(
      fit->rss, rssWithFreeDriveScales(c.d, c.L, best, level, k, 0.0, o.level_gain_fit_iterations) *
                    c.zs * c.zs);
}

/// The column-scaled Jacobian at the optimum and its SVD.
struct ScaledJacobian {
  Eigen::VectorXd scale;  ///< column norms of J (1 for a zero column)
  Eigen::JacobiSVD<Eigen::MatrixXd> svd;
  Eigen::VectorXd sv;  ///< singular values, largest first
};

/// Step 11a. The Jacobian at `best`, its columns scaled to unit norm, and its SVD.
ScaledJacobian scaledJacobianAt(const FitContext& c, const ResponseParams& best,
                                const ResponseFitOptions& o) {
  const std::vector<double> x = pack(best, c.L);
  const Eigen::MatrixXd J = jacobianAt(c.d, c.L, c.f_ref, x, o.fold_crossing_relative_u);
  if (J.size() == 0)
    throw AnalysisError("the fitted response cannot be evaluated near the optimum");
  ScaledJacobian sj;
  sj.scale = J.colwise().norm();
  for (int j = 0; j < sj.scale.size(); ++j) sj.scale(j) = sj.scale(j) > 0 ? sj.scale(j) : 1.0;
  const Eigen::MatrixXd Js = J * sj.scale.cwiseInverse().asDiagonal();
  sj.svd.compute(Js, Eigen::ComputeThinU | Eigen::ComputeThinV);
  sj.sv = sj.svd.singularValues();
  return sj;
}

/// Step 11b. What the data cannot determine: near-null directions of the column-scaled Jacobian
/// (fit->not_determined, and a note per gain or background component).
void markNotDetermined(const Layout& L, const ScaledJacobian& sj, const ResponseFitOptions& o,
                       ResponseFit* fit) {
  const Eigen::VectorXd& sv = sj.sv;
  std::vector<bool> weak(L.size(), false);
  for (int k = 0; k < sv.size(); ++k) {
    if (sv(k) > o.rank_tolerance * o.weak_direction_tolerance_factor * sv(0)) continue;
    for (int j = 0; j < L.size(); ++j)
      if (std::abs(sj.svd.matrixV()(j, k)) > o.weak_direction_loading) weak[j] = true;
  }
  std::vector<std::string> weak_derived;
  {
    int k = 6 + (L.slope ? 2 : 0);
    if (weak[0]) weak_derived.push_back("f0_hz");
    if (weak[1]) weak_derived.push_back("width_hz");
    if (weak[0] || weak[1]) weak_derived.push_back("Q");
    for (const ResponseLaw& law : responseLaws())
      if (L.has(law) && weak[k++]) weak_derived.push_back(law.derived_key);
    for (int j = 2; j < 6; ++j)
      if (weak[j]) fit->notes.push_back(std::string(kParamNames[j]) + " is not determined");
  }
  fit->not_determined = weak_derived;
}

/// Step 12a. Sum over the sweeps of the Bartlett-weighted products of the points' scores (Jp
/// times the Huber psi of the residual) within a sweep, bandwidth 4 (m/100)^(2/9) point lags.
Eigen::MatrixXd withinSweepScoreProducts(const FitContext& c, const ResponseParams& best,
                                         double delta, const Eigen::MatrixXd& Jp) {
  const ResponseData& d = c.d;
  const Layout& L = c.L;
  const size_t n = c.n;
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(L.size(), L.size());
  const std::vector<cd> mn = stationaryResponse(best, d);
  size_t start = 0;
  while (start < n) {
    size_t end = start;
    while (end < n && d.sweep[end] == d.sweep[start]) ++end;
    const int mlen = static_cast<int>(end - start);
    const int bw = static_cast<int>(
        std::ceil(kBartlettBandwidthScale *
                  std::pow(mlen / kBartlettBandwidthPoints, kBartlettBandwidthExponent)));
    Eigen::MatrixXd S(L.size(), mlen);  // score of each point (both components)
    for (int i = 0; i < mlen; ++i) {
      const size_t pi = start + i;
      cd e = d.z[pi] - mn[pi];
      if (std::abs(e) > delta) e *= delta / std::abs(e);  // Huber's psi
      S.col(i) = Jp.col(2 * pi) * e.real() + Jp.col(2 * pi + 1) * e.imag();
    }
    for (int lag = 0; lag <= std::min(bw, mlen - 1); ++lag) {
      const double wgt = lag == 0 ? 1.0 : 1.0 - lag / (bw + 1.0);
      Eigen::MatrixXd P = S.leftCols(mlen - lag) * S.rightCols(mlen - lag).transpose();
      cov += lag == 0 ? P : Eigen::MatrixXd(wgt * (P + P.transpose()));
    }
    start = end;
  }
  return cov;
}

/// Step 12b. The within-sweep sandwich's standard errors of the derived quantities: cov = Jp K
/// Jp', Jp the pseudo-inverse of J, K the residual products within a sweep (step 12a).
std::map<std::string, double> sandwichStd(const FitContext& c, const ResponseParams& best,
                                          double delta, const ScaledJacobian& sj,
                                          const ResponseFitOptions& o) {
  const Layout& L = c.L;
  const double zs = c.zs;
  const Eigen::VectorXd& sv = sj.sv;
  const Eigen::VectorXd& scale = sj.scale;
  std::map<std::string, double> sandwich_std;
  const Eigen::MatrixXd Jp = sj.svd.matrixV() *
                             sv.unaryExpr([&](double s) {
                                 return s > o.rank_tolerance * sv(0) ? 1.0 / s : 0.0;
                               }).asDiagonal() *
                             sj.svd.matrixU().transpose();
  Eigen::MatrixXd cov = withinSweepScoreProducts(c, best, delta, Jp);
  cov = scale.cwiseInverse().asDiagonal() * cov * scale.cwiseInverse().asDiagonal();
  auto sd = [&](const Eigen::VectorXd& grad) {
    return std::sqrt(std::max(0.0, grad.dot(cov * grad)));
  };
  Eigen::VectorXd g0 = Eigen::VectorXd::Zero(L.size()), g1 = g0, gq = g0;
  g0(0) = 1;
  g1(1) = 1;
  gq(0) = 1.0 / best.width_hz;
  gq(1) = -best.f0_hz / (best.width_hz * best.width_hz);
  sandwich_std["f0_hz"] = sd(g0);
  sandwich_std["width_hz"] = sd(g1);
  sandwich_std["Q"] = sd(gq);
  int k = 6 + (L.slope ? 2 : 0);
  for (const ResponseLaw& law : responseLaws()) {
    if (!L.has(law)) continue;
    Eigen::VectorXd gt = Eigen::VectorXd::Zero(L.size());
    gt(k++) = 1.0 / (zs * zs);
    sandwich_std[law.derived_key] = sd(gt);
  }
  return sandwich_std;
}

/// Step 12c. The sandwich's standard errors as the intervals' (a jackknife may replace them).
void applySandwich(const FitContext& c, const std::map<std::string, double>& sandwich_std, int G,
                   ResponseFit* fit) {
  fit->interval_dof = std::max(1, static_cast<int>(2 * c.n) - c.L.size());
  for (const auto& kv : sandwich_std) {
    ResponseValue& rv = fit->derived[kv.first];
    rv.std = kv.second;
    rv.dof = fit->interval_dof;
  }
  fit->interval_method = "sandwich with a Bartlett kernel within each sweep (" + std::to_string(G) +
                         " sweeps: too few for a jackknife over sweeps), Student t";
}

/// Step 13a. The derived quantities refitted without each sweep in turn (the smooth stage
/// first, continuous in the data, then the branch followed again); *used counts the refits
/// that converged.
std::map<std::string, std::vector<double>> leaveOneSweepOut(const FitContext& c,
                                                            const ResponseParams& best,
                                                            double delta, int G,
                                                            const ResponseFitOptions& o,
                                                            int* used) {
  const ResponseData& d = c.d;
  const Layout& L = c.L;
  std::map<std::string, std::vector<double>> reps;
  for (int g = 0; g < G; ++g) {
    std::vector<int> keep;
    for (size_t i = 0; i < c.n; ++i)
      if (d.sweep[i] != g) keep.push_back(static_cast<int>(i));
    const ResponseData dg = subset(d, keep);
    // The smooth stage first (continuous in the data), then the branch followed again.
    bool ok_smooth = false, ok = false;
    ResponseParams pg = best;
    if (L.nonlinear()) {
      const ResponseParams ps = refine(dg, L, best, o.jackknife_refit_iterations, &ok_smooth,
                                       BranchChoice::kNearestData, delta);
      if (ok_smooth) pg = ps;
    }
    pg = refine(dg, L, pg, o.jackknife_refit_iterations, &ok, BranchChoice::kFollow, delta);
    if (!ok || !(pg.width_hz > 0)) continue;
    ++*used;
    for (const auto& kv : derivedOf(pg, L, c.zs * c.zs)) reps[kv.first].push_back(kv.second);
  }
  return reps;
}

/// Step 13b. With enough sweeps, a jackknife over whole sweeps, whose standard error is used
/// unless the sandwich's is larger where a fold can trap a refit (a refit that cannot leave a
/// fold-trap would make the jackknife's spread too small).
void jackknifeOverSweeps(const FitContext& c, const ResponseParams& best, double delta, int G,
                         const std::map<std::string, double>& sandwich_std,
                         const ResponseFitOptions& o, ResponseFit* fit) {
  const Layout& L = c.L;
  int used = 0;
  const std::map<std::string, std::vector<double>> reps =
      leaveOneSweepOut(c, best, delta, G, o, &used);
  // Student t with the jackknife's effective degrees of freedom: G - 1 when the sweeps weigh
  // alike, fewer when a few sweeps carry the estimate (the high drive levels, a drift of f0
  // between sweeps): 3 (sum d^2)^2 / sum d^4 of the leave-one-out deviations d (= G for
  // Gaussian d of equal variance), at most G - 1.
  fit->interval_dof = std::max(1, used - 1);
  // The sandwich is a floor only where a fold can trap a refit (a nonlinear term). A linear
  // model has no fold; there its sandwich, linearised once with unweighted bread under Huber
  // weights, can exceed the refits' spread many times (the low half of the wire record
  // example6: width sd 4.7 Hz against leave-one-out deviations of 0.05 Hz) and is not used.
  const bool folds_possible = L.nonlinear();
  int min_dof = fit->interval_dof, floored = 0;
  for (auto& kv : reps) {
    const auto& v = kv.second;
    const double mean = std::accumulate(v.begin(), v.end(), 0.0) / v.size();
    double ss = 0, s4 = 0;
    for (double a : v) {
      ss += (a - mean) * (a - mean);
      s4 += std::pow(a - mean, 4);
    }
    double sd = std::sqrt(ss * (v.size() - 1.0) / v.size());
    const int dof = s4 > 0
                        ? std::max(1, std::min(fit->interval_dof,
                                               static_cast<int>(kGaussianKurtosis * ss * ss / s4)))
                        : fit->interval_dof;
    min_dof = std::min(min_dof, dof);
    if (folds_possible && sandwich_std.count(kv.first) && sandwich_std.at(kv.first) > sd) {
      sd = sandwich_std.at(kv.first);
      ++floored;
    }
    ResponseValue& rv = fit->derived[kv.first];
    rv.std = sd;
    rv.dof = dof;
  }
  fit->interval_method = "jackknife over whole sweeps (" + std::to_string(used) + " of " +
                         std::to_string(G) + " refits), Student t with the effective dof " +
                         std::to_string(min_dof) + ".." + std::to_string(fit->interval_dof) +
                         " (3 (sum d^2)^2 / sum d^4 of the leave-one-out deviations); " +
                         (folds_possible ? std::to_string(floored) +
                                               " standard errors raised to the within-sweep "
                                               "sandwich's"
                                         : std::string("no fold, no sandwich floor"));
  if (used < G)
    fit->notes.push_back(std::to_string(G - used) + " jackknife refits did not converge");
}

/// Step 14. Student t intervals at o.confidence from each value's std and dof.
void setIntervals(const ResponseFitOptions& o, ResponseFit* fit) {
  for (auto& kv : fit->derived) {
    ResponseValue& rv = kv.second;
    const double t = studentQuantile(o.confidence, std::max(1, rv.dof));
    rv.ci_low = rv.value - t * rv.std;
    rv.ci_high = rv.value + t * rv.std;
  }
}

/// Step 16. The model term's coefficient of each term that has one (response_laws.h,
/// gamma_nl_conventions.h: gamma_nl_term = 8 pi times the width growth).
void addModelTerms(ResponseFit* fit) {
  for (const ResponseLaw& law : responseLaws()) {
    if (!law.model_term_key) continue;
    const auto g = fit->derived.find(law.derived_key);
    if (g == fit->derived.end()) continue;
    ResponseValue t = g->second;
    for (double* v : {&t.value, &t.std, &t.ci_low, &t.ci_high}) *v *= law.model_term_per_unit;
    fit->derived[law.model_term_key] = t;
    if (std::find(fit->not_determined.begin(), fit->not_determined.end(), g->first) !=
        fit->not_determined.end())
      fit->not_determined.push_back(law.model_term_key);
  }
}

}  // namespace

/// Step 15. No resonance: a width whose interval reaches zero is not a mode's (noise, or a mode
/// outside the swept band); nothing of it is reported as a number.
void requireResponseResonance(const ResponseFit& fit) {
  const ResponseValue& w = fit.derived.at("width_hz");
  if (!(w.ci_low > 0.0))
    throw AnalysisError("no resonance determined by these data: the width's interval [" +
                        std::to_string(w.ci_low) + ", " + std::to_string(w.ci_high) +
                        "] Hz reaches zero (noise only, or the mode outside the swept band)");
}

ResponseData responseDataOf(const ResponseRecord& r, ResponseKind kind) {
  ResponseData d;
  d.kind = kind;
  d.frequency_hz = r.frequency_hz;
  d.drive = r.drive;
  d.sweep = splitSweeps(r);
  for (size_t i = 0; i < r.size(); ++i) d.z.emplace_back(r.x[i], r.y[i]);
  return d;
}

ResponseFit fitResponse(const ResponseData& data_in, const ResponseTerms& terms,
                        const ResponseFitOptions& o) {
  FitContext c;
  c.n = data_in.size();
  if (c.n < kMinResponsePoints) throw AnalysisError("fewer than 8 response points");
  ResponseFit fit;
  fit.terms = terms;
  fit.kind = o.kind;
  normalise(data_in, o, &c);
  ResponseParams lin = choosePhaseConvention(o, &c, &fit);
  chooseLayout(terms, o, &c, &lin, &fit);
  const std::map<double, std::vector<int>> by_level = pointsByDriveLevel(c.d, c.n);
  std::vector<double> free_abs = fitEachLevel(c, by_level, o, &fit);
  fit.n_drive_levels = static_cast<int>(by_level.size());
  const std::vector<ResponseParams> starts = startsOf(c, lin, fit.levels, o);
  const double noise = noiseScale(c.d, o.min_residuals_for_noise, &free_abs);
  const BestFit bf = refineStarts(c, starts, lin, noise, o, &fit);
  const ResponseParams& best = bf.params;
  const double delta = bf.delta;
  if (!fit.converged || !(best.width_hz > 0))
    throw AnalysisError("the response fit did not converge");
  fillPointEstimates(c, best, delta, o, &fit);
  if (o.level_gain_check && by_level.size() >= 2) checkLevelGains(c, by_level, best, o, &fit);
  if (!o.intervals) return fit;

  const ScaledJacobian sj = scaledJacobianAt(c, best, o);
  markNotDetermined(c.L, sj, o, &fit);
  // Intervals. The within-sweep sandwich always; with 5 or more sweeps also a jackknife over
  // whole sweeps, whose standard error is used unless the sandwich's is larger (a refit that
  // cannot leave a fold-trap would make the jackknife's spread too small).
  const int G = fit.n_sweeps;
  const std::map<std::string, double> sandwich_std = sandwichStd(c, best, delta, sj, o);
  applySandwich(c, sandwich_std, G, &fit);
  if (G >= o.min_sweeps_for_jackknife)
    jackknifeOverSweeps(c, best, delta, G, sandwich_std, o, &fit);
  setIntervals(o, &fit);
  if (o.require_resonance) requireResponseResonance(fit);
  addModelTerms(&fit);
  return fit;
}

}  // namespace cvg_bench

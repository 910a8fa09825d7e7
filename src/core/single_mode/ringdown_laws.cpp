#include "cvg_bench/core/single_mode/ringdown_laws.h"

#include <algorithm>
#include <boost/math/special_functions/expint.hpp>
#include <cmath>
#include <limits>
#include <utility>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/numeric_least_squares.h"
#include "cvg_bench/core/model/gamma_nl_conventions.h"

namespace cvg_bench {
namespace {

/// Below this |k t|, (1 - e^{-k t}) / k is taken as its limit t.
constexpr double kSmallRateTime = 1e-10;
/// Above this A^2 / F^2 the floor's Rice term E1(x) / 2 is left out (below 1e-18 there).
constexpr double kRiceNegligibleAbove = 40.0;
/// Below this A^2 / F^2 the detected level is the floor's alone.
constexpr double kRiceFloorOnlyBelow = 1e-8;
/// Euler's constant: the mean of ln|n| for circular Gaussian n of rms F is ln F - gamma / 2.
constexpr double kEulerGamma = 0.5772156649015329;

/// Smallest baseline rate [1/T] the starting points split or scale.
constexpr double kMinStartRate = 0.05;
/// gamma_nl / gamma_a starts: fractions of the start rate given to the amplitude-dependent part.
constexpr double kAmplitudeDependentFractions[] = {0.0, 0.5, -0.3};
/// two_stage starts: rate of the fast stage per baseline rate.
constexpr double kTwoStageFastRatios[] = {3.0, 10.0};
/// two_stage starts: level of the slow stage against the fast one [Np].
constexpr double kTwoStageSlowLevels[] = {-1.0, -2.5};
/// two_stage starts: rate of the slow stage per baseline rate.
constexpr double kTwoStageSlowRateFactor = 0.7;
/// beat starts: at most this many time bins the linear residuals are averaged into.
constexpr int kBeatMaxBins = 1024;
/// beat starts: periodogram variants (as they are, weighted, first part of the span only).
constexpr int kBeatVariants = 3;
/// beat starts: the part of the span the third periodogram covers.
constexpr double kBeatEarlyFraction = 0.4;
/// beat starts: lowest split searched [cycles per span].
constexpr double kBeatMinCycles = 1.5;
/// beat starts: periodogram step in w [rad per span] (an eighth of a cycle per span).
constexpr double kBeatStepW = M_PI / 4.0;
/// beat starts: a peak within this many steps of one taken is the same split.
constexpr double kBeatDuplicateSteps = 1.5;
/// beat starts: peaks taken from the first periodogram, and from each of the others.
constexpr int kBeatPeaksFirst = 3;
constexpr int kBeatPeaksOther = 2;
/// beat starts: bounds of the modulation depth m (A2/A1) read from a peak.
constexpr double kBeatMinDepth = 1e-3;
constexpr double kBeatMaxDepth = 0.9;
/// Guard against a zero total weight.
constexpr double kTinyWeightSum = 1e-300;
/// beat start without a periodogram peak: second mode this far below [Np], split 2 cycles per span.
constexpr double kBeatFallbackDepth = 2.0;
constexpr double kBeatFallbackW = 4.0 * M_PI;

const double kInf = std::numeric_limits<double>::infinity();

/// (1 - e^{-k t}) / k, stable as k -> 0 (limit t).
double oneMinusExpOver(double k, double t) {
  if (std::fabs(k * t) < kSmallRateTime) return t;
  return -std::expm1(-k * t) / k;
}

/// For laws without a canonical order.
void keepOrder(Eigen::VectorXd&) {}

/// Rate and amplitude a, g of the linear baseline the starting points build on.
std::pair<double, double> baselineLevelAndRate(const RingdownFit& lin) {
  return {lin.p(0), std::max(lin.p(1), kMinStartRate)};
}

/// Standard error and interval of a function of the parameters by the delta method.
RingdownValue deltaValue(const std::function<double(const Eigen::VectorXd&)>& fn,
                         const Eigen::VectorXd& p, const Eigen::MatrixXd& cov,
                         const Eigen::MatrixXd& cov_crb, double z) {
  RingdownValue v;
  v.value = fn(p);
  const ResidualFunction value = [&](const Eigen::VectorXd& q, Eigen::VectorXd& out) {
    out = Eigen::VectorXd::Constant(1, fn(q));
    return true;
  };
  Eigen::MatrixXd g;
  // A value that is not finite next to p leaves a NaN gradient (its std then reads 0, as before).
  const Eigen::VectorXd grad = centralDifferenceJacobian(value, p, g)
                                   ? Eigen::VectorXd(g.row(0).transpose())
                                   : Eigen::VectorXd::Constant(p.size(), NAN);
  v.std = std::sqrt(std::max(0.0, grad.dot(cov * grad)));
  v.crb_std = std::sqrt(std::max(0.0, grad.dot(cov_crb * grad)));
  v.ci_low = v.value - z * v.std;
  v.ci_high = v.value + z * v.std;
  return v;
}

// ---- linear: ln A = a - g t ----

bool linearLogAmplitude(const Eigen::VectorXd& p, double t, double& log_a) {
  log_a = p(0) - p(1) * t;
  return true;
}

std::vector<Eigen::VectorXd> linearStarts(const RingdownFit& lin) {
  return {lin.p};
}

void linearReadout(const RingdownReadout& r) {
  const RingdownValue g = r.param(1);
  r.putRate("decay_rate_1_s", g);
  r.putQ("Q", g);
  RingdownValue tau = ringdownQFromRate(g, r.T);
  r.fit.derived["tau_s"] = tau;
  if (g.value < 0.0) r.fit.flags.push_back("negative_damping");
}

/// The baseline is never a candidate: no check.
std::string linearPhysicalCheck(const Eigen::VectorXd&, const RingdownPlausibilityOptions&) {
  return "";
}

RingdownLaw linearLaw() {
  RingdownLaw law;
  law.name = "linear";
  law.parameters = {"a", "g"};
  law.is_extension = false;
  law.log_amplitude = linearLogAmplitude;
  law.starts = linearStarts;
  law.canonical_order = keepOrder;
  law.readout = linearReadout;
  law.kind = RingdownLawKind::kBaseline;
  law.physical_check = linearPhysicalCheck;
  return law;
}

// ---- gamma_nl (rate g0 + g2 A^2) and gamma_a (rate g0 + g1 A): one amplitude-dependent rate ----

/// Starts of gamma_nl (squared) and gamma_a.
std::vector<Eigen::VectorXd> amplitudeDependentStarts(const RingdownFit& lin, bool squared) {
  const auto [a, g] = baselineLevelAndRate(lin);
  std::vector<Eigen::VectorXd> s;
  for (double frac : kAmplitudeDependentFractions) {
    Eigen::VectorXd p(3);
    // Split the rate at the start between g0 and the amplitude-dependent part.
    p << a, g * (1.0 - frac), g * frac * (squared ? std::exp(-2.0 * a) : std::exp(-a));
    s.push_back(p);
  }
  return s;
}

/// Readout of gamma_nl (sq) and gamma_a.
void amplitudeDependentReadout(const RingdownReadout& r, bool sq) {
  RingdownFit& fit = r.fit;
  const std::string model = r.law.name;
  const RingdownValue g0 = r.param(1);
  const RingdownValue gn = r.param(2);
  r.putRate("decay_rate_1_s", g0);
  // Physical coefficient: rate = g0 + gamma_nl A^2 (A in the file's unit), or + gamma_a A.
  fit.parameters[model] = ringdownScaled(gn, 1.0 / (r.T * (sq ? r.a_ref * r.a_ref : r.a_ref)));
  // The model term's coefficient (gamma_nl_conventions.h): 8 times the ring-down's.
  if (sq)
    fit.derived["gamma_nl_term"] =
        ringdownScaled(fit.parameters[model], kGammaNlTermPerRingdownRate);
  r.putQ("Q0", g0);
  const RingdownValue start_rate = r.value(
      [sq](const Eigen::VectorXd& q) { return q(1) + q(2) * std::exp((sq ? 2.0 : 1.0) * q(0)); });
  r.putQ("Q_start", start_rate);
  // Q of the span: the law's mean decay rate over the fitted span (the level it drops over the
  // span per unit time, floor left out), i.e. what a straight line through the same decay
  // gives; the value a ring-down Q is compared by (docs/validation_ringdown_real.md). Q0 is the
  // zero-amplitude limit, Q_start the rate at the span's first sample.
  const double t0 = r.t_first, t1 = r.t_last;
  const RingdownLaw* law = &r.law;
  const RingdownValue span_rate = r.value([law, t0, t1](const Eigen::VectorXd& q) {
    return (law->logAmplitude(q, t0, 0.0) - law->logAmplitude(q, t1, 0.0)) / (t1 - t0);
  });
  r.putQ("Q", span_rate);
  fit.derived["tau_s"] = ringdownQFromRate(span_rate, r.T);
  if (g0.value < 0.0 || start_rate.value < 0.0) fit.flags.push_back("negative_damping");
  if (gn.value < 0.0) fit.flags.push_back("negative_amplitude_dependent_damping");
}

/// Sign check of gamma_nl and gamma_a: both dampings positive.
std::string amplitudeDependentPhysicalCheck(const Eigen::VectorXd& p,
                                            const RingdownPlausibilityOptions&) {
  if (p(1) <= 0.0) return "zero-amplitude damping g0 fitted negative";
  if (p(2) <= 0.0)
    return "amplitude-dependent damping fitted negative (decay accelerates as the amplitude "
           "falls: no physical damping law)";
  return "";
}

bool gammaNlLogAmplitude(const Eigen::VectorXd& p, double t, double& log_a) {
  const double den = 1.0 + 2.0 * p(2) * std::exp(2.0 * p(0)) * oneMinusExpOver(2.0 * p(1), t);
  if (!(den > 0.0)) return false;
  log_a = p(0) - p(1) * t - 0.5 * std::log(den);
  return true;
}

std::vector<Eigen::VectorXd> gammaNlStarts(const RingdownFit& lin) {
  return amplitudeDependentStarts(lin, true);
}

void gammaNlReadout(const RingdownReadout& r) {
  amplitudeDependentReadout(r, true);
}

RingdownLaw gammaNlLaw() {
  RingdownLaw law;
  law.name = "gamma_nl";
  law.parameters = {"a", "g0", "g2"};
  law.is_extension = true;
  law.log_amplitude = gammaNlLogAmplitude;
  law.starts = gammaNlStarts;
  law.canonical_order = keepOrder;
  law.readout = gammaNlReadout;
  law.kind = RingdownLawKind::kAmplitudeLaw;
  law.amplitude_power = 2;
  law.physical_check = amplitudeDependentPhysicalCheck;
  law.cause_text =
      "Damping grows with the amplitude squared (gas or thermoelastic-like loss): Q0 = {Q0} at "
      "zero amplitude, Q = {Q} over the span (its mean decay rate); compare resonators by Q0 or "
      "at one amplitude. ";
  return law;
}

bool gammaALogAmplitude(const Eigen::VectorXd& p, double t, double& log_a) {
  const double den = 1.0 + p(2) * std::exp(p(0)) * oneMinusExpOver(p(1), t);
  if (!(den > 0.0)) return false;
  log_a = p(0) - p(1) * t - std::log(den);
  return true;
}

std::vector<Eigen::VectorXd> gammaAStarts(const RingdownFit& lin) {
  return amplitudeDependentStarts(lin, false);
}

void gammaAReadout(const RingdownReadout& r) {
  amplitudeDependentReadout(r, false);
}

RingdownLaw gammaALaw() {
  RingdownLaw law;
  law.name = "gamma_a";
  law.parameters = {"a", "g0", "g1"};
  law.is_extension = true;
  law.log_amplitude = gammaALogAmplitude;
  law.starts = gammaAStarts;
  law.canonical_order = keepOrder;
  law.readout = gammaAReadout;
  law.kind = RingdownLawKind::kAmplitudeLaw;
  law.amplitude_power = 1;
  law.physical_check = amplitudeDependentPhysicalCheck;
  law.cause_text =
      "Damping grows linearly with the amplitude (clamping or friction-like loss at the mount): "
      "Q0 = {Q0}, Q = {Q} over the span (its mean decay rate); check the clamping. ";
  return law;
}

// ---- beat and two_stage: two modes (a1, d1, a2, d2 [, w, phi]) ----

/// Readout of the two-mode laws; Q from the mode that dominates the span (beat: the larger at the
/// start, mode 1; two_stage: the slow, late stage, mode 2).
void twoModeReadout(const RingdownReadout& r, bool beat) {
  RingdownFit& fit = r.fit;
  const RingdownValue d1 = r.param(1), d2 = r.param(3);
  r.putRate("decay_rate_1_1_s", d1);
  r.putRate("decay_rate_2_1_s", d2);
  r.putQ("Q_mode1", d1);
  r.putQ("Q_mode2", d2);
  const RingdownValue& main = beat ? d1 : d2;
  r.putQ("Q", main);
  fit.derived["tau_s"] = ringdownQFromRate(main, r.T);
  fit.derived["amplitude_ratio"] =
      r.value([](const Eigen::VectorXd& q) { return std::exp(q(2) - q(0)); });
  if (beat) {
    const double T = r.T;
    fit.derived["frequency_split_hz"] = ringdownScaled(r.param(4), 1.0 / (2.0 * M_PI * T));
    fit.derived["frequency_split_rad_s"] = ringdownScaled(r.param(4), 1.0 / T);
    // Difference of the two modes' amplitude decay rates: the 2-D model's damping anisotropy
    // (docs/paper.md: modes along the damping axes decay at gamma +- anisotropy / 2).
    fit.derived["damping_anisotropy_1_s"] =
        r.value([T](const Eigen::VectorXd& q) { return (q(1) - q(3)) / T; });
  }
  if (d1.value < 0.0 || d2.value < 0.0) fit.flags.push_back("negative_damping");
}

bool beatLogAmplitude(const Eigen::VectorXd& p, double t, double& log_a) {
  const double l1 = p(0) - p(1) * t, l2 = p(2) - p(3) * t;
  const double m = std::max(l1, l2);
  const double e1 = std::exp(l1 - m), e2 = std::exp(l2 - m);
  const double pw = e1 * e1 + e2 * e2 + 2.0 * e1 * e2 * std::cos(p(4) * t + p(5));
  if (!(pw > 0.0)) return false;
  log_a = m + 0.5 * std::log(pw);
  return true;
}

/// The linear fit's residuals over [0, t_cut] of the span averaged into at most kBeatMaxBins equal
/// time bins (only the non-empty ones kept, m_used of them), weighted by the error model or not.
struct BinnedResiduals {
  std::vector<double> tt, rr;  ///< mean normalized time and (weighted) residual of each bin
  double w_sum = 0.0;          ///< sum of the bins' mean weights
  int m_used = 0;
};

BinnedResiduals binLinearResiduals(const RingdownFit& lin, bool weighted, double t_cut) {
  const int n = static_cast<int>(lin.t_s.size());
  const int nb = std::min(n, kBeatMaxBins);
  std::vector<double> tt(nb, 0.0), rr(nb, 0.0), ww(nb, 0.0);
  std::vector<int> cnt(nb, 0);
  for (int i = 0; i < n; ++i) {
    const double tn = (lin.t_s[i] - lin.t_ref_s) / lin.t_scale_s;
    if (tn > t_cut) break;
    const int b = std::min(nb - 1, std::max(0, static_cast<int>(tn / t_cut * nb)));
    const double wt = weighted && i < static_cast<int>(lin.weight.size()) ? lin.weight[i] : 1.0;
    tt[b] += tn, rr[b] += wt * (lin.log_amplitude[i] - lin.fitted[i]), ww[b] += wt, ++cnt[b];
  }
  int m_used = 0;
  double w_sum = 0.0;
  for (int b = 0; b < nb; ++b)
    if (cnt[b] > 0) {
      tt[m_used] = tt[b] / cnt[b], rr[m_used] = rr[b] / cnt[b], ww[m_used] = ww[b] / cnt[b];
      w_sum += ww[m_used], ++m_used;
    }
  tt.resize(m_used), rr.resize(m_used);
  BinnedResiduals out;
  out.tt = std::move(tt), out.rr = std::move(rr), out.w_sum = w_sum, out.m_used = m_used;
  return out;
}

/// Local maxima of the residuals' periodogram from kBeatMinCycles cycles per span up to a quarter
/// of the bins' rate, as (power, w), strongest first.
std::vector<std::pair<double, double>> periodogramPeaks(const BinnedResiduals& b) {
  const std::vector<double>&tt = b.tt, &rr = b.rr;
  const int m_used = b.m_used;
  const double w_max = M_PI * m_used / 2.0;
  std::vector<std::pair<double, double>> peaks;  // power, w
  double prev2 = 0, prev1 = 0, w_prev = 0;
  const double dw = kBeatStepW;
  for (double w = kBeatMinCycles * 2 * M_PI; w < w_max; w += dw) {
    double c = 0, sn = 0;
    for (int i = 0; i < m_used; ++i)
      c += rr[i] * std::cos(w * tt[i]), sn += rr[i] * std::sin(w * tt[i]);
    const double pw = c * c + sn * sn;
    if (prev1 > prev2 && prev1 >= pw) peaks.emplace_back(prev1, w_prev);
    prev2 = prev1, prev1 = pw, w_prev = w;
  }
  std::sort(peaks.rbegin(), peaks.rend());
  return peaks;
}

/// The beat start at split w: the residuals' modulation depth m there gives A2/A1 ~ m, and its
/// phase phi.
Eigen::VectorXd beatStartAt(double a, double g, const BinnedResiduals& b, bool weighted, double w) {
  const std::vector<double>&tt = b.tt, &rr = b.rr;
  const int m_used = b.m_used;
  double c = 0, sn = 0;
  for (int i = 0; i < m_used; ++i)
    c += rr[i] * std::cos(w * tt[i]), sn += rr[i] * std::sin(w * tt[i]);
  const double norm = weighted ? std::max(b.w_sum, kTinyWeightSum) : m_used;
  const double m =
      std::min(kBeatMaxDepth, std::max(kBeatMinDepth, 2.0 * std::sqrt(c * c + sn * sn) / norm));
  const double phi = std::atan2(-sn, c);
  Eigen::VectorXd p(6);
  p << a, g, a + std::log(m), g, w, phi;
  return p;
}

// Residual periodogram of the linear fit: peaks between 1.5 cycles per span and a quarter of
// the sample rate (at most 256 cycles per span) give the split w; the modulation depth m
// gives A2/A1 ~ m. The residuals are averaged into at most 1024 equal time bins first. Two
// periodograms: of the residuals as they are, and weighted by the error model (the quiet
// start counts more than the noisy end near the floor), and of the first 40 % of the span only
// (a second mode that decays faster modulates the start alone); the highest peaks of each.
std::vector<Eigen::VectorXd> beatStarts(const RingdownFit& lin) {
  const auto [a, g] = baselineLevelAndRate(lin);
  std::vector<Eigen::VectorXd> s;
  std::vector<double> seen;
  for (int variant = 0; variant < kBeatVariants; ++variant) {
    const bool weighted = variant == 1;
    const double t_cut = variant == 2 ? kBeatEarlyFraction : 1.0;
    const BinnedResiduals bins = binLinearResiduals(lin, weighted, t_cut);
    const std::vector<std::pair<double, double>> peaks = periodogramPeaks(bins);
    int taken = 0;
    for (size_t k = 0;
         k < peaks.size() && taken < (variant == 0 ? kBeatPeaksFirst : kBeatPeaksOther); ++k) {
      const double w = peaks[k].second;
      bool dup = false;
      for (double v : seen) dup |= std::fabs(v - w) < kBeatDuplicateSteps * kBeatStepW;
      if (dup) continue;
      seen.push_back(w), ++taken;
      s.push_back(beatStartAt(a, g, bins, weighted, w));
    }
  }
  if (s.empty()) {
    Eigen::VectorXd p(6);
    p << a, g, a - kBeatFallbackDepth, g, kBeatFallbackW, 0.0;
    s.push_back(p);
  }
  return s;
}

/// Canonical order: component 1 the larger at the start, w >= 0, phi in [-pi, pi].
void beatCanonicalOrder(Eigen::VectorXd& p) {
  if (p(2) > p(0)) {
    std::swap(p(0), p(2));
    std::swap(p(1), p(3));
    p(4) = -p(4), p(5) = -p(5);
  }
  if (p(4) < 0.0) p(4) = -p(4), p(5) = -p(5);
  p(5) = std::remainder(p(5), 2.0 * M_PI);
}

void beatReadout(const RingdownReadout& r) {
  twoModeReadout(r, true);
}

/// Sign check of the beat: both rates positive, two beat periods in the span, a second mode that
/// is not negligible.
std::string beatPhysicalCheck(const Eigen::VectorXd& p, const RingdownPlausibilityOptions& o) {
  if (p(1) <= 0.0 || p(3) <= 0.0) return "a mode's decay rate fitted negative";
  if (p(4) < o.beat_min_split_w) return "under two beat periods in the span (a step is not a beat)";
  if (p(2) - p(0) < std::log(o.beat_min_amplitude_ratio))
    return "second mode below 0.5 % of the first";
  return "";
}

RingdownLaw beatLaw() {
  RingdownLaw law;
  law.name = "beat";
  law.parameters = {"a1", "d1", "a2", "d2", "w", "phi"};
  law.is_extension = true;
  law.log_amplitude = beatLogAmplitude;
  law.starts = beatStarts;
  law.canonical_order = beatCanonicalOrder;
  law.readout = beatReadout;
  law.kind = RingdownLawKind::kShapeAlternative;
  law.searched_frequency = true;
  law.q_checked_against_baseline = true;
  law.physical_check = beatPhysicalCheck;
  law.cause_text =
      "Two close modes beat in this channel: split {frequency_split_hz.value} Hz, Q1 = {Q_mode1}, "
      "Q2 = {Q_mode2} (damping anisotropy {damping_anisotropy_1_s.value} 1/s); the degenerate "
      "pair is split: trim it, or excite along one mode axis. ";
  return law;
}

bool twoStageLogAmplitude(const Eigen::VectorXd& p, double t, double& log_a) {
  const double l1 = p(0) - p(1) * t, l2 = p(2) - p(3) * t;
  const double m = std::max(l1, l2);
  log_a = m + 0.5 * std::log(std::exp(2.0 * (l1 - m)) + std::exp(2.0 * (l2 - m)));
  return true;
}

std::vector<Eigen::VectorXd> twoStageStarts(const RingdownFit& lin) {
  const auto [a, g] = baselineLevelAndRate(lin);
  std::vector<Eigen::VectorXd> s;
  for (double ratio : kTwoStageFastRatios) {
    for (double lvl : kTwoStageSlowLevels) {
      Eigen::VectorXd p(4);
      p << a, g * ratio, a + lvl, g * kTwoStageSlowRateFactor;
      s.push_back(p);
    }
  }
  return s;
}

/// Canonical order: component 1 the faster.
void twoStageCanonicalOrder(Eigen::VectorXd& p) {
  if (p(1) < p(3)) {
    std::swap(p(0), p(2));
    std::swap(p(1), p(3));
  }
}

void twoStageReadout(const RingdownReadout& r) {
  twoModeReadout(r, false);
}

/// Sign check of the two-stage decay: both rates positive, the stages' rates apart.
std::string twoStagePhysicalCheck(const Eigen::VectorXd& p, const RingdownPlausibilityOptions& o) {
  if (p(1) <= 0.0 || p(3) <= 0.0) return "a stage's decay rate fitted negative";
  if (p(1) < o.two_stage_min_rate_ratio * p(3)) return "the two stages' rates differ by under 1.5x";
  return "";
}

RingdownLaw twoStageLaw() {
  RingdownLaw law;
  law.name = "two_stage";
  law.parameters = {"a1", "d1", "a2", "d2"};
  law.is_extension = true;
  law.log_amplitude = twoStageLogAmplitude;
  law.starts = twoStageStarts;
  law.canonical_order = twoStageCanonicalOrder;
  law.readout = twoStageReadout;
  law.kind = RingdownLawKind::kShapeAlternative;
  law.q_checked_against_baseline = true;
  law.physical_check = twoStagePhysicalCheck;
  law.cause_text =
      "Two-stage decay: a fast stage (Q1 = {Q_mode1}) then the slow one (Q2 = {Q_mode2}): a "
      "second mode or a transient after switch-off; quote Q2. ";
  return law;
}

}  // namespace

const std::vector<RingdownLaw>& ringdownLaws() {
  static const std::vector<RingdownLaw> laws = {linearLaw(), gammaNlLaw(), gammaALaw(), beatLaw(),
                                                twoStageLaw()};
  return laws;
}

const RingdownLaw* findRingdownLaw(const std::string& name) {
  for (const RingdownLaw& law : ringdownLaws())
    if (name == law.name) return &law;
  return nullptr;
}

const RingdownLaw& ringdownLaw(const std::string& name) {
  if (const RingdownLaw* law = findRingdownLaw(name)) return *law;
  const std::vector<RingdownLaw>& laws = ringdownLaws();
  std::string known;
  for (size_t k = 0; k < laws.size(); ++k)
    known += (k == 0 ? "" : k + 1 == laws.size() ? " or " : ", ") + std::string(laws[k].name);
  throw InputError("ring-down model '" + name + "' unknown: use " + known);
}

double RingdownLaw::logAmplitude(const Eigen::VectorXd& p, double t, double floor_rel) const {
  double log_a = std::numeric_limits<double>::quiet_NaN();
  if (!log_amplitude(p, t, log_a)) return std::numeric_limits<double>::quiet_NaN();
  if (!(floor_rel > 0.0)) return log_a;
  // Mean of ln|A + n| for circular Gaussian n of rms F (a Rice magnitude): ln A + E1(A^2/F^2) / 2
  // (exact; below ~0.1 A^2/F^2 the floor dominates and the mean tends to ln F - 0.289).
  const double x = std::exp(2.0 * log_a) / (floor_rel * floor_rel);
  if (x > kRiceNegligibleAbove) return log_a;
  if (x < kRiceFloorOnlyBelow) return std::log(floor_rel) - 0.5 * kEulerGamma;
  return log_a + 0.5 * boost::math::expint(1, x);
}

RingdownValue RingdownReadout::param(int k) const {
  return value([k](const Eigen::VectorXd& q) { return q(k); });
}

RingdownValue RingdownReadout::value(
    const std::function<double(const Eigen::VectorXd&)>& fn) const {
  return deltaValue(fn, fit.p, fit.cov_hac, fit.cov_crb, z);
}

void RingdownReadout::putRate(const std::string& name, const RingdownValue& rate) const {
  fit.parameters[name] = ringdownScaled(rate, 1.0 / T);
}

void RingdownReadout::putQ(const std::string& name, const RingdownValue& rate) const {
  if (fit.frequency_hz > 0.0) fit.derived[name] = ringdownQFromRate(rate, qc);
}

RingdownValue ringdownQFromRate(const RingdownValue& rate, double c) {
  RingdownValue q;
  q.value = c / rate.value;
  q.std = c * rate.std / (rate.value * rate.value);
  q.crb_std = c * rate.crb_std / (rate.value * rate.value);
  if (!(rate.value > 0.0)) {
    q.ci_low = -kInf, q.ci_high = kInf;
    return q;
  }
  const double z = rate.std > 0.0 ? (rate.ci_high - rate.value) / rate.std : 0.0;
  const double half = z * rate.std / rate.value;  // half-width of ln Q's interval
  if (!(half >= 0.0) || !std::isfinite(half)) {   // no usable sd (infinite or NaN): unbounded
    q.ci_low = 0.0, q.ci_high = kInf;
    return q;
  }
  q.ci_low = q.value * std::exp(-half);
  q.ci_high = q.value * std::exp(half);
  return q;
}

RingdownValue ringdownScaled(RingdownValue v, double s) {
  v.value *= s, v.std *= std::fabs(s), v.crb_std *= std::fabs(s);
  double lo = v.ci_low * s, hi = v.ci_high * s;
  v.ci_low = std::min(lo, hi), v.ci_high = std::max(lo, hi);
  return v;
}

}  // namespace cvg_bench

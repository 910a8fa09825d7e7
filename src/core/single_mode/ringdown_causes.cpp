#include "cvg_bench/core/single_mode/ringdown_causes.h"

#include <Eigen/Dense>
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include "cvg_bench/core/model/errors.h"
#include "cvg_bench/core/single_mode/ringdown_envelope.h"
#include "cvg_bench/core/single_mode/ringdown_intervals.h"
#include "cvg_bench/core/single_mode/ringdown_models.h"
#include "cvg_bench/core/single_mode/ringdown_span_spread.h"

namespace cvg_bench {
namespace {

const double kInfinity = std::numeric_limits<double>::infinity();

double chi2Upper(int df, double x) {
  if (!(x > 0.0)) return 1.0;
  return boost::math::cdf(boost::math::complement(boost::math::chi_squared(df), x));
}

std::string fmt(double v, int prec = 4) {
  std::ostringstream s;
  s.precision(prec);
  s << v;
  return s.str();
}

/// Physical plausibility (sign checks) of an extension's fit; returns "" when plausible.
std::string signCheck(const RingdownFit& f) {
  const auto& p = f.p;
  if (f.model == "gamma_nl" || f.model == "gamma_a") {
    if (p(1) <= 0.0) return "zero-amplitude damping g0 fitted negative";
    if (p(2) <= 0.0)
      return "amplitude-dependent damping fitted negative (decay accelerates as the amplitude "
             "falls: no physical damping law)";
  } else if (f.model == "beat") {
    if (p(1) <= 0.0 || p(3) <= 0.0) return "a mode's decay rate fitted negative";
    if (p(4) < 4.0 * M_PI) return "under two beat periods in the span (a step is not a beat)";
    if (p(2) - p(0) < std::log(0.005)) return "second mode below 0.5 % of the first";
  } else if (f.model == "two_stage") {
    if (p(1) <= 0.0 || p(3) <= 0.0) return "a stage's decay rate fitted negative";
    if (p(1) < 1.5 * p(3)) return "the two stages' rates differ by under 1.5x";
  }
  return "";
}

/// RMS over the middle 80 % of the span [t.front(), t.back()] (41 points, slopes over 4 % of the
/// span) of the slope of `curve` (sampled at t, Np), over `mean_rate` (Np/s): how far a local decay
/// rate departs from another by `curve`. The middle: on real exports the span's first and last
/// tenths carry the switch-off's settling and the bend towards the floor, which the segmentation
/// bounds, not a damping law (over the whole span, 62 of 154 clean tuning records read as
/// unexplained against 45 over the middle).
double curveRateVariation(const std::vector<double>& t, const std::vector<double>& curve,
                          double mean_rate) {
  const size_t n = t.size();
  if (n < 3 || curve.size() != n) return 0.0;
  const double t0 = t.front(), span_s = t.back() - t0;
  if (!(span_s > 0.0)) return 0.0;
  if (!(mean_rate > 0.0)) return kInfinity;
  auto at = [&](double x) {  // linear interpolation between the samples
    const auto it = std::lower_bound(t.begin(), t.end(), x);
    const size_t j = std::min<size_t>(std::max<size_t>(it - t.begin(), 1), n - 1);
    const double u = (x - t[j - 1]) / (t[j] - t[j - 1]);
    return curve[j - 1] + u * (curve[j] - curve[j - 1]);
  };
  const double h = 0.02 * span_s;
  double ss = 0.0;
  int k = 0;
  for (int j = 0; j <= 40; ++j, ++k) {
    const double x = t0 + span_s * (0.1 + 0.8 * j / 40.0);
    const double rel = (at(x + h) - at(x - h)) / (2.0 * h) / mean_rate;
    ss += rel * rel;
  }
  return std::sqrt(ss / k);
}

/// Mean decay rate of a fit over its span [Np/s] (its fitted level's fall over the span's length).
double meanDecayRate(const RingdownFit& f) {
  if (f.t_s.size() < 2) return 0.0;
  return (f.fitted.front() - f.fitted.back()) / (f.t_s.back() - f.t_s.front());
}

/// Size of the misfit the lack-of-fit test finds: the curve m = X beta / sqrt(w) that the model's
/// own parameter changes plus Legendre P2..P5 fit to the residuals (the Legendre coefficients
/// alone trade against a curved law's columns), as the RMS rate variation of curveRateVariation:
/// how far the local decay rate wanders from the model's, which is what a person reads off a dB
/// plot.
double misfitRateVariation(const Eigen::MatrixXd& X, const Eigen::VectorXd& r,
                           const RingdownFit& fit) {
  const int n = static_cast<int>(r.size());
  if (n < 3 || !X.allFinite() || !r.allFinite()) return 0.0;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(X);
  if (qr.rank() < X.cols()) return 0.0;
  const Eigen::VectorXd fitted_w = X * qr.solve(r);
  std::vector<double> m(n);
  for (int i = 0; i < n; ++i) m[i] = fitted_w(i) / std::sqrt(fit.weight[i]);  // Np
  return curveRateVariation(fit.t_s, m, meanDecayRate(fit));
}

}  // namespace

std::vector<std::string> RingdownExplainOptions::validate() const {
  std::vector<std::string> out = fit.validate();
  if (!(alpha > 0.0 && alpha <= 0.2)) out.push_back("alpha must be in (0, 0.2]");
  if (!(margin >= 0.0) || !(law_margin >= 0.0)) out.push_back("margins must be >= 0");
  if (!(rate_variation >= 0.0 && rate_variation < 1.0))
    out.push_back("rate_variation must be in [0, 1)");
  for (const auto& c : candidates) {
    bool known = false;
    for (const auto& k : ringdownExtensionNames()) known |= k == c;
    if (!known) out.push_back("unknown ring-down candidate '" + c + "'");
  }
  for (const auto& s : segmentation.validate()) out.push_back(s);
  return out;
}

constexpr int kLackOfFitBlocks = 4;

RingdownLackOfFit ringdownLackOfFit(const RingdownFit& fit) {
  RingdownLackOfFit out;
  const int n = fit.n, p = fit.n_params;
  if (n < p + 12) return out;
  const int q = 4;
  Eigen::MatrixXd X(n, p + q);
  Eigen::VectorXd r(n);
  for (int i = 0; i < n; ++i) {
    const double tn = (fit.t_s[i] - fit.t_ref_s) / fit.t_scale_s;
    const double sw = std::sqrt(fit.weight[i]);
    r(i) = sw * (fit.log_amplitude[i] - fit.fitted[i]);
    for (int k = 0; k < p; ++k) {
      const double h = 1e-6 * (1.0 + std::fabs(fit.p(k)));
      Eigen::VectorXd pp = fit.p, pm = fit.p;
      pp(k) += h, pm(k) -= h;
      X(i, k) = sw *
                (ringdownLogAmplitude(fit.model, pp, tn, fit.floor_rel) -
                 ringdownLogAmplitude(fit.model, pm, tn, fit.floor_rel)) /
                (2 * h);
    }
    const double x = 2.0 * tn - 1.0;  // Legendre P2..P5 on [-1, 1]
    const double P2 = 0.5 * (3 * x * x - 1), P3 = 0.5 * (5 * x * x * x - 3 * x);
    const double P4 = (35 * std::pow(x, 4) - 30 * x * x + 3) / 8.0;
    const double P5 = (63 * std::pow(x, 5) - 70 * x * x * x + 15 * x) / 8.0;
    X(i, p) = sw * P2, X(i, p + 1) = sw * P3, X(i, p + 2) = sw * P4, X(i, p + 3) = sw * P5;
  }
  out.p_value = ringdownAddedTermsP(X, r, q);
  out.rate_variation = misfitRateVariation(X, r, fit);
  return out;
}

double ringdownLackOfFitP(const RingdownFit& fit) {
  return ringdownLackOfFit(fit).p_value;
}

double ringdownAddedTermsP(const Eigen::MatrixXd& X, const Eigen::VectorXd& r, int q) {
  const int m = static_cast<int>(X.cols());
  if (!X.allFinite() || !r.allFinite() || q < 1 || q >= m) return 1.0;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(X);
  if (qr.rank() < m) return 1.0;
  const Eigen::VectorXd b = qr.solve(r);
  const Eigen::VectorXd e = r - X * b;
  const Eigen::VectorXd bq = b.tail(q);
  // Structure must be significant under both noise models: one AR model of the whole span, and
  // AR models fitted block by block (the noise changes along a record: relative noise early, the
  // detector's slow floor noise late). Either alone flags clean records where the other holds.
  double p_value = 0.0;
  for (int local = 0; local < 2; ++local) {
    const RingdownCovariance cov =
        local ? ringdownCovarianceLocalAr(X, e, kLackOfFitBlocks) : ringdownCovariance(X, e, false);
    const Eigen::MatrixXd C = cov.covariance.bottomRightCorner(q, q);
    const double w = bq.dot(C.colPivHouseholderQr().solve(bq));
    if (!std::isfinite(w)) continue;  // no usable noise model: that one shows nothing
    p_value = std::max(p_value, chi2Upper(q, w));
  }
  return p_value;
}

namespace {

/// Blocked two-fold hold-out error of a model: the span's used samples in kHoldOutBlocks
/// contiguous blocks, fitted on the even blocks and scored on the odd ones between them and back,
/// started from the full fit. Returns the weighted squared prediction error over all samples (inf
/// on failure).
constexpr int kHoldOutBlocks = 48;
double holdOutError(const RingdownEnvelope& env, const RingdownSegment& seg,
                    const RingdownFit& full, const RingdownFitOptions& base) {
  std::vector<size_t> used;
  for (size_t i = seg.i_start; i < seg.i_end; ++i)
    if (!seg.dropout[i] && std::isfinite(env.log_amplitude[i])) used.push_back(i);
  const size_t n = used.size();
  if (n != full.t_s.size() || n < 4 * kHoldOutBlocks) return kInfinity;
  double err = 0.0;
  for (int fold = 0; fold < 2; ++fold) {
    RingdownFitOptions o = base;
    o.details = false;
    o.hold_out.assign(env.size(), false);
    for (size_t k = 0; k < n; ++k)
      o.hold_out[used[k]] = static_cast<int>(k * kHoldOutBlocks / n) % 2 != fold;
    RingdownFit f;
    try {
      f = fitRingdown(env, seg, full.model, o, {full.p});
    } catch (const AnalysisError&) {
      return kInfinity;
    }
    // Scored between the first and the last fitted sample only: predicting the block before the
    // first fitted one extrapolates a fast first stage backwards, which says nothing of the fit.
    size_t first = n, last = 0;
    for (size_t k = 0; k < n; ++k)
      if (!o.hold_out[used[k]]) first = std::min(first, k), last = k;
    for (size_t k = first; k < last; ++k) {
      if (!o.hold_out[used[k]]) continue;
      const double e = full.log_amplitude[k] - ringdownPredict(f, full.t_s[k]);
      if (!std::isfinite(e)) return kInfinity;
      err += full.weight[k] * e * e;
    }
  }
  return err;
}

bool isAmplitudeLaw(const std::string& c) {
  return c == "gamma_nl" || c == "gamma_a";
}

}  // namespace

RingdownExplanation explainRingdown(const RingdownEnvelope& env,
                                    const RingdownExplainOptions& options) {
  const auto problems = options.validate();
  if (!problems.empty()) throw InputError("ring-down explain: " + problems.front());
  RingdownExplanation x;
  x.segment = segmentRingdown(env, options.segmentation);
  x.baseline = fitRingdown(env, x.segment, "linear", options.fit);
  x.final_fit = x.baseline;
  const int nc = static_cast<int>(options.candidates.size());
  std::vector<RingdownFit> fits(nc);
  std::vector<bool> ok(nc, false);
  // Likelihood under a common AR noise model (generalized least squares): the AR filter of the
  // best-fitting model's residuals (those closest to the noise) whitens every model's weighted
  // residuals, and the criterion is BIC on the whitened sum of squares, so that correlated noise
  // neither counts as independent samples nor hides structure at the beat frequencies.
  const RingdownFit* closest = &x.baseline;
  for (int k = 0; k < nc; ++k) {
    const std::string& c = options.candidates[k];
    try {
      fits[k] = fitRingdown(env, x.segment, c, options.fit, ringdownStarts(c, x.baseline));
      ok[k] = std::isfinite(fits[k].sse_w);
    } catch (const AnalysisError& e) {
      RingdownStep s;
      s.added = c;
      s.note = std::string("fit failed: ") + e.what();
      x.steps.push_back(s);
      continue;
    }
  }
  for (int k = 0; k < nc; ++k)
    if (ok[k] && fits[k].sse_w < closest->sse_w) closest = &fits[k];
  const std::vector<double> ar = closest->noise_ar;
  auto whitenedSse = [&ar](const RingdownFit& f) {
    const size_t m = f.t_s.size();
    std::vector<double> e(m);
    for (size_t i = 0; i < m; ++i)
      e[i] = std::sqrt(f.weight[i]) * (f.log_amplitude[i] - f.fitted[i]);
    double sse = 0.0;
    for (double w : ringdownArWhiten(ar, e)) sse += w * w;
    return sse;
  };
  const double n = static_cast<double>(x.baseline.n);
  const double n_eff = n;
  auto ic = [&](const RingdownFit& f) {
    double pen = f.n_params * std::log(n);
    if (f.model == "beat") pen += 2.0 * std::log(std::max(2.0, n / 4.0));
    return n * std::log(std::max(whitenedSse(f), 1e-300) / n) + pen;
  };
  const double ic_lin = ic(x.baseline);
  x.information_criterion["linear"] = ic_lin;
  std::vector<RingdownStep> steps(nc);
  double ic_law = kInfinity, ic_negative_law = kInfinity;
  std::string negative_law;
  for (int k = 0; k < nc; ++k) {
    if (!ok[k]) continue;
    const RingdownFit& f = fits[k];
    RingdownStep& s = steps[k];
    s.added = options.candidates[k];
    s.n_eff = n_eff;
    s.sigma = f.sigma;
    s.sigma_ratio = x.baseline.sigma / std::max(f.sigma, 1e-300);
    s.lr_statistic =
        n * std::log(std::max(whitenedSse(x.baseline), 1e-300) / std::max(whitenedSse(f), 1e-300));
    s.information_criterion = ic(f);
    s.threshold = s.information_criterion - ic_lin + s.lr_statistic + options.margin;
    s.p_value = chi2Upper(f.n_params - 2, s.lr_statistic);
    s.significant = ic_lin - s.information_criterion > options.margin;
    s.note = signCheck(f);
    s.physical = s.note.empty();
    if (f.fitted.size() == x.baseline.fitted.size()) {
      for (size_t i = 0; i < f.fitted.size(); ++i)
        s.effect_db = std::max(s.effect_db, std::fabs(f.fitted[i] - x.baseline.fitted[i]));
      s.effect_db *= kDbPerNeper;
      s.effect_over_rms = s.effect_db / std::max(x.baseline.rms_log * kDbPerNeper, 1e-300);
    }
    x.information_criterion[s.added] = s.information_criterion;
    if (isAmplitudeLaw(s.added)) {
      if (s.physical)
        ic_law = std::min(ic_law, s.information_criterion);
      else if (f.p(2) < 0.0 && s.information_criterion < ic_negative_law)
        ic_negative_law = s.information_criterion, negative_law = s.added;
    }
  }
  // Ranking: a beat or a two-stage decay must beat every physical amplitude law by the margin
  // beyond its extra parameters; then the lowest criterion among the significant physical ones.
  int best = -1;
  std::vector<bool> eligible(nc, false);
  for (int k = 0; k < nc; ++k) {
    RingdownStep& s = steps[k];
    if (!ok[k]) continue;
    if (!s.significant || !s.physical) {
      if (s.note.empty()) s.note = "criterion not below the single exponential's by the margin";
      continue;
    }
    if (!isAmplitudeLaw(s.added) && ic_law - s.information_criterion < options.law_margin) {
      s.note = "does not beat the amplitude-dependent damping laws by the margin";
      continue;
    }
    eligible[k] = true;
    if (best < 0 || s.information_criterion < steps[best].information_criterion) best = k;
  }
  // The detector's filter from the floor, and the choice between the two amplitude laws re-made
  // through it from the plateau on (ringdown_filter.h): the span skips the filter's settling, which
  // is where a law in A^2 spends its extra rate. A filter taken too slow makes the corner rounder
  // than it is and favours the law with more early rate (and the reverse), so a choice through the
  // filter counts only when it holds with the time constant at 1 / kFilterSpread, 1 and
  // kFilterSpread times its estimate (the estimate's spread on simulated floors).
  x.detector_filter =
      estimateDetectorFilter(env, x.segment, x.baseline.p(1) / x.baseline.t_scale_s);
  const double kFilterSpread = 1.4;
  auto scaledFilter = [&](double s) {
    RingdownDetectorFilter f = x.detector_filter;
    f.time_constant_s *= s;
    return f;
  };
  const double kScales[3] = {1.0, 1.0 / kFilterSpread, kFilterSpread};
  auto icf = [](const RingdownFilteredFit& f) {
    return f.n * std::log(std::max(f.sse_whitened, 1e-300) / f.n) +
           static_cast<double>(f.p.size()) * std::log(static_cast<double>(f.n));
  };
  auto physical = [](const RingdownFilteredFit& f) { return f.ok && f.p(1) > 0.0 && f.p(2) > 0.0; };
  if (best >= 0 && isAmplitudeLaw(steps[best].added)) {
    int rival = -1;
    for (int k = 0; k < nc; ++k)
      if (k != best && ok[k] && isAmplitudeLaw(steps[k].added) && steps[k].physical &&
          steps[k].significant)
        rival = k;
    if (rival < 0) {
      x.law_choice = "the other amplitude law does not pass: no second comparison";
    } else if (!x.detector_filter.found) {
      x.law_choice = "no detector filter estimated: the laws compared on the span alone";
    } else {
      std::ostringstream w;
      w << "through the detector filter (T x 1, 1/" << kFilterSpread << ", " << kFilterSpread
        << "):";
      int votes = 0;
      for (double sc : kScales) {
        const RingdownDetectorFilter filt = scaledFilter(sc);
        const RingdownFilteredFit fb =
            fitRingdownThroughFilter(env, x.segment, fits[best], filt, ar);
        const RingdownFilteredFit fr =
            fitRingdownThroughFilter(env, x.segment, fits[rival], filt, ar);
        const bool pb = physical(fb), pr = physical(fr);
        if (sc == 1.0) {
          if (fb.ok) x.law_choice_sse[fb.model] = fb.sse_whitened;
          if (fr.ok) x.law_choice_sse[fr.model] = fr.sse_whitened;
          w << " from " << fmt(fb.t_start_s) << " s (drive-off fitted at " << fmt(fb.drive_off_s)
            << " s, " << fb.n << " samples)";
        }
        const bool flip = pr && (!pb || fr.sse_whitened < fb.sse_whitened);
        votes += flip;
        w << "; AR-whitened SSE " << fb.model << " " << (fb.ok ? fmt(fb.sse_whitened) : "n/a")
          << (pb ? "" : " (negative damping)") << ", " << fr.model << " "
          << (fr.ok ? fmt(fr.sse_whitened) : "n/a") << (pr ? "" : " (negative damping)");
      }
      w << " -> " << (votes == 3 ? steps[rival].added : steps[best].added)
        << (votes == 3 ? " at every filter" : " (the span's choice; a change needs every filter)");
      if (votes == 3) best = rival;
      x.law_choice = w.str();
    }
  } else if (best < 0 && x.detector_filter.found) {
    // No extension on the span: the amplitude laws against the single exponential once more
    // through the filter from the plateau on (the same criterion and margin on those samples), at
    // each of the three filters; a law is added when the same one wins at all three.
    std::ostringstream w;
    w.precision(6);
    w << "no extension on the span; through the detector filter (T x 1, 1/" << kFilterSpread << ", "
      << kFilterSpread << ") from the plateau on, criteria:";
    int common = -2;
    for (double sc : kScales) {
      const RingdownDetectorFilter filt = scaledFilter(sc);
      const RingdownFilteredFit fl = fitRingdownThroughFilter(env, x.segment, x.baseline, filt, ar);
      int pick = -1;
      if (fl.ok) {
        if (sc == 1.0) x.law_choice_sse["linear"] = fl.sse_whitened;
        w << (sc == 1.0 ? " " : "; ") << "linear " << icf(fl);
        double ic_pick = icf(fl) - options.margin;
        for (int k = 0; k < nc; ++k) {
          if (!ok[k] || !isAmplitudeLaw(steps[k].added) || !steps[k].physical) continue;
          const RingdownFilteredFit f = fitRingdownThroughFilter(env, x.segment, fits[k], filt, ar);
          if (!f.ok || f.n != fl.n) continue;
          if (sc == 1.0) x.law_choice_sse[f.model] = f.sse_whitened;
          w << ", " << f.model << " " << icf(f) << (physical(f) ? "" : " (negative damping)");
          if (physical(f) && icf(f) < ic_pick) ic_pick = icf(f), pick = k;
        }
      }
      common = common == -2 || common == pick ? pick : -1;
    }
    if (common >= 0) {
      best = common;
      steps[common].note =
          "criterion below the single exponential's by the margin through the detector filter "
          "(from the plateau on, at each of the three filters)";
    }
    w << " -> " << (common >= 0 ? steps[common].added : std::string("linear"));
    x.law_choice = w.str();
  }
  // Hold-out confirmation against the single exponential (and, for a beat or a two-stage decay,
  // against the best physical amplitude law); then, for a beat or a two-stage decay, its Q within
  // q_factor of the single exponential's over the same span: one that lies further describes
  // something else than the decay a person reads off the record (on the real development set: a
  // switch-off transient taken for a fast beating mode, a floor taken for a slow second stage);
  // the generator's true beats and two-stage decays stay within it (tuning base 41000000: 29 of 30
  // each). The amplitude laws report Q at zero amplitude, which differs from the line's by design.
  // The rivals' hold-out errors are the same for every candidate tried: computed once, on demand.
  std::optional<double> cv_lin, cv_laws;
  auto confirmCandidate = [&](int k) {
    RingdownStep& s = steps[k];
    s.hold_out_error = holdOutError(env, x.segment, fits[k], options.fit);
    if (!cv_lin) cv_lin = holdOutError(env, x.segment, x.baseline, options.fit);
    double cv_rival = *cv_lin;
    if (!isAmplitudeLaw(s.added)) {
      if (!cv_laws) {
        double m = *cv_lin;
        for (int j = 0; j < nc; ++j)
          if (ok[j] && isAmplitudeLaw(steps[j].added) && steps[j].physical && steps[j].significant)
            m = std::min(m, holdOutError(env, x.segment, fits[j], options.fit));
        cv_laws = m;
      }
      cv_rival = *cv_laws;
    }
    s.hold_out_reference = cv_rival;
    // A beat or a two-stage decay (4 parameters more than the line, a searched split) must
    // predict held-out blocks 10 % better than its rival; an amplitude law (1 more) just better.
    const double factor = isAmplitudeLaw(s.added) ? 1.0 : 0.9;
    if (!(s.hold_out_error < factor * cv_rival)) {
      s.note = "not confirmed on hold-out (blocked two-fold prediction error " +
               fmt(s.hold_out_error) + " vs " + fmt(cv_rival) + ")";
      return false;
    }
    if (!isAmplitudeLaw(s.added)) {
      const auto qe = fits[k].derived.find("Q"), ql = x.baseline.derived.find("Q");
      if (qe != fits[k].derived.end() && ql != x.baseline.derived.end()) {
        const double ratio = qe->second.value / ql->second.value;
        if (!(ratio < options.q_factor && ratio > 1.0 / options.q_factor)) {
          s.note = "Q " + fmt(qe->second.value) + " against the single exponential's " +
                   fmt(ql->second.value) + " over the same span (a factor over " +
                   fmt(options.q_factor) + "): not the decay read off the record";
          return false;
        }
      }
    }
    s.accepted = true;
    return true;
  };
  // Confirmation: the pick and, when it is a beat or a two-stage decay, the other of those two
  // when eligible, in the order of their criterion, until one passes both checks above (a beat
  // rejected as a switch-off transient leaves the two-stage decay that describes the same record
  // its turn; D060 of the development set). The amplitude laws get no second turn: a beat or
  // two-stage decay is eligible only when it beat them by law_margin (letting them in after it
  // named gamma laws on 6 of the development set's clean tuning records).
  std::vector<int> order;
  if (best >= 0) order.push_back(best);
  {
    std::vector<int> rest;
    for (int k = 0; k < nc; ++k)
      if (k != best && eligible[k] && !isAmplitudeLaw(steps[k].added) && best >= 0 &&
          !isAmplitudeLaw(steps[best].added))
        rest.push_back(k);
    std::sort(rest.begin(), rest.end(), [&](int a, int b) {
      return steps[a].information_criterion < steps[b].information_criterion;
    });
    if (best >= 0) order.insert(order.end(), rest.begin(), rest.end());
  }
  best = -1;
  for (const int k : order) {
    if (confirmCandidate(k)) {
      best = k;
      break;
    }
  }
  // Eligible candidates never tried, or tried after the pick: say why they were not selected.
  for (int k = 0; k < nc; ++k)
    if (ok[k] && eligible[k] && k != best && steps[k].note.empty())
      steps[k].note = "criterion above " + (best >= 0 ? steps[best].added + "'s (selected)"
                                                      : std::string("a candidate tried first"));
  for (int k = 0; k < nc; ++k)
    if (ok[k]) x.steps.push_back(steps[k]);
  const RingdownStep* pick = nullptr;
  if (best >= 0) {
    x.selected.push_back(steps[best].added);
    x.final_fit = fits[best];
    for (const auto& s : x.steps)
      if (s.accepted) pick = &s;
  }
  // An amplitude law that fits only with a negative coefficient and beats every physical
  // candidate: the decay accelerates as it falls (no damping law does that).
  double ic_best_physical = ic_lin;
  for (int k = 0; k < nc; ++k)
    if (ok[k] && steps[k].physical)
      ic_best_physical = std::min(ic_best_physical, steps[k].information_criterion);
  if (!(ic_best_physical - ic_negative_law > options.margin)) negative_law.clear();
  // ... and only when the acceleration is large enough to see (the lack of fit's size rule).
  for (int k = 0; k < nc && !negative_law.empty(); ++k) {
    if (!ok[k] || steps[k].added != negative_law) continue;
    std::vector<double> d(fits[k].fitted.size());
    if (d.size() != x.baseline.fitted.size()) break;
    for (size_t i = 0; i < d.size(); ++i) d[i] = fits[k].fitted[i] - x.baseline.fitted[i];
    x.negative_law_rate_variation = curveRateVariation(fits[k].t_s, d, meanDecayRate(x.baseline));
    if (!(x.negative_law_rate_variation > options.rate_variation)) negative_law.clear();
  }
  requirePositiveQ(x.final_fit, x.segment);
  addSpanSpread(env, x.segment, options.fit, &x.final_fit);
  const RingdownLackOfFit lack = ringdownLackOfFit(x.final_fit);
  x.lack_of_fit_p = lack.p_value;
  x.lack_of_fit_rate_variation = lack.rate_variation;
  x.lack_of_fit_test =
      "Wald test of Legendre P2..P5 in time added to the final model's weighted residuals, "
      "significant under both the residuals' AR noise model and AR models fitted in 4 contiguous "
      "blocks";
  // Unexplained only when the misfit is significant and large enough to see: a local decay rate
  // that wanders by under `rate_variation` (RMS) of the mean leaves one Q for the span (real
  // records: a floor that breathes under the decay, a detector not quite log-linear).
  const bool lof =
      x.lack_of_fit_p < options.alpha && x.lack_of_fit_rate_variation > options.rate_variation;
  x.unexplained = lof || (!pick && !negative_law.empty());
  bool negative = false;
  for (const auto& fl : x.final_fit.flags) negative |= fl.rfind("negative", 0) == 0;
  x.adequate = !x.unexplained && !negative;
  const RingdownStep* best_step = pick;
  // Causes and the sentence.
  std::ostringstream cs;
  const auto& fin = x.final_fit;
  auto qtext = [&](const std::string& k) {
    const auto it = fin.derived.find(k);
    if (it == fin.derived.end()) return std::string("n/a (no frequency)");
    return fmt(it->second.value) + " [" + fmt(it->second.ci_low) + ", " + fmt(it->second.ci_high) +
           "]";
  };
  if (x.segment.has_floor) {
    x.causes.push_back("noise_floor");
    cs << "Noise floor at " << fmt(x.segment.floor_log_amplitude * kDbPerNeper) << " dB from "
       << fmt(x.segment.floor_start_s) << " s: the fit stops " << fmt(x.segment.floor_margin_db)
       << " dB above it. ";
  }
  if (x.segment.n_dropouts_in_span > 0) {
    x.causes.push_back("drop_outs");
    cs << x.segment.n_dropouts_in_span << " drop-outs in the decay were left out. ";
  }
  if (best_step) {
    const RingdownStep* best = best_step;
    x.causes.push_back(best->added);
    if (best->added == "gamma_nl")
      cs << "Damping grows with the amplitude squared (gas or thermoelastic-like loss): Q0 = "
         << qtext("Q0") << " at zero amplitude, Q = " << qtext("Q")
         << " over the span (its mean decay rate); compare resonators by Q0 or at one "
            "amplitude. ";
    else if (best->added == "gamma_a")
      cs << "Damping grows linearly with the amplitude (clamping or friction-like loss at the "
            "mount): Q0 = "
         << qtext("Q0") << ", Q = " << qtext("Q")
         << " over the span (its mean decay rate); check the clamping. ";
    else if (best->added == "beat")
      cs << "Two close modes beat in this channel: split "
         << fmt(fin.derived.at("frequency_split_hz").value) << " Hz, Q1 = " << qtext("Q_mode1")
         << ", Q2 = " << qtext("Q_mode2") << " (damping anisotropy "
         << fmt(fin.derived.at("damping_anisotropy_1_s").value)
         << " 1/s); the degenerate pair is split: trim it, or excite along one mode axis. ";
    else if (best->added == "two_stage")
      cs << "Two-stage decay: a fast stage (Q1 = " << qtext("Q_mode1")
         << ") then the slow one (Q2 = " << qtext("Q_mode2")
         << "): a second mode or a transient after switch-off; quote Q2. ";
  }
  if (x.unexplained) {
    x.causes.push_back("unexplained");
    cs << "Unexplained: the decay rate changes along the record without a physical damping law"
       << (negative_law.empty() ? std::string(" (lack-of-fit p = " + fmt(x.lack_of_fit_p, 2) + ")")
                                : std::string(" (an amplitude law fits only with a negative "
                                              "coefficient: the decay accelerates as it falls)"))
       << ": drift of the mode out of the detection band or loss of detection; this Q is not "
          "reliable. ";
  }
  if (!best_step && !x.unexplained)
    cs << "A single exponential decay explains the envelope: Q = " << qtext("Q") << ". ";
  if (!x.unexplained && x.lack_of_fit_p < options.alpha)
    cs << "The residuals still curve (lack-of-fit p = " << fmt(x.lack_of_fit_p, 2)
       << "), but the local decay rate wanders by only "
       << fmt(100.0 * x.lack_of_fit_rate_variation, 2)
       << " % (RMS) of its mean along the span (under " << fmt(100.0 * options.rate_variation, 2)
       << " %): one Q describes it to that precision. ";
  if (negative) cs << "A fitted damping is negative: not an adequate model. ";
  x.cause = cs.str();
  if (!x.cause.empty() && x.cause.back() == ' ') x.cause.pop_back();
  return x;
}

}  // namespace cvg_bench

#include "cvg_bench/core/diagnose/ringdown_causes.h"

#include <Eigen/Dense>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <sstream>

#include "cvg_bench/core/estimate/hac_covariance.h"
#include "cvg_bench/core/estimate/ringdown_models.h"
#include "cvg_bench/core/model/errors.h"

namespace cvg_bench {
namespace {

double chi2Quantile(int df, double p_upper) {
  return boost::math::quantile(boost::math::complement(boost::math::chi_squared(df), p_upper));
}
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
    if (p(4) < 2.0 * M_PI) return "split under one beat period in the span";
    if (p(2) - p(0) < std::log(0.005)) return "second mode below 0.5 % of the first";
  } else if (f.model == "two_stage") {
    if (p(1) <= 0.0 || p(3) <= 0.0) return "a stage's decay rate fitted negative";
    if (p(1) < 1.5 * p(3)) return "the two stages' rates differ by under 1.5x";
  }
  return "";
}

}  // namespace

std::vector<std::string> RingdownExplainOptions::validate() const {
  std::vector<std::string> out = fit.validate();
  if (!(alpha > 0.0 && alpha <= 0.2)) out.push_back("alpha must be in (0, 0.2]");
  for (const auto& c : candidates) {
    bool known = false;
    for (const auto& k : ringdownExtensionNames()) known |= k == c;
    if (!known) out.push_back("unknown ring-down candidate '" + c + "'");
  }
  for (const auto& s : segmentation.validate()) out.push_back(s);
  return out;
}

double ringdownLackOfFitP(const RingdownFit& fit) {
  const int n = fit.n, p = fit.n_params;
  if (n < p + 12) return 1.0;
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
  if (!X.allFinite()) return 1.0;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(X);
  if (qr.rank() < p + q) return 1.0;
  const Eigen::VectorXd b = qr.solve(r);
  const Eigen::VectorXd e = r - X * b;
  const HacCovariance hac = hacCovariance(X, e, -1);
  const Eigen::VectorXd bq = b.tail(q);
  const Eigen::MatrixXd C = hac.covariance.bottomRightCorner(q, q);
  const double w = bq.dot(C.colPivHouseholderQr().solve(bq));
  return chi2Upper(q, w);
}

RingdownExplanation explainRingdown(const RingdownEnvelope& env,
                                    const RingdownExplainOptions& options) {
  const auto problems = options.validate();
  if (!problems.empty()) throw InputError("ring-down explain: " + problems.front());
  RingdownExplanation x;
  x.segment = segmentRingdown(env, options.segmentation);
  x.baseline = fitRingdown(env, x.segment, "linear", options.fit);
  x.final_fit = x.baseline;
  const double alpha_each = options.alpha / std::max<size_t>(1, options.candidates.size());
  const RingdownStep* best = nullptr;
  std::vector<RingdownFit> fits;
  fits.reserve(options.candidates.size());
  std::string negative_law;
  for (const auto& c : options.candidates) {
    RingdownStep s;
    s.added = c;
    try {
      fits.push_back(fitRingdown(env, x.segment, c, options.fit, ringdownStarts(c, x.baseline)));
    } catch (const AnalysisError& e) {
      s.note = std::string("fit failed: ") + e.what();
      x.steps.push_back(s);
      fits.emplace_back();
      continue;
    }
    const RingdownFit& f = fits.back();
    // Variance inflation of the extended fit's residuals (HAC / iid), >= 1.
    const double infl = std::max(
        1.0, f.cov_crb.trace() > 0
                 ? f.cov_hac.diagonal().cwiseQuotient(f.cov_crb.diagonal().cwiseMax(1e-300)).mean()
                 : 1.0);
    s.n_eff = f.n / infl;
    s.sigma = f.sigma;
    s.sigma_ratio = x.baseline.sigma / std::max(f.sigma, 1e-300);
    s.lr_statistic =
        s.n_eff * std::log(std::max(x.baseline.sse_w, 1e-300) / std::max(f.sse_w, 1e-300));
    const int df = f.n_params - 2;
    double a = alpha_each;
    if (c == "beat") a /= std::max(1.0, f.n / 4.0);  // the split was searched over ~n/4 frequencies
    s.threshold = chi2Quantile(df, a);
    s.p_value = chi2Upper(df, s.lr_statistic);
    s.significant = s.lr_statistic > s.threshold;
    s.note = signCheck(f);
    s.physical = s.note.empty();
    s.accepted = s.significant && s.physical;
    if (s.significant && !s.physical && (c == "gamma_nl" || c == "gamma_a") && f.p(2) < 0.0)
      negative_law = c;
    if (!s.significant && s.note.empty()) s.note = "not significant";
    x.steps.push_back(s);
  }
  size_t best_k = 0;
  for (size_t k = 0; k < x.steps.size(); ++k)
    if (x.steps[k].accepted && (!best || x.steps[k].lr_statistic > best->lr_statistic))
      best = &x.steps[k], best_k = k;
  if (best) {
    x.selected.push_back(best->added);
    x.final_fit = fits[best_k];
  }
  x.lack_of_fit_p = ringdownLackOfFitP(x.final_fit);
  x.lack_of_fit_test =
      "HAC Wald test of Legendre P2..P5 in time added to the final model's weighted residuals";
  const bool lof = x.lack_of_fit_p < options.alpha;
  x.unexplained = lof || (!best && !negative_law.empty());
  bool negative = false;
  for (const auto& fl : x.final_fit.flags) negative |= fl.rfind("negative", 0) == 0;
  x.adequate = !x.unexplained && !negative;

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
    cs << "Noise floor at " << fmt(x.segment.floor_log_amplitude * 20.0 / std::log(10.0))
       << " dB from " << fmt(x.segment.floor_start_s) << " s: the fit stops "
       << options.segmentation.floor_margin_db << " dB above it. ";
  }
  if (x.segment.n_dropouts_in_span > 0) {
    x.causes.push_back("drop_outs");
    cs << x.segment.n_dropouts_in_span << " drop-outs in the decay were left out. ";
  }
  if (best) {
    x.causes.push_back(best->added);
    if (best->added == "gamma_nl")
      cs << "Damping grows with the amplitude squared (gas or thermoelastic-like loss): Q0 = "
         << qtext("Q0") << " at zero amplitude, Q = " << qtext("Q")
         << " at the start of the span; compare resonators by Q0 or at one amplitude. ";
    else if (best->added == "gamma_a")
      cs << "Damping grows linearly with the amplitude (clamping or friction-like loss at the "
            "mount): Q0 = "
         << qtext("Q0") << ", Q = " << qtext("Q") << " at the start; check the clamping. ";
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
  if (!best && !x.unexplained)
    cs << "A single exponential decay explains the envelope: Q = " << qtext("Q") << ". ";
  if (negative) cs << "A fitted damping is negative: not an adequate model. ";
  x.cause = cs.str();
  if (!x.cause.empty() && x.cause.back() == ' ') x.cause.pop_back();
  return x;
}

}  // namespace cvg_bench

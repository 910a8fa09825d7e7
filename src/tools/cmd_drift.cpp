// cvg_ident drift: the drift rate theta' of (5.9) (corrected, docs/paper.md item 4-5) at a given
// (r, k, theta) or over a theta grid on [0, pi/2), from an identify JSON (or a flat parameter
// file).
#include <cmath>
#include <iomanip>
#include <iostream>

#include "cli_args.h"
#include "cvg_bench/core/estimate/derived_quantities.h"
#include "cvg_bench/core/estimate/derived_uncertainty.h"
#include "cvg_bench/core/model/errors.h"
#include "cvg_bench/core/model/orbit_elements.h"
#include "cvg_bench/core/model/orbit_rates_chain_rule.h"
#include "cvg_bench/report/estimate_json.h"
#include "cvg_ident_commands.h"

namespace cvg_bench {
namespace tools {

using report::ParameterFile;
using report::readParameterFile;
using report::writeJsonFile;
namespace {

const char* kHelp =
    "usage: cvg_ident drift --params FILE.json [--r R --k K --theta TH | --theta-grid N]\n"
    "                       [--angular-gain K] [--json FILE]\n"
    "Drift rate theta' of (5.9) [rad/s and deg/h] of the wave pattern at amplitude r, quadrature "
    "k\n"
    "(record amplitude units) and pattern angle theta [rad]; default r = 1, k = 0.01, a grid of 8\n"
    "angles on [0, pi/2). Also prints section 4's derived quantities (angular gain K, default "
    "0.4).\n"
    "FILE.json: identify --json, or explain --json (its \"final\" model is used).\n"
    "When the params file carries a covariance (identify --json), every figure gets a confidence\n"
    "interval by the delta method (numerical Jacobian; the file's confidence and interval_dof).\n"
    "At one state (--r --k --theta) it also prints the amplitude envelope's decay rate\n"
    "-2 r'/r of (5.7) and the Q = omega / rate it implies (JSON \"envelope\").\n"
    "example: cvg_ident drift --params est.json --r 0.5 --k 0.1 --theta 0.3\n";

/// The amplitude envelope's decay at one state, from (5.7): rate = -2 r'/r [1/s] and the quality
/// factor Q = omega / rate that a ring-down at this state shows, with the rate's CI (delta method)
/// mapped to Q. Unlike omega / gamma it needs only the combination of gamma, b_c, b_s and n that
/// the record determines (a single standing wave does not separate them, docs/paper.md item 11).
nlohmann::json envelopeDecay(double r, double k, double theta, const UncertainParameters& up,
                             double omega_rad_s) {
  const OrbitElements e{r, k, theta, 0.0};
  const ResonatorModel model = freeOscillationModelOf(up.values);
  const ParameterEstimate rate = deltaMethod(
      [&](const ParameterValues& v) { return -2.0 * orbitRatesOfModel(model, v, e).r_dot / r; },
      up);
  nlohmann::json j = {{"decay_rate_1_s", rate.value},
                      {"Q", omega_rad_s / rate.value},
                      {"method",
                       "amplitude envelope decay -2 r'/r at (r, k, theta), r' by the chain rule "
                       "over the averaged equations of " +
                           model.spec() + " ((5.7) for the paper's terms)"}};
  std::cout << std::setprecision(6) << "envelope decay (" << model.spec() << ") at r = " << r
            << ", k = " << k << ", theta = " << theta << ": -2 r'/r = " << rate.value
            << " 1/s, Q = omega / rate = " << omega_rad_s / rate.value;
  if (!up.cov_names.empty()) {
    j["std_1_s"] = rate.std_error;
    j["ci_low_1_s"] = rate.ci_low;
    j["ci_high_1_s"] = rate.ci_high;
    if (rate.ci_low > 0.0) {
      j["Q_ci_low"] = omega_rad_s / rate.ci_high;
      j["Q_ci_high"] = omega_rad_s / rate.ci_low;
      std::cout << " [" << omega_rad_s / rate.ci_high << ", " << omega_rad_s / rate.ci_low << "]";
    }
  }
  std::cout << "\n";
  return j;
}

}  // namespace

int runDrift(const std::vector<std::string>& argv) {
  const CliArgs args(argv, {"params", "r", "k", "theta", "theta-grid", "json", "angular-gain"}, {});
  if (args.help()) {
    std::cout << kHelp;
    return 0;
  }
  if (!args.positionals().empty())
    throw InputError("unexpected argument '" + args.positionals().front() + "'");
  if (!args.has("params")) throw InputError("--params FILE.json is required");
  if (args.has("theta") && args.has("theta-grid"))
    throw InputError("give either --theta or --theta-grid, not both");
  const ParameterFile pf = readParameterFile(args.get("params"));
  const double r = args.getDouble("r", 1.0), k = args.getDouble("k", 0.01);
  const double gain = args.getDouble("angular-gain", 0.4);
  std::vector<double> thetas;
  if (args.has("theta")) {
    thetas.push_back(args.getDouble("theta", 0.0));
  } else {
    const long n = args.getInt("theta-grid", 8);
    if (n < 1 || n > kMaxThetaGridPoints)
      throw InputError("--theta-grid: need 1.." + std::to_string(kMaxThetaGridPoints) +
                       " pattern angles, got " + std::to_string(n));
    thetas = thetaGrid(n);
  }
  UncertainParameters up;
  up.values = pf.values;
  up.cov_names = pf.cov_names;
  up.covariance = pf.covariance;
  up.dof = pf.dof;
  up.confidence = pf.confidence;
  const bool with_ci = !pf.cov_names.empty();
  // Section 4's figures as identify / explain reported them (each from what the record
  // identifies, e.g. the envelope's Q when gamma is not identified); recomputed from the values
  // only for a file without them (hand-written parameters).
  const bool as_identified = !pf.derived_ci.empty();
  const auto derived =
      as_identified ? pf.derived_ci : deriveQuantitiesWithIntervals(up, pf.omega_rad_s, gain);
  const double to_deg_h = 180.0 / M_PI * 3600.0;
  nlohmann::json out;
  out["omega"] = pf.omega_rad_s;
  out["r"] = r;
  out["k"] = k;
  nlohmann::json dj = nlohmann::json::object(), dci = nlohmann::json::object();
  for (const auto& kv : derived) {
    dj[kv.first] = kv.second.value;
    dci[kv.first] = {{"value", kv.second.value},
                     {"std", kv.second.std_error},
                     {"ci_low", kv.second.ci_low},
                     {"ci_high", kv.second.ci_high}};
  }
  out["derived"] = dj;
  if (with_ci) {
    out["derived_ci"] = dci;
    out["confidence"] = pf.confidence;
  }
  nlohmann::json rows = nlohmann::json::array();
  std::cout << std::fixed << std::setprecision(4);
  std::cout << (as_identified ? "derived (as the params file reports them)"
                              : "derived (section 4, K = " + std::to_string(gain) + ")")
            << (with_ci ? ", +- half-width of the " + std::to_string(pf.confidence) + " CI" : "")
            << ":\n";
  for (const auto& kv : derived) {
    std::cout << "  " << std::setw(24) << kv.first << "  " << kv.second.value;
    if (with_ci) std::cout << "  +- " << kv.second.ci_high - kv.second.value;
    std::cout << "\n";
  }
  std::cout << "drift rate theta' of " << freeOscillationModelOf(up.values).spec()
            << " (chain rule over its averaged equations; (5.9) for the paper's terms) at r = " << r
            << ", k = " << k << ":\n"
            << "  theta [rad]   theta [deg]   drift [rad/s]   drift [deg/h]"
            << (with_ci ? "   +- CI [deg/h]" : "") << "\n";
  for (double th : thetas) {
    const ParameterEstimate rate = driftRateWithInterval(r, k, th, up);
    std::cout << "  " << std::setw(11) << th << "   " << std::setw(11) << th * 180 / M_PI << "   "
              << std::setw(13) << rate.value << "   " << std::setw(13) << rate.value * to_deg_h;
    if (with_ci) std::cout << "   " << std::setw(13) << (rate.ci_high - rate.value) * to_deg_h;
    std::cout << "\n";
    nlohmann::json row = {
        {"theta_rad", th}, {"drift_rad_s", rate.value}, {"drift_deg_h", rate.value * to_deg_h}};
    if (with_ci) {
      row["std_rad_s"] = rate.std_error;
      row["ci_low_rad_s"] = rate.ci_low;
      row["ci_high_rad_s"] = rate.ci_high;
    }
    rows.push_back(row);
  }
  out["drift"] = rows;
  if (thetas.size() == 1) out["envelope"] = envelopeDecay(r, k, thetas.front(), up, pf.omega_rad_s);
  if (args.has("json")) writeJsonFile(out, args.get("json"));
  return 0;
}

}  // namespace tools
}  // namespace cvg_bench

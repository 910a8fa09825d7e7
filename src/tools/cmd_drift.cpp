// cvg_ident drift: the drift rate theta' of (5.9) (corrected, docs/paper.md item 4-5) at a given
// (r, k, theta) or over a theta grid on [0, pi/2), from an identify JSON (or a flat parameter
// file).
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>

#include "bag_input.h"
#include "cli_args.h"
#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/package_resources.h"
#include "cvg_bench/core/diagnose/drift_measurement.h"
#include "cvg_bench/core/estimate/derived_quantities.h"
#include "cvg_bench/core/estimate/uncertainty/derived_uncertainty.h"
#include "cvg_bench/core/io/input_checks.h"
#include "cvg_bench/core/io/record_io.h"
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
    "       cvg_ident drift --params FILE.json --measured RECORD [--walk RAD_S] [--bins N]\n"
    "                       [--png FILE]\n"
    "                       [--angular-gain K] [--json FILE]\n"
    "Drift rate theta' of (5.9) [rad/s and deg/h] of the wave pattern at amplitude r, quadrature "
    "k\n"
    "(record amplitude units) and pattern angle theta [rad]; default the record's median r, k "
    "when\n"
    "the file is explain --json (its measured windows), else r = 1, k = 0.01; a grid of 8\n"
    "angles on [0, pi/2). Also prints section 4's derived quantities (angular gain K, default "
    "0.4).\n"
    "FILE.json: identify --json, or explain --json (its \"final\" model is used).\n"
    "When the params file carries a covariance (identify --json), every figure gets a confidence\n"
    "interval by the delta method (numerical Jacobian; the file's confidence and interval_dof).\n"
    "At one state (--r --k --theta) it also prints the amplitude envelope's decay rate\n"
    "-2 r'/r of (5.7) and the Q = omega / rate it implies (JSON \"envelope\").\n"
    "--measured RECORD: theta'(theta) measured in a whole-angle run (simulate --mode\n"
    "whole_angle; the walk from its # whole_angle_walk_rad_s line or --walk) in --bins theta bins\n"
    "(default 24) beside the model's prediction; harmonics, RMS difference and the residual drift\n"
    "after compensation with the prediction (JSON theta_deg, measured_deg_h, measured_ci,\n"
    "predicted_deg_h, predicted_ci, harmonics, rms_difference_deg_h, ...); --png: the plot of\n"
    "both with their bands and the residual after compensation.\n"
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

/// --measured: theta'(theta) measured in a whole-angle record against the prediction
/// (drift_measurement.h); JSON arrays per theta bin as interfaces.md names them.
int runMeasuredDrift(const CliArgs& args, const UncertainParameters& up) {
  RecordReadOptions ro;
  const std::string path = args.get("measured");
  const AnyRecord any = readRecordInput(path, ro, "");
  if (any.kind != RecordKind::kFreeDecay)
    throw InputError(path + ": --measured needs a slow record t,q1,p1,q2,p2 of a whole-angle run");
  double walk = args.getDouble("walk", 0.0);
  if (!args.has("walk")) {
    const auto it = any.slow.metadata.find("whole_angle_walk_rad_s");
    if (it != any.slow.metadata.end()) {
      // The header line is the walk the simulator wrote; anything else there is an input error
      // (it was read as 0 rad/s before 29 Nov, and every bin's prediction then left it out).
      if (!parseFiniteNumber(it->second, &walk))
        throw InputError(path + ": header '# whole_angle_walk_rad_s': not a finite number: '" +
                         it->second + "' (give the walk with --walk RAD_S)");
    }
  }
  const long bins = args.getInt("bins", 24);
  if (bins < 4 || bins > 3600) throw InputError("--bins: need 4..3600 theta bins");
  const DriftComparison c = measureDrift(any.slow, walk, up, static_cast<int>(bins), up.confidence);
  const double dh = 180.0 / M_PI * 3600.0;
  nlohmann::json j;
  nlohmann::json th = nlohmann::json::array(), m = nlohmann::json::array(),
                 mci = nlohmann::json::array(), p = nlohmann::json::array(),
                 pci = nlohmann::json::array(), passes = nlohmann::json::array();
  std::cout << std::setprecision(5) << c.summary << "\n  theta [deg]   measured [deg/h]   "
            << "predicted [deg/h]\n";
  for (const auto& b : c.bins) {
    th.push_back(b.theta_rad * 180.0 / M_PI);
    passes.push_back(b.passes);
    if (b.measured_ok) {
      m.push_back(b.measured.value * dh);
      mci.push_back({b.measured.ci_low * dh, b.measured.ci_high * dh});
    } else {
      m.push_back(nullptr);
      mci.push_back(nullptr);
    }
    p.push_back(b.predicted.value * dh);
    pci.push_back({b.predicted.ci_low * dh, b.predicted.ci_high * dh});
    std::cout << "  " << std::setw(11) << b.theta_rad * 180 / M_PI << "   " << std::setw(16)
              << (b.measured_ok ? std::to_string(b.measured.value * dh) : std::string("-")) << "   "
              << std::setw(16) << b.predicted.value * dh << "\n";
  }
  auto harm = [&](const DriftHarmonics& h) {
    return nlohmann::json{{"c0_deg_h", h.c0 * dh},
                          {"cos4_deg_h", h.a4 * dh},
                          {"sin4_deg_h", h.b4 * dh},
                          {"amp4_deg_h", std::hypot(h.a4, h.b4) * dh},
                          {"cos8_deg_h", h.a8 * dh},
                          {"sin8_deg_h", h.b8 * dh},
                          {"amp8_deg_h", std::hypot(h.a8, h.b8) * dh}};
  };
  j["theta_deg"] = th;
  j["measured_deg_h"] = m;
  j["measured_ci"] = mci;
  j["predicted_deg_h"] = p;
  j["predicted_ci"] = pci;
  j["passes"] = passes;
  j["harmonics"] = {{"measured", harm(c.measured_harmonics)},
                    {"predicted", harm(c.predicted_harmonics)},
                    {"residual", harm(c.residual_harmonics)},
                    {"note",
                     "theta is defined modulo pi/2: the drift's harmonics are 4 theta and "
                     "8 theta (2 theta and 4 theta of the oscillation plane 2 theta)"}};
  j["rms_measured_deg_h"] = c.rms_measured_rad_s * dh;
  j["rms_difference_deg_h"] = c.rms_difference_rad_s * dh;
  j["residual_after_compensation_deg_h"] = c.rms_difference_rad_s * dh;
  j["compensation_gain"] = c.rms_difference_rad_s > 0
                               ? nlohmann::json(c.rms_measured_rad_s / c.rms_difference_rad_s)
                               : nlohmann::json(nullptr);
  j["r"] = c.r;
  j["k"] = c.k;
  j["walk_deg_h"] = c.walk_rad_s * dh;
  j["model"] = c.model;
  j["confidence"] = up.confidence;
  j["method"] =
      "measured: slopes of the unwrapped pattern angle over passes through each theta bin, walk "
      "subtracted, inverse-variance mean of the passes; slope errors from the noise pooled over "
      "all passes (AR(1) long-run factor), widened by the passes' scatter ratio where they "
      "scatter more; predicted: theta' of the model by the chain rule at the run's median r, k, "
      "harmonic mean of walk + theta' across each bin less the walk (what a pass measures), "
      "delta-method interval";
  j["noise_lag1"] = c.noise_lag1;
  j["pass_scatter_ratio"] = c.pass_scatter_ratio;
  j["pass_scatter_dof"] = c.pass_scatter_dof;
  if (args.has("json")) writeJsonFile(j, args.get("json"));
  if (args.has("png")) {
    // The angle-dependent drift plot (scripts/drift_plot.py) from this JSON.
    const std::string png = args.get("png");
    requireOutputFile(png, "--png");
    const std::string json_path = png + ".json";
    writeJsonFile(j, json_path);
    std::string script = executableDirectory() + "/drift_plot.py";
    if (!std::filesystem::is_regular_file(script))
      script = findPackageResource("scripts/drift_plot.py");
    const std::string cmd = "/usr/bin/python3 '" + script + "' '" + json_path + "' '" + png + "'";
    const int rc = std::system(cmd.c_str());
    std::filesystem::remove(json_path);
    if (rc != 0)
      std::cerr << "cvg_ident drift: the plot was not made (" << cmd << ")\n";
    else
      std::cout << "plot: " << png << "\n";
  }
  return 0;
}

int runDrift(const std::vector<std::string>& argv) {
  const CliArgs args(argv,
                     {"params", "r", "k", "theta", "theta-grid", "json", "angular-gain", "measured",
                      "walk", "bins", "png"},
                     {});
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
  // Default state: the record's own (median r, k of explain's measured windows), so that the
  // table is comparable with the measured rate; r = 1, k = 0.01 for other files.
  const double r = args.getDouble("r", pf.has_record_state ? pf.record_r : 1.0);
  const double k = args.getDouble("k", pf.has_record_state ? pf.record_k : 0.01);
  if (pf.has_record_state && !args.has("r") && !args.has("k") && !args.has("measured"))
    std::cout << "state: the record's median amplitude r = " << pf.record_r
              << " and quadrature k = " << pf.record_k
              << " (explain's measured windows; --r, --k for another)\n";
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
  const UncertainParameters up = report::uncertainParameters(pf);
  const bool with_ci = !pf.cov_names.empty();
  if (args.has("measured")) return runMeasuredDrift(args, up);
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

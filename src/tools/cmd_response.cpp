// cvg_ident identify / explain / simulate with --mode response: one mode's frequency response
// (docs/interfaces.md, "One-mode frequency response"; docs/response.md). Reader:
// core/io/response_record.h; model, fit and selection: core/single_mode/response_*.h; generator:
// core/simulate/response_simulator.h.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "cli_args.h"
#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/io/response_record.h"
#include "cvg_bench/core/simulate/response_simulator.h"
#include "cvg_bench/core/single_mode/response_explain.h"
#include "cvg_bench/core/single_mode/response_laws.h"
#include "cvg_bench/report/estimate_json.h"
#include "cvg_bench/report/response_json.h"
#include "cvg_ident_commands.h"
#include "report_directory.h"

namespace cvg_bench {
namespace tools {
namespace {

const char* kIdentifyHelp =
    "usage: cvg_ident identify INPUT --mode response [--model linear|xi|gamma_nl|xi+gamma_nl]\n"
    "         [--columns t=N,frequency_hz=N,x=N,y=N,drive=N] [--response displacement|velocity]\n"
    "         [--confidence P] [--json FILE]\n"
    "One mode's complex response Z = x + iy against drive frequency (lock-in, network analyser),\n"
    "all drive levels and up/down sweeps of the file fitted at once by output error, following "
    "the\n"
    "branch along each sweep in time order (jumps, hysteresis). INPUT: CSV or whitespace columns,\n"
    "'#'/'%' comments; named columns t, frequency_hz, x, y, drive (per point), direction; a\n"
    "headerless file through --columns (1-based; without it 5 columns are "
    "t,frequency_hz,x,y,drive).\n"
    "Prints f0, width (FWHM) and Q, and with xi the backbone (Hz per amplitude^2, amplitude in "
    "the\n"
    "x, y unit), with gamma_nl the width growth (Hz per amplitude^2, either sign). Intervals: a\n"
    "jackknife over whole sweeps (5 or more sweeps), else a within-sweep sandwich.\n"
    "--response velocity: the lock-in sees the velocity (e.g. a wire's induced voltage).\n"
    "Exit 1 when no resonance can be fitted; 2 on bad input.\n";

const char* kExplainHelp =
    "usage: cvg_ident explain INPUT --mode response [--columns ...] [--response KIND]\n"
    "         [--confidence P] [--alpha A] [--json FILE] [--report DIR] [--no-figures]\n"
    "Which amplitude law the response shows: linear, a backbone (xi), a width changing with\n"
    "amplitude (gamma_nl, either sign), both, or unexplained (the drive levels differ in a way no\n"
    "law follows). --report DIR writes the data, every candidate's response and (unless\n"
    "--no-figures) the figures: amplitude and phase per drive level (up and down in two colours),\n"
    "the backbone, the residuals.\n";

const char* kSimulateHelp =
    "usage: cvg_ident simulate --mode response --out FILE [--f0 HZ] [--q Q] [--levels N]\n"
    "         [--max-amplitude A] [--effect xi=V] [--effect gamma_nl=V] [--noise SD]\n"
    "         [--correlation RHO] [--f0-drift-hz SD] [--background RE,IM] [--background-slope\n"
    "         RE,IM] [--response displacement|velocity] [--conjugate] [--saturation A]\n"
    "         [--sweeps-per-level N] [--points N] [--span-widths W] [--seed N]\n"
    "A lock-in record of one mode driven at N levels, up and down sweeps, integrated in time\n"
    "(x'' + 2 pi w(x) x' + (2 pi f0)^2 x + k3 x^3 = F cos(2 pi f t)) and demodulated; the truth\n"
    "goes to '#' lines (f0_hz, width_hz, Q, backbone_hz_per_amp2, width_growth_hz_per_amp2).\n";

/// The generator's coefficient of a term (its options name them like ResponseParams).
double& effectOf(ResponseSimulatorOptions& o, const ResponseLaw& law) {
  if (law.coefficient == &ResponseParams::backbone_hz_per_amp2) return o.backbone_hz_per_amp2;
  if (law.coefficient == &ResponseParams::width_growth_hz_per_amp2)
    return o.width_growth_hz_per_amp2;
  throw std::logic_error(std::string("--effect ") + law.name + ": the generator has no such term");
}

/// The terms' names as --effect's message lists them: "a, b and c".
std::string effectNames() {
  const std::vector<ResponseLaw>& laws = responseLaws();
  std::string s;
  for (size_t i = 0; i < laws.size(); ++i)
    s += (i == 0 ? "" : i + 1 == laws.size() ? " and " : ", ") + std::string(laws[i].name);
  return s;
}

ResponseRecord readInput(const CliArgs& args, std::vector<std::string>& notes) {
  if (args.positionals().size() != 1) throw InputError("exactly one INPUT file is needed");
  ResponseRecord r = readResponseFile(args.positionals().front(), args.get("columns"));
  notes.insert(notes.end(), r.notes.begin(), r.notes.end());
  return r;
}

ResponseKind kindOf(const CliArgs& args, std::vector<std::string>& notes) {
  if (args.has("response")) return parseResponseKind(args.get("response"));
  notes.push_back(
      "--response not given: displacement assumed (velocity for a wire's or a coil's "
      "induced voltage)");
  return ResponseKind::kDisplacement;
}

void printFit(const ResponseFit& f, std::ostream& os) {
  os << "mode response, model " << f.terms.name() << ", " << f.n_points << " points, " << f.n_sweeps
     << " sweeps, " << f.n_drive_levels << " drive levels, response " << responseKindName(f.kind)
     << "\n";
  char buf[200];
  std::vector<const char*> keys = {"f0_hz", "width_hz", "Q"};
  for (const ResponseLaw& law : responseLaws()) keys.push_back(law.derived_key);
  for (const ResponseLaw& law : responseLaws())
    if (law.model_term_key) keys.push_back(law.model_term_key);
  for (const char* k : keys) {
    const auto it = f.derived.find(k);
    if (it == f.derived.end()) continue;
    if (std::find(f.not_determined.begin(), f.not_determined.end(), k) != f.not_determined.end()) {
      std::snprintf(buf, sizeof(buf), "  %-26s not determined by these data\n", k);
    } else {
      std::snprintf(buf, sizeof(buf), "  %-26s %14.8g  [%.8g, %.8g]\n", k, it->second.value,
                    it->second.ci_low, it->second.ci_high);
    }
    os << buf;
  }
  os << "intervals: " << f.interval_method << "; residual lag-1 correlation " << f.residual_lag1
     << "; jumps " << f.jumps << "\n";
  for (const auto& n : f.notes) os << "note: " << n << "\n";
}

/// Data of the report (read by scripts/response_report.py): the points and every candidate's
/// response.
void writeReport(const std::string& dir, const nlohmann::json& j, const ResponseRecord& r,
                 const ResponseData& d, const ResponseExplanation& x) {
  makeReportDirectory(dir);
  report::writeJsonFile(j, dir + "/explain.json");
  std::ofstream out(dir + "/response_points.csv");
  out << std::setprecision(12) << "t,frequency_hz,drive,sweep,x,y";
  for (const auto& c : x.candidates) {
    std::string name = c.fit.terms.name();
    std::replace(name.begin(), name.end(), '+', '_');  // xi+gamma_nl -> xi_gamma_nl
    out << ",x_" << name << ",y_" << name << ",u_" << name;
  }
  out << "\n";
  for (size_t i = 0; i < r.size(); ++i) {
    out << r.t_s[i] << "," << r.frequency_hz[i] << "," << r.drive[i] << "," << d.sweep[i] << ","
        << r.x[i] << "," << r.y[i];
    for (const auto& c : x.candidates)
      out << "," << c.fit.model[i].real() << "," << c.fit.model[i].imag() << "," << c.fit.u[i];
    out << "\n";
  }
}

}  // namespace

int runResponseIdentify(const std::vector<std::string>& argv) {
  const CliArgs args(argv, {"mode", "model", "columns", "response", "confidence", "json"}, {});
  if (args.help()) {
    std::cout << kIdentifyHelp;
    return 0;
  }
  std::vector<std::string> notes;
  const ResponseRecord rec = readInput(args, notes);
  ResponseFitOptions o;
  o.kind = kindOf(args, notes);
  o.confidence = args.getDouble("confidence", 0.95);
  if (!(o.confidence > 0 && o.confidence < 1)) throw InputError("--confidence must lie in (0, 1)");
  const ResponseTerms terms = parseResponseTerms(args.get("model", kLinearResponseModel));
  const ResponseFit fit = fitResponse(responseDataOf(rec, o.kind), terms, o);
  for (const auto& n : notes) std::cout << "note: " << n << "\n";
  printFit(fit, std::cout);
  if (args.has("json"))
    report::writeJsonFile(report::responseFitToJson(fit, o.confidence, notes), args.get("json"));
  return 0;
}

int runResponseExplain(const std::vector<std::string>& argv) {
  const CliArgs args(argv, {"mode", "columns", "response", "confidence", "json", "report", "alpha"},
                     {"no-figures"});
  if (args.help()) {
    std::cout << kExplainHelp;
    return 0;
  }
  std::vector<std::string> notes;
  const ResponseRecord rec = readInput(args, notes);
  ResponseExplainOptions o;
  o.fit.kind = kindOf(args, notes);
  o.fit.confidence = args.getDouble("confidence", 0.95);
  o.alpha = args.getDouble("alpha", o.alpha);
  if (!(o.fit.confidence > 0 && o.fit.confidence < 1))
    throw InputError("--confidence must lie in (0, 1)");
  if (!(o.alpha > 0 && o.alpha < 0.5)) throw InputError("--alpha must lie in (0, 0.5)");
  const ResponseData data = responseDataOf(rec, o.fit.kind);
  const ResponseExplanation x = explainResponse(data, o);
  for (const auto& n : notes) std::cout << "note: " << n << "\n";
  for (const auto& c : x.candidates) {
    std::cout << "candidate " << std::setw(12) << std::left << c.fit.terms.name() << " rss "
              << c.fit.rss;
    for (const auto& p : c.p_values)
      std::cout << "  p(" << p.first << ") " << p.second << " effect/width "
                << c.effect_over_width.at(p.first);
    std::cout << "\n";
  }
  std::cout << "selected: " << x.selected << (x.unexplained ? " (unexplained)" : "") << "\n"
            << "adequacy: " << x.adequacy_test << ": " << x.adequacy_ratio << " (threshold "
            << x.adequacy_threshold << ")\n"
            << "verdict: " << x.verdict << "\n";
  printFit(x.candidates[x.selected_index].fit, std::cout);
  const nlohmann::json j = report::responseExplanationToJson(x, o.fit.confidence, notes);
  if (args.has("json")) report::writeJsonFile(j, args.get("json"));
  if (args.has("report")) {
    const std::string dir = args.get("report");
    writeReport(dir, j, rec, data, x);
    if (!args.has("no-figures")) {
      const std::string cmd = "/usr/bin/python3 '" + std::string(CVG_BENCH_SOURCE_DIR) +
                              "/scripts/response_report.py' '" + dir + "'";
      if (std::system(cmd.c_str()) != 0)
        std::cerr << "cvg_ident explain: figures not drawn (" << cmd << " failed)\n";
    }
  }
  return 0;
}

int runResponseSimulate(const std::vector<std::string>& argv) {
  const CliArgs args(argv,
                     {"mode", "out", "f0", "q", "levels", "max-amplitude", "noise", "correlation",
                      "f0-drift-hz", "background", "background-slope", "response", "saturation",
                      "sweeps-per-level", "points", "span-widths", "seed"},
                     {"conjugate"}, {"effect"});
  if (args.help()) {
    std::cout << kSimulateHelp;
    return 0;
  }
  if (!args.has("out")) throw InputError("--out FILE is required");
  ResponseSimulatorOptions o;
  o.f0_hz = args.getDouble("f0", o.f0_hz);
  o.q = args.getDouble("q", o.q);
  o.levels = static_cast<int>(args.getInt("levels", o.levels));
  o.max_amplitude = args.getDouble("max-amplitude", o.max_amplitude);
  o.noise = args.getDouble("noise", o.noise);
  o.correlation = args.getDouble("correlation", o.correlation);
  o.f0_drift_hz = args.getDouble("f0-drift-hz", o.f0_drift_hz);
  o.saturation_amplitude = args.getDouble("saturation", o.saturation_amplitude);
  o.sweeps_per_level = static_cast<int>(args.getInt("sweeps-per-level", o.sweeps_per_level));
  o.points_per_sweep = static_cast<int>(args.getInt("points", o.points_per_sweep));
  o.span_widths = args.getDouble("span-widths", o.span_widths);
  o.seed = static_cast<unsigned>(args.getInt("seed", o.seed));
  o.conjugate = args.has("conjugate");
  if (args.has("response")) o.kind = parseResponseKind(args.get("response"));
  auto complexArg = [&](const char* key, std::complex<double>& c) {
    if (!args.has(key)) return;
    double re = 0, im = 0;
    char comma = 0;
    std::istringstream ss(args.get(key));
    if (!(ss >> re >> comma >> im) || comma != ',')
      throw InputError(std::string("--") + key + ": give RE,IM");
    c = {re, im};
  };
  complexArg("background", o.background);
  complexArg("background-slope", o.background_slope_per_hz);
  for (const std::string& e : args.getAll("effect")) {
    const size_t eq = e.find('=');
    const std::string k = e.substr(0, eq);
    const double v = eq == std::string::npos ? NAN : std::atof(e.c_str() + eq + 1);
    if (!std::isfinite(v)) throw InputError("--effect " + e + ": give NAME=VALUE");
    const ResponseLaw* law = findResponseLaw(k);
    if (!law) throw InputError("--effect " + k + ": one-mode effects are " + effectNames());
    effectOf(o, *law) = v;
  }
  const ResponseRecord rec = simulateResponse(o);
  std::ofstream out(args.get("out"));
  if (!out) throw InputError("--out: cannot write '" + args.get("out") + "'");
  writeResponseCsv(rec, out);
  return 0;
}

}  // namespace tools
}  // namespace cvg_bench

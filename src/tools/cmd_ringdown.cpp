// cvg_ident identify / explain / simulate with --mode ringdown: single-channel ring-downs
// (interfaces.md, "Single-channel ring-downs"). Reader: core/io/ringdown_record.h; segmentation and
// fit: core/single_mode/ringdown_*.h; causes: core/single_mode/ringdown_causes.h; generator:
// core/simulate/ringdown_simulator.h.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "bag_input.h"
#include "cli_args.h"
#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/io/ringdown_record.h"
#include "cvg_bench/core/simulate/ringdown_simulator.h"
#include "cvg_bench/core/single_mode/ringdown_causes.h"
#include "cvg_bench/core/single_mode/ringdown_envelope.h"
#include "cvg_bench/core/single_mode/ringdown_laws.h"
#include "cvg_bench/core/single_mode/ringdown_span_spread.h"
#include "cvg_bench/report/estimate_json.h"
#include "cvg_bench/report/ringdown_json.h"
#include "cvg_ident_commands.h"
#include "report_directory.h"

namespace cvg_bench {
namespace tools {
namespace {

const char* kIdentifyHelp =
    "usage: cvg_ident identify INPUT --mode ringdown --model linear|TERMS [--frequency HZ]\n"
    "         [--confidence P] [--error-model auto|log|additive] [--floor-margin-db D]\n"
    "         [--q-bins N] [--method ceres] [--json FILE]\n"
    "Q of one channel's ring-down. INPUT: CSV with t and amplitude (linear) or power_db (dBm, "
    "dBV,\n"
    "any offset), '#'/'%' comment lines (frequency_hz: F, Frequency [Hz]: F or omega: W), ',' ';'\n"
    "or tab separated; or a raw waveform t,f (demodulated first); or a .bag of the project's\n"
    "messages (channel 1 amplitude). The drive switch-off, the noise floor and drop-outs are "
    "found\n"
    "and only the decay above the floor is fitted (the output says which span and why).\n"
    "TERMS: linear, gamma_nl (damping + gamma_nl A^2), gamma_a (+ gamma_a A), beat (two close\n"
    "modes), two_stage. Q = omega tau / 2 = pi f tau (tau: amplitude time constant); the interval\n"
    "is HAC (correlated residuals), the Cramer-Rao bound is printed beside it. Every fit is\n"
    "weighted least squares on ln A solved by Ceres (--method ceres or wls_log; others exit 2).\n"
    "Exit 1 when there is no decay to fit; 2 on bad input.\n";

const char* kExplainHelp =
    "usage: cvg_ident explain INPUT --mode ringdown [--frequency HZ] [--json FILE] [--report DIR]\n"
    "         [--confidence P] [--alpha A] [--rate-variation F]\n"
    "         [--candidates gamma_nl,gamma_a,beat,two_stage] [--error-model auto|log|additive]\n"
    "         [--method ceres] [--no-figures]\n"
    "What the ring-down shows besides Q: amplitude-dependent damping (gamma_nl: A^2 law, gamma_a:\n"
    "A law), a beat of two close modes (split and both decay rates), a two-stage decay, the noise\n"
    "floor and drop-outs, and 'unexplained' when the rate changes without a physical law: the\n"
    "lack-of-fit test is significant at --alpha (1e-5) and the curve it adds moves the local\n"
    "decay rate by more than --rate-variation (0.10, RMS) of the span's mean rate. Every\n"
    "fitted damping is sign-checked. --report DIR writes the data and (unless --no-figures) the\n"
    "figures: envelope in dB with the model and span, residuals, Q against amplitude.\n";

const char* kSimulateHelp =
    "usage: cvg_ident simulate --mode ringdown --out FILE [--frequency HZ] [--q Q] [--amplitude "
    "A]\n"
    "         [--scale linear|db] [--db-offset D] [--samples N] [--duration-s S] [--plateau-s S]\n"
    "         [--noise-db D] [--floor-db D] [--correlation RHO] [--dropouts N]\n"
    "         [--split-hz F --second-amplitude R [--q2 Q]] [--two-stage-ratio R [--q-fast Q]]\n"
    "         [--detection-loss-db D] [--effect gamma_nl=V] [--effect gamma_a=V] [--seed N]\n"
    "Writes a single-channel ring-down (plateau, decay, floor, drop-outs) as t,amplitude or\n"
    "t,power_db with '# frequency_hz:'. gamma_nl [1/(s unit^2)], gamma_a [1/(s unit)].\n";

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

/// The generator's coefficient of a ring-down law (--effect NAME=V): an amplitude law's, by the
/// power of A in its rate (the generator's dA/dt = -(g0 + gamma_nl A^2 + gamma_a A) A); nullptr
/// for a law the generator has no coefficient of.
double* simulatedCoefficient(const RingdownLaw& law, RingdownSimulationOptions& o) {
  if (law.kind != RingdownLawKind::kAmplitudeLaw) return nullptr;
  if (law.amplitude_power == 2) return &o.gamma_nl;
  if (law.amplitude_power == 1) return &o.gamma_a;
  return nullptr;
}

/// The laws --effect takes, as the message lists them ("a or b", "a, b or c").
std::string simulatedLawNames() {
  RingdownSimulationOptions probe;
  std::vector<std::string> names;
  for (const RingdownLaw& law : ringdownLaws())
    if (simulatedCoefficient(law, probe)) names.push_back(law.name);
  std::string out;
  for (size_t k = 0; k < names.size(); ++k)
    out += (k == 0 ? "" : k + 1 == names.size() ? " or " : ", ") + names[k];
  return out;
}

/// The envelope of INPUT: a ring-down CSV, or a bag of the project's messages.
RingdownEnvelope readEnvelope(const std::string& path, double frequency_hz,
                              std::vector<std::string>& notes) {
  RingdownRecord rec;
  if (isBagInput(path)) {
    const AnyRecord any = readRecordInput(path, {}, "", {RecordKind::kFreeDecay, RecordKind::kRaw});
    rec.source = path;
    if (any.kind == RecordKind::kRaw) {
      rec.kind = RingdownValueKind::kRawWaveform;
      rec.t_s = any.raw.t_s;
      rec.value = any.raw.f;
      rec.frequency_hz = any.raw.omega_rad_s / (2.0 * M_PI);
      notes.push_back("bag raw samples: channel f used as the single channel");
    } else {
      rec.kind = RingdownValueKind::kAmplitude;
      rec.t_s = any.slow.t_s;
      for (const auto& q : any.slow.q) rec.value.push_back(std::hypot(q[0], q[1]));
      rec.frequency_hz = any.slow.omega_rad_s / (2.0 * M_PI);
      notes.push_back("bag slow states: amplitude sqrt(q1^2 + p1^2) of channel 1");
    }
  } else {
    rec = readRingdownCsv(path);
  }
  RingdownEnvelope env = ringdownEnvelope(rec, frequency_hz);
  for (const auto& n : env.notes) notes.push_back(n);
  if (!(env.frequency_hz > 0.0))
    notes.push_back(
        "no frequency (give --frequency HZ or a 'frequency_hz:' line): Q not computed, "
        "tau_s only");
  return env;
}

std::string ci(const RingdownValue& v) {
  char buf[160];
  std::snprintf(buf, sizeof(buf), "%.6g  [%.6g, %.6g]  std %.3g", v.value, v.ci_low, v.ci_high,
                v.std);
  std::string s = buf;
  if (v.crb_std > 0.0) {
    std::snprintf(buf, sizeof(buf), "  (Cramer-Rao std %.3g)", v.crb_std);
    s += buf;
  }
  return s;
}

void printFit(const RingdownFit& f, const RingdownSegment& seg, std::ostream& os) {
  os << "mode ringdown, model " << f.model << ", frequency " << f.frequency_hz << " Hz\n";
  os << "span " << seg.t_start_s << " .. " << seg.t_end_s << " s: " << seg.why << "\n";
  os << "error model: " << f.error_model << " (" << f.error_model_why << ")\n";
  os << "n " << f.n << ", rms residual " << f.rms_log * kDbPerNeper << " dB, lag-1 correlation "
     << f.rho1 << "\n";
  for (const auto& kv : f.parameters)
    os << "  " << std::setw(22) << std::left << kv.first << ci(kv.second) << "\n";
  for (const auto& kv : f.derived)
    os << "  " << std::setw(22) << std::left << kv.first << ci(kv.second) << "\n";
  os << "intervals: " << f.interval_method << "\n";
  if (!f.q_vs_amplitude.empty()) {
    os << "Q against amplitude (straight fit per bin):\n";
    for (const auto& b : f.q_vs_amplitude) {
      char buf[200];
      std::snprintf(buf, sizeof(buf),
                    "  level %8.2f dB  amplitude %-11.4g Q %-11.5g [%.5g, %.5g]\n", b.level_db,
                    b.amplitude, b.Q.value, b.Q.ci_low, b.Q.ci_high);
      os << buf;
    }
  }
  for (const auto& fl : f.flags) os << "FLAG: " << fl << "\n";
}

RingdownFitOptions fitOptions(const CliArgs& args) {
  RingdownFitOptions o;
  o.confidence = args.getDouble("confidence", 0.95);
  o.error_model = args.get("error-model", "auto");
  o.q_bins = static_cast<int>(args.getInt("q-bins", 0));
  const auto p = o.validate();
  if (!p.empty()) throw InputError("invalid options: " + p.front());
  return o;
}

/// Data files of the ring-down report (read by scripts/ringdown_report.py).
void writeReportFiles(const std::string& dir, const nlohmann::json& j, const RingdownEnvelope& env,
                      const RingdownExplanation& x) {
  makeReportDirectory(dir);
  report::writeJsonFile(j, dir + "/explain.json");
  std::ofstream e(dir + "/ringdown_envelope.csv");
  e << std::setprecision(10) << "t,level_db,in_span,dropout\n";
  for (size_t i = 0; i < env.size(); ++i)
    e << env.t_s[i] << "," << env.log_amplitude[i] * kDbPerNeper << ","
      << (i >= x.segment.i_start && i < x.segment.i_end ? 1 : 0) << ","
      << (x.segment.dropout[i] ? 1 : 0) << "\n";
  std::ofstream f(dir + "/ringdown_fit.csv");
  f << std::setprecision(10) << "model,t,level_db,fitted_db,residual_db\n";
  for (const RingdownFit* fit : {&x.baseline, &x.final_fit}) {
    if (fit == &x.final_fit && x.selected.empty()) break;
    for (size_t i = 0; i < fit->t_s.size(); ++i)
      f << fit->model << "," << fit->t_s[i] << "," << fit->log_amplitude[i] * kDbPerNeper << ","
        << fit->fitted[i] * kDbPerNeper << ","
        << (fit->log_amplitude[i] - fit->fitted[i]) * kDbPerNeper << "\n";
  }
  std::ofstream q(dir + "/ringdown_q_vs_amplitude.csv");
  q << std::setprecision(10) << "level_db,amplitude,Q,ci_low,ci_high,n\n";
  for (const auto& b : x.final_fit.q_vs_amplitude)
    q << b.level_db << "," << b.amplitude << "," << b.Q.value << "," << b.Q.ci_low << ","
      << b.Q.ci_high << "," << b.n << "\n";
}

/// `--method` with `--mode ringdown`: every ring-down fit is weighted least squares on ln A solved
/// by Ceres (JSON "method": "wls_log"); `ceres` and `wls_log` name it, anything else is refused
/// rather than ignored (issue #23: it was accepted and ignored).
void checkRingdownMethod(const CliArgs& args) {
  if (!args.has("method")) return;
  const std::string m = args.get("method");
  if (m != "ceres" && m != "wls_log")
    throw InputError("--method " + m +
                     ": ring-down fits are nonlinear (weighted least squares on ln A, solved by "
                     "Ceres); --method ceres (or wls_log) is the only one");
}

}  // namespace

int runRingdownIdentify(const std::vector<std::string>& argv) {
  const CliArgs args(argv,
                     {"mode", "model", "frequency", "confidence", "json", "error-model",
                      "floor-margin-db", "q-bins", "method"},
                     {});
  if (args.help()) {
    std::cout << kIdentifyHelp;
    return 0;
  }
  if (args.positionals().size() != 1) throw InputError("identify needs exactly one INPUT file");
  checkRingdownMethod(args);
  const std::string model_arg = args.get("model", "linear");
  std::string model = model_arg;
  if (model.rfind("linear+", 0) == 0) model = model.substr(7);
  if (model.find('+') != std::string::npos)
    throw InputError("--model: ring-down models take one extension at a time (got '" + model_arg +
                     "')");
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::string> notes;
  const RingdownEnvelope env =
      readEnvelope(args.positionals().front(), args.getDouble("frequency", 0.0), notes);
  RingdownSegmentationOptions so;
  so.floor_margin_db = args.getDouble("floor-margin-db", so.floor_margin_db);
  const RingdownFitOptions fo = fitOptions(args);
  const RingdownSegment seg = segmentRingdown(env, so);
  RingdownFit fit = fitRingdown(env, seg, model, fo);
  requirePositiveQ(fit, seg);
  addSpanSpread(env, seg, fo, &fit);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << std::setprecision(6);
  printFit(fit, seg, std::cout);
  for (const auto& n : notes) std::cout << "note: " << n << "\n";
  std::cout << "time " << secs << " s\n";
  if (args.has("json")) {
    nlohmann::json j = report::ringdownFitToJson(fit, seg, fo.confidence, notes);
    j["model"] = model == "linear" ? "linear" : "linear+" + model;
    report::writeJsonFile(j, args.get("json"));
  }
  if (!fit.flags.empty()) {
    std::cerr << "cvg_ident identify: flagged: a fitted damping is negative; the model is not "
                 "adequate (see explain --mode ringdown)\n";
  }
  return 0;
}

int runRingdownExplain(const std::vector<std::string>& argv) {
  const CliArgs args(
      argv,
      {"mode", "frequency", "confidence", "json", "report", "alpha", "rate-variation", "candidates",
       "error-model", "floor-margin-db", "q-bins", "method"},
      {"no-figures"});
  if (args.help()) {
    std::cout << kExplainHelp;
    return 0;
  }
  if (args.positionals().size() != 1) throw InputError("explain needs exactly one INPUT file");
  checkRingdownMethod(args);
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::string> notes;
  const RingdownEnvelope env =
      readEnvelope(args.positionals().front(), args.getDouble("frequency", 0.0), notes);
  RingdownExplainOptions o;
  o.fit = fitOptions(args);
  o.alpha = args.getDouble("alpha", o.alpha);
  o.rate_variation = args.getDouble("rate-variation", o.rate_variation);
  o.segmentation.floor_margin_db =
      args.getDouble("floor-margin-db", o.segmentation.floor_margin_db);
  if (args.has("candidates")) o.candidates = splitList(args.get("candidates"));
  const RingdownExplanation x = explainRingdown(env, o);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << std::setprecision(6);
  std::cout << "baseline (single exponential): sigma " << x.baseline.sigma << ", rms "
            << x.baseline.rms_log * kDbPerNeper << " dB\n";
  for (const auto& s : x.steps) {
    char buf[300];
    std::snprintf(buf, sizeof(buf),
                  "  + %-10s sigma ratio %7.4f  BIC %10.4g (linear %.4g, n_eff %.0f)  %s%s\n",
                  s.added.c_str(), s.sigma_ratio, s.information_criterion,
                  x.information_criterion.at("linear"), s.n_eff,
                  s.accepted ? "ACCEPTED" : "rejected: ", s.accepted ? "" : s.note.c_str());
    std::cout << buf;
  }
  std::cout << "selected: " << (x.selected.empty() ? "none" : x.selected.front())
            << "; unexplained: " << (x.unexplained ? "yes" : "no")
            << "; lack of fit p = " << x.lack_of_fit_p << ", local decay rate varies by "
            << 100.0 * x.lack_of_fit_rate_variation << " % (RMS) of the mean\n";
  std::cout << "detector filter: " << x.detector_filter.why << "\n";
  if (!x.law_choice.empty()) std::cout << "amplitude law choice: " << x.law_choice << "\n";
  std::cout << "final model:\n";
  printFit(x.final_fit, x.segment, std::cout);
  std::cout << "verdict: " << x.cause << "\n";
  std::cout << "adequate: " << (x.adequate ? "yes" : "NO") << "\n";
  for (const auto& n : notes) std::cout << "note: " << n << "\n";
  std::cout << "time " << secs << " s\n";
  const nlohmann::json j = report::ringdownExplanationToJson(x, o.fit.confidence, notes);
  if (args.has("json")) report::writeJsonFile(j, args.get("json"));
  if (args.has("report")) {
    const std::string dir = args.get("report");
    writeReportFiles(dir, j, env, x);
    if (!args.has("no-figures")) {
      const std::string cmd = "/usr/bin/python3 '" + std::string(CVG_BENCH_SOURCE_DIR) +
                              "/scripts/ringdown_report.py' '" + dir + "'";
      if (std::system(cmd.c_str()) != 0)
        std::cerr << "cvg_ident explain: the figures were not made (" << cmd
                  << "); the data files are in " << dir << "\n";
    }
    std::cout << "report: " << dir << "\n";
  }
  return 0;
}

int runRingdownSimulate(const std::vector<std::string>& argv) {
  const CliArgs args(argv, {"mode",        "out",
                            "frequency",   "q",
                            "amplitude",   "scale",
                            "db-offset",   "samples",
                            "duration-s",  "plateau-s",
                            "noise-db",    "floor-db",
                            "correlation", "dropouts",
                            "split-hz",    "second-amplitude",
                            "q2",          "two-stage-ratio",
                            "q-fast",      "detection-loss-db",
                            "effect",      "seed"},
                     {}, {"effect"});
  if (args.help()) {
    std::cout << kSimulateHelp;
    return 0;
  }
  if (!args.has("out")) throw InputError("simulate needs --out FILE");
  RingdownSimulationOptions o;
  o.frequency_hz = args.getDouble("frequency", o.frequency_hz);
  o.q = args.getDouble("q", o.q);
  o.amplitude = args.getDouble("amplitude", o.amplitude);
  const std::string scale = args.get("scale", "linear");
  if (scale != "linear" && scale != "db") throw InputError("--scale must be linear or db");
  o.output_db = scale == "db";
  o.db_offset = args.getDouble("db-offset", 0.0);
  o.n_samples = static_cast<int>(args.getInt("samples", o.n_samples));
  o.duration_s = args.getDouble("duration-s", 0.0);
  o.plateau_s = args.getDouble("plateau-s", -1.0);
  o.noise_db = args.getDouble("noise-db", o.noise_db);
  o.floor_db = args.getDouble("floor-db", o.floor_db);
  o.noise_correlation = args.getDouble("correlation", 0.0);
  o.dropouts = static_cast<int>(args.getInt("dropouts", 0));
  o.split_hz = args.getDouble("split-hz", 0.0);
  o.second_amplitude = args.getDouble("second-amplitude", 0.0);
  o.q2 = args.getDouble("q2", 0.0);
  o.two_stage_ratio = args.getDouble("two-stage-ratio", 0.0);
  o.q_fast = args.getDouble("q-fast", 0.0);
  o.detection_loss_db = args.getDouble("detection-loss-db", 0.0);
  o.seed = static_cast<uint32_t>(args.getInt("seed", 1));
  for (const auto& e : args.getAll("effect")) {
    const size_t eq = e.find('=');
    if (eq == std::string::npos) throw InputError("--effect needs NAME=VALUE, got '" + e + "'");
    const std::string name = e.substr(0, eq);
    double v = 0.0;
    try {
      v = std::stod(e.substr(eq + 1));
    } catch (const std::exception&) {
      throw InputError("--effect " + name + ": not a number: '" + e.substr(eq + 1) + "'");
    }
    const RingdownLaw* law = findRingdownLaw(name);
    double* coefficient = law ? simulatedCoefficient(*law, o) : nullptr;
    if (!coefficient)
      throw InputError("--effect for ring-downs: " + simulatedLawNames() + ", got '" + name + "'");
    *coefficient = v;
  }
  const RingdownRecord rec = simulateRingdown(o);
  std::ofstream out(args.get("out"));
  if (!out) throw InputError("cannot write '" + args.get("out") + "'");
  writeRingdownCsv(rec, out);
  std::cout << "wrote " << rec.size() << " samples to " << args.get("out") << "\n";
  return 0;
}

}  // namespace tools
}  // namespace cvg_bench

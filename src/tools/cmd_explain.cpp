// cvg_ident explain: what the linear model gets wrong, the physical cause, the extended model and
// the gain (core: explanation.h). Raw t,f,g input is demodulated first (and the output says so).
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "bag_input.h"
#include "cli_args.h"
#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/demod/raw_record_demodulation.h"
#include "cvg_bench/core/diagnose/explanation.h"
#include "cvg_bench/core/io/input_checks.h"
#include "cvg_bench/core/io/record_io.h"
#include "cvg_bench/report/estimate_json.h"
#include "cvg_bench/report/explain_json.h"
#include "cvg_ident_commands.h"
#include "explain_report_files.h"
#include "term_help.h"

namespace cvg_bench {
namespace tools {

using report::explanationToJson;
using report::writeJsonFile;
namespace {

const char* kHelp =
    "usage: cvg_ident explain INPUT --mode free_decay|forced [--json FILE] [--report DIR]\n"
    "         [--omega W] [--confidence P] [--angular-gain K] [--mu M] [--alpha A]\n"
    "         [--candidates a,b,...] [--holdout-fraction F] [--columns t=COL,f=COL,g=COL]\n"
    "         [--no-figures] [--threads N]\n"
    "Fits the linear model, shows what it gets wrong (residual signature against amplitude^2,\n"
    "amplitude^4, time or detuning, pattern angle), tries the candidate extensions (free decay:\n"
    "{CANDIDATES_FREE_DECAY}; forced: {CANDIDATES_FORCED}) by forward\n"
    "selection (Wald test with the honest covariance, Bonferroni over the candidates of a step at\n"
    "level --alpha (0.01), hold-out prediction must improve), tests the final model's lack of fit\n"
    "(runs test) and prints the verdict. --json FILE ('-' = stdout) writes the explain JSON of\n"
    "interfaces.md; --report DIR writes explain.json, curves.csv, residuals.csv, signature.csv "
    "and\n"
    "(unless --no-figures) PNG figures + report.md by scripts/explain_report.py.\n"
    "INPUT: t,q1,p1,q2,p2 (free decay), omega0,q1,p1,q2,p2 (forced) or raw t,f,g (demodulated\n"
    "first at --omega or the file's omega); or a .bag of the project's messages (--topic NAME).\n"
    "--threads N: candidate fits run N at a time (default 0 = the machine's cores; the results\n"
    "do not depend on N).\n"
    "example: cvg_ident explain slow.csv --mode free_decay --json explain.json\n";

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

void printSummary(const Explanation& x) {
  std::cout << std::setprecision(4);
  std::cout << "explain (" << experimentModeName(x.mode) << "): baseline "
            << x.selection.baseline.model << ", sigma " << x.selection.baseline.sigma << "\n";
  for (const auto& s : x.selection.steps)
    std::cout << "  + " << std::left << std::setw(9) << s.added << std::right << " sigma "
              << s.sigma << "  ratio " << s.sigma_ratio << "  F " << s.wald.f_statistic << "  p "
              << s.wald.p_value << "  dIC " << s.delta_criterion << "  hold-out " << s.holdout_ratio
              << "\n";
  for (const auto& s : x.selection.last_round)
    std::cout << "    (not accepted: +" << s.added << ", dIC " << s.delta_criterion << ", p "
              << s.wald.p_value << ", sigma ratio " << s.sigma_ratio << ")\n";
  std::cout << "selection: " << x.selection.criterion_description << "\n";
  if (!x.selection.runner_up.model.empty())
    // The same words as the verdict's: a negative delta is a better criterion the hold-out did not
    // confirm (it printed "-25 worse").
    std::cout << "runner-up: " << x.selection.runner_up.model << ", criterion "
              << x.selection.runner_up_delta
              << (!std::isfinite(x.selection.runner_up_delta) ? " (not comparable) against "
                  : x.selection.runner_up_delta >= 0
                      ? " worse than "
                      : " better (not confirmed by the hold-out) than ")
              << x.selection.chosen.model << "\n";
  std::cout << "baseline residual signature: " << x.baseline_signature.describe(0.01) << "\n";
  std::cout << "selected: " << (x.selection.selected.empty() ? "none" : "");
  for (size_t i = 0; i < x.selection.selected.size(); ++i)
    std::cout << (i ? ", " : "") << x.selection.selected[i];
  std::cout << "\nlack of fit: p = " << x.lack_of_fit.p_value
            << "; unexplained: " << (x.unexplained ? "yes" : "no") << "\nverdict: " << x.cause
            << "\n";
}

}  // namespace

int runExplain(const std::vector<std::string>& argv) {
  const CliArgs args(argv,
                     {"mode", "json", "report", "omega", "confidence", "angular-gain", "mu",
                      "alpha", "candidates", "holdout-fraction", "columns", "topic", "threads"},
                     {"no-figures"});
  if (args.help()) {
    std::cout << withTermLists(kHelp);
    return 0;
  }
  if (args.positionals().size() != 1) throw InputError("explain needs exactly one INPUT file");
  if (!args.has("mode")) throw InputError("--mode free_decay|forced is required");
  const ExperimentMode mode = parseExperimentMode(args.get("mode"));

  ExplainOptions options;
  IdentificationOptions& id = options.fitting.identification;
  id.omega_rad_s = args.getDouble("omega", 0.0);
  id.confidence = args.getDouble("confidence", 0.95);
  id.angular_gain_k = args.getDouble("angular-gain", 0.4);
  id.mu = args.getDouble("mu", 0.0);
  options.fitting.ceres.confidence = id.confidence;
  options.selection.alpha = args.getDouble("alpha", options.selection.alpha);
  options.fitting.holdout_fraction =
      args.getDouble("holdout-fraction", options.fitting.holdout_fraction);
  if (args.has("candidates")) options.candidates = splitList(args.get("candidates"));
  const long threads = args.getInt("threads", 0);
  if (threads < 0 || threads > 64) throw InputError("--threads must lie in 0..64");
  options.selection.threads = static_cast<int>(threads);

  RecordReadOptions read;
  read.repair_raw_timestamps = true;
  if (args.has("columns")) read.raw_columns = parseRawColumnMap(args.get("columns"));
  if (args.has("omega")) requireOmegaInRange(id.omega_rad_s, "--omega");
  if (args.has("json") && args.get("json") != "-") requireOutputFile(args.get("json"), "--json");
  const std::string input = args.positionals().front();
  AnyRecord rec = readRecordInput(input, read, args.get("topic"));
  std::vector<std::string> input_notes;
  Explanation x;
  SlowRecord slow;
  SweepRecord sweep;
  if (mode == ExperimentMode::kFreeDecay) {
    if (rec.kind == RecordKind::kForcedSweep)
      throw InputError(input + ": a forced sweep (omega0,q1,...) given with --mode free_decay");
    slow = rec.kind == RecordKind::kRaw ? demodulateRawRecord(rec.raw, id.omega_rad_s, input_notes)
                                        : rec.slow;
    if (!(id.omega_rad_s > 0.0) && slow.omega_rad_s > 0.0) id.omega_rad_s = slow.omega_rad_s;
    // Without omega the final model could not be used downstream (drift, Q): refused (#25).
    if (!(id.omega_rad_s > 0.0))
      throw InputError(input +
                       ": the natural frequency omega is unknown (no '# omega:' line): give "
                       "--omega W [rad/s]; without it the model's Q and drift cannot be computed");
    x = explainFreeDecay(slow, options);
  } else {
    if (rec.kind != RecordKind::kForcedSweep)
      throw InputError(input + ": --mode forced needs a sweep record (omega0,q1,p1,q2,p2), got " +
                       recordKindName(rec.kind));
    sweep = rec.sweep;
    x = explainForced(sweep, options);
  }
  x.notes.insert(x.notes.begin(), input_notes.begin(), input_notes.end());
  const nlohmann::json j = explanationToJson(x);
  printSummary(x);
  if (x.measured.valid) std::cout << x.measured.summary << "\n";
  for (const auto& n : input_notes) std::cout << "note: " << n << "\n";
  if (args.has("json")) writeJsonFile(j, args.get("json"));
  if (args.has("report")) {
    const std::string dir = args.get("report");
    writeExplainReportFiles(dir, j, x, mode == ExperimentMode::kFreeDecay ? &slow : nullptr,
                            mode == ExperimentMode::kForced ? &sweep : nullptr, 1);
    std::cout.flush();
    if (!args.has("no-figures") && runExplainReportScript(dir))
      std::cout << "report: " << dir << "/report.md\n";
  }
  if (!x.determined) {
    // The files are written (they say why), but no usable model: exit 1, as identify (#25).
    std::cerr << "cvg_ident explain: analysis failed: the record does not determine the model ("
              << x.finalEstimate().rank << " of " << x.finalEstimate().n_params
              << " parameters; see the verdict)\n";
    return 1;
  }
  return 0;
}

}  // namespace tools
}  // namespace cvg_bench

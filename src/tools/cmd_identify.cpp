// cvg_ident identify: parameter estimation with confidence intervals (interfaces.md). Free decay:
// the integral regression (2.7)-(2.8); forced sweep: the stationary regression (3.4)-(3.5); LS
// (batch QR), RLS (2.12, corrected pairing) or Ceres (output-error refinement of the LS answer),
// all through the one pipeline of identify_pipeline.h.
// Raw t,f,g input is demodulated first (free decay) and the output says so.
#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <iostream>

#include "bag_input.h"
#include "cli_args.h"
#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/demod/raw_record_demodulation.h"
#include "cvg_bench/core/estimate/identify_pipeline.h"
#include "cvg_bench/core/io/record_io.h"
#include "cvg_bench/report/estimate_json.h"
#include "cvg_ident_commands.h"
#include "term_help.h"

namespace cvg_bench {
namespace tools {

using report::estimateToJson;
using report::writeJsonFile;
namespace {

const char* kHelp =
    "usage: cvg_ident identify INPUT [INPUT...] --mode free_decay|forced --model TERMS [--method "
    "ls|rls|ceres]\n"
    "                          [--confidence P] [--omega W] [--angular-gain K] [--mu MU]\n"
    "                          [--columns t=COL,f=COL,g=COL] [--json FILE]\n"
    "Estimates the model parameters with confidence intervals.\n"
    "  INPUT    CSV: t,q1,p1,q2,p2 (free decay), omega0,q1,p1,q2,p2 (forced sweep) or raw t,f,g\n"
    "           (free decay; demodulated first at --omega / the file's omega / estimated),\n"
    "           or a rosbag (.bag) of the project's SlowState / SweepPoint / RawSampleBatch "
    "messages\n"
    "           Several free decays of one resonator (e.g. started at several pattern angles)\n"
    "           are stacked for one fit: the equations across their joins are left out\n"
    "           (--method ls or rls).\n"
    "  --topic  bag topic to read (default: the one topic of a project message type)\n"
    "  --columns  raw input with other column names or orders (as explain and demod)\n"
    "  --model  linear, or +-joined extensions (mu multiplies u~ bilinearly: LS cannot fit it):\n"
    "{MODEL_TERMS}\n"
    "  --method ls (batch QR, default), rls (block recursive LS (2.12)), ceres (output-error fit\n"
    "           started from LS; removes the errors-in-variables bias of noisy forced sweeps).\n"
    "  --confidence P0 of the intervals (default 0.95); --angular-gain K (default 0.4);\n"
    "  --mu     known control nonlinearity for forced LS (default 0).\n"
    "Intervals: \"parameters\" hold honest intervals (free decay: the shared-sample error "
    "structure of\n"
    "(2.7) is modelled; forced: per-point sandwich); \"parameters_paper_2_11\" the paper's "
    "(2.11).\n"
    "Exit 1 when the data cannot identify every parameter (the report says which and why).\n"
    "example: cvg_ident identify sweep.csv --mode forced --model xi+mu --method ceres\n";

/// A free-decay model without the natural frequency cannot be used downstream (drift, Q): refused
/// before fitting (issue #25: never a model with omega 0 at exit 0).
void requireKnownOmega(double option, const SlowRecord& rec) {
  if (!(option > 0.0) && !(rec.omega_rad_s > 0.0))
    throw InputError(rec.source +
                     ": the natural frequency omega is unknown (no '# omega:' line): give --omega "
                     "W [rad/s]; without it the model's Q and drift cannot be computed");
}

void printTable(const Estimate& e, std::ostream& os) {
  os << "mode " << experimentModeName(e.mode) << ", model " << e.model << ", method " << e.method
     << ", omega " << e.omega_rad_s << " rad/s\n"
     << "n_equations " << e.n_equations << ", n_params " << e.n_params << ", rank " << e.rank
     << ", sigma " << e.sigma << " (equation units), confidence " << e.confidence << "\n";
  char buf[200];
  os << "  parameter        value          +- honest CI      +- paper (2.11)\n";
  for (const auto& name : e.names) {
    const auto it = e.parameters.find(name);
    const bool weak =
        std::find(e.not_identified.begin(), e.not_identified.end(), name) != e.not_identified.end();
    if (it == e.parameters.end()) {
      std::snprintf(buf, sizeof(buf), "  %-10s  (not identifiable alone)\n", name.c_str());
    } else if (weak) {
      std::snprintf(buf, sizeof(buf), "  %-10s  not identified by this record (VIF %.3g)\n",
                    name.c_str(), e.vif.at(name));
    } else {
      const auto pp = e.parameters_paper.find(name);
      const double paper =
          pp == e.parameters_paper.end() ? 0.0 : pp->second.ci_high - pp->second.value;
      std::snprintf(buf, sizeof(buf), "  %-10s  %14.8g  +- %-14.6g  +- %-14.6g\n", name.c_str(),
                    it->second.value, it->second.ci_high - it->second.value, paper);
    }
    os << buf;
  }
  for (const auto& kv : e.combinations) {
    std::snprintf(buf, sizeof(buf), "  %-16s  %14.8g  +- %-14.6g\n", kv.first.c_str(),
                  kv.second.value, kv.second.ci_high - kv.second.value);
    os << buf;
  }
  if (!e.derived.empty()) os << "derived (section 4):\n";
  for (const auto& kv : e.derived) {
    std::snprintf(buf, sizeof(buf), "  %-24s  %14.8g  [%.6g, %.6g]\n", kv.first.c_str(),
                  kv.second.value, kv.second.ci_low, kv.second.ci_high);
    os << buf;
    const auto how = e.derived_method.find(kv.first);
    if (how != e.derived_method.end()) os << "      (" << how->second << ")\n";
  }
  if (!e.interval_method_id.empty())
    os << "intervals: " << e.interval_method_id << "; residual lag-1 correlation "
       << e.residual_lag1 << " (z = " << e.residual_lag1_z << "), noise " << e.noise_model << "\n";
  if (!e.identifiability_note.empty()) os << "identifiability: " << e.identifiability_note << "\n";
  for (const auto& n : e.notes) os << "note: " << n << "\n";
}

}  // namespace

int runIdentify(const std::vector<std::string>& argv) {
  const CliArgs args(argv,
                     {"mode", "model", "method", "confidence", "omega", "angular-gain", "json",
                      "mu", "topic", "columns"},
                     {});
  if (args.help()) {
    std::cout << withTermLists(kHelp);
    return 0;
  }
  if (args.positionals().empty()) throw InputError("identify needs an INPUT file");
  if (!args.has("mode")) throw InputError("--mode free_decay|forced is required");
  if (!args.has("model")) throw InputError("--model TERMS is required (e.g. linear, xi)");
  const std::string path = args.positionals().front();
  const ExperimentMode mode = parseExperimentMode(args.get("mode"));
  PipelineOptions po;
  po.method = parseMethod(args.get("method", "ls"));
  IdentificationOptions& opt = po.identification;
  opt.model = args.get("model");
  opt.confidence = args.getDouble("confidence", 0.95);
  opt.omega_rad_s = args.getDouble("omega", 0.0);
  opt.angular_gain_k = args.getDouble("angular-gain", 0.4);
  opt.mu = args.getDouble("mu", 0.0);
  throwIfInvalid("invalid options", po.validate());
  RecordReadOptions ro;
  ro.repair_raw_timestamps = true;
  if (args.has("columns")) ro.raw_columns = parseRawColumnMap(args.get("columns"));
  std::vector<std::string> pre_notes;
  Estimate e;
  if (mode == ExperimentMode::kFreeDecay) {
    std::vector<SlowRecord> recs;
    for (const std::string& file : args.positionals()) {
      const AnyRecord any = readRecordInput(file, ro, args.get("topic"));
      if (any.kind == RecordKind::kForcedSweep)
        throw InputError(file +
                         ": holds a forced sweep (omega0 column) but --mode free_decay was "
                         "given; use --mode forced");
      recs.push_back(any.kind == RecordKind::kRaw
                         ? demodulateRawRecord(any.raw, opt.omega_rad_s, pre_notes)
                         : any.slow);
      if (recs.back().source.empty()) recs.back().source = file;
    }
    for (const SlowRecord& rec : recs) requireKnownOmega(opt.omega_rad_s, rec);
    e = identify(recs, po);
  } else {
    if (args.positionals().size() != 1)
      throw InputError("identify --mode forced takes one INPUT (several: free decays only)");
    const AnyRecord any = readRecordInput(path, ro, args.get("topic"));
    if (any.kind == RecordKind::kFreeDecay)
      throw InputError(path +
                       ": holds a free-decay record (t column, no omega0) but --mode forced "
                       "was given; use --mode free_decay");
    if (any.kind == RecordKind::kRaw)
      throw InputError(path +
                       ": raw t,f,g input in forced mode needs the stationary point of each "
                       "sweep step: run `cvg_ident demod` per step or give omega0,q1,p1,q2,p2");
    SweepRecord rec = any.sweep;
    if (rec.source.empty()) rec.source = path;
    e = identify(rec, po);
  }
  e.notes.insert(e.notes.begin(), pre_notes.begin(), pre_notes.end());
  std::cout << std::setprecision(8);
  printTable(e, std::cout);
  if (args.has("json")) writeJsonFile(estimateToJson(e), args.get("json"));
  if (e.rank < e.n_params) {
    std::cerr << "cvg_ident identify: analysis failed: rank-deficient (" << e.rank << " of "
              << e.n_params << "): " << e.identifiability_note << "\n";
    return 1;
  }
  return 0;
}

}  // namespace tools
}  // namespace cvg_bench

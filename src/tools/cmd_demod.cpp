// cvg_ident demod: raw f, g -> slow q1, p1, q2, p2 of (2.4) (interfaces.md). Uniform timestamps go
// through the FIR demodulator (demodulator.h), irregular ones through the windowed least-squares
// demodulator (irregular_demodulator.h); the reference frequency comes from --omega, the file's
// `# omega:` line, or is estimated from the data (frequency_estimator.h) and said so.
#include <cmath>
#include <iostream>
#include <sstream>

#include "bag_input.h"
#include "cli_args.h"
#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/demod/demodulator.h"
#include "cvg_bench/core/demod/frequency_estimator.h"
#include "cvg_bench/core/demod/irregular_demodulator.h"
#include "cvg_bench/core/io/input_checks.h"
#include "cvg_bench/core/io/record_io.h"
#include "cvg_ident_commands.h"

namespace cvg_bench {
namespace tools {
namespace {

const char* kHelp =
    "usage: cvg_ident demod INPUT [--omega W] [--rate HZ] [--columns t=COL,f=COL,g=COL] --out "
    "FILE\n"
    "                       [--attenuation DB] [--window S]\n"
    "Demodulates raw f(t), g(t) (CSV, or a .bag of RawSampleBatch messages: --topic NAME picks "
    "the\n"
    "topic) into the slow variables of (2.4):\n"
    "  f = p1 sin(W t) + q1 cos(W t),  g = p2 sin(W t) + q2 cos(W t)\n"
    "and writes t,q1,p1,q2,p2 with `# omega:` and `# mode: free_decay`.\n"
    "  --omega W      reference frequency [rad/s]; default the file's `# omega:`, else estimated\n"
    "                 from the data (FFT peak + nonlinear least squares; reported on stderr).\n"
    "  --rate HZ      slow output rate [Hz] (default: uniform data min(100, input rate / 4);\n"
    "                 irregular data min(10, reference frequency / 2)).\n"
    "  --columns ...  header names of the t, f, g columns (default t,f,g).\n"
    "  --attenuation  FIR stopband attenuation and passband ripple bound [dB] (default 120).\n"
    "  --window S     least-squares window for irregular timestamps [s] (default 2 / rate).\n"
    "Uniform timestamps (every interval within 1 % of the median, or a whole multiple of it for\n"
    "dropped samples) use the FIR path (passband 0.2 x rate, stopband 0.5 x rate); otherwise the\n"
    "windowed least-squares path is used. The choice is printed on stderr and in the output.\n"
    "example: cvg_ident demod raw.csv --rate 200 --out slow_200hz.csv\n";

}  // namespace

int runDemod(const std::vector<std::string>& argv) {
  const CliArgs args(argv, {"omega", "rate", "columns", "out", "attenuation", "window", "topic"},
                     {});
  if (args.help()) {
    std::cout << kHelp;
    return 0;
  }
  if (args.positionals().size() != 1) throw InputError("demod needs exactly one INPUT file");
  if (!args.has("out")) throw InputError("--out FILE is required");
  RecordReadOptions ro;
  if (args.has("columns")) ro.raw_columns = parseRawColumnMap(args.get("columns"));
  ro.repair_raw_timestamps = true;
  const AnyRecord any =
      readRecordInput(args.positionals().front(), ro, args.get("topic"), {RecordKind::kRaw});
  if (any.kind != RecordKind::kRaw)
    throw InputError(args.positionals().front() + ": not a raw t,f,g record (found " +
                     recordKindName(any.kind) + " columns); use --columns to map raw columns");
  const RawRecord& raw = any.raw;
  if (raw.n_reordered > 0 || raw.n_duplicates_dropped > 0)
    std::cerr << "cvg_ident demod: " << raw.n_reordered << " rows re-ordered, "
              << raw.n_duplicates_dropped << " rows with repeated timestamps dropped\n";

  if (args.has("omega")) requireOmegaInRange(args.getDouble("omega", 0.0), "--omega");
  if (args.has("rate") && !(args.getDouble("rate", 0.0) > 0.0))
    throw InputError("--rate must be > 0 [Hz], got " + args.get("rate"));
  if (args.has("window") && !(args.getDouble("window", 0.0) > 0.0))
    throw InputError("--window must be > 0 [s], got " + args.get("window"));
  requireOutputFile(args.get("out"), "--out");
  std::vector<std::string> notes;
  double omega = args.getDouble("omega", raw.omega_rad_s);
  if (!(omega > 0.0)) {
    const FrequencyEstimate e = estimateFrequency(raw.t_s, raw.f, raw.g);
    omega = e.omega_rad_s;
    notes.push_back("no omega given: reference frequency " + e.method);
  }
  const SamplingSummary sampling = summarizeSampling(raw.t_s);
  const double input_rate = sampling.median_interval_s > 0 ? 1.0 / sampling.median_interval_s : 0;
  SlowRecord out;
  if (sampling.uniform) {
    DemodulatorOptions o;
    o.omega_rad_s = omega;
    o.sample_rate_hz = input_rate;
    o.output_rate_hz = args.getDouble("rate", std::min(100.0, input_rate / 4.0));
    o.attenuation_db = args.getDouble("attenuation", o.attenuation_db);
    SampleCounters counters;
    out = demodulateUniform(raw, o, &counters);
    std::ostringstream m;
    m << "uniform timestamps (" << input_rate << " Hz): FIR path";
    notes.push_back(m.str());
    if (counters.rejected() + counters.missing_filled + counters.restarts > 0) {
      std::ostringstream c;
      c << "input screening:";
      for (const auto& kv : counters.asMap())
        if (kv.second > 0 && kv.first != "accepted") c << " " << kv.first << "=" << kv.second;
      notes.push_back(c.str());
    }
  } else {
    IrregularDemodulatorOptions o;
    o.omega_rad_s = omega;
    // Default: about one output per two periods (window = four periods), at most 10 Hz, rounded
    // down to 1-2-5 x 10^k Hz so that the output times fall on round values.
    const double x = std::min(10.0, omega / (2.0 * M_PI) / 2.0);
    const double decade = std::pow(10.0, std::floor(std::log10(x)));
    const double nice = x >= 5 * decade ? 5 * decade : x >= 2 * decade ? 2 * decade : decade;
    o.output_rate_hz = args.getDouble("rate", nice);
    o.window_s = args.getDouble("window", 0.0);
    const IrregularDemodResult res = demodulateIrregular(raw, o);
    out = res.record;
    std::ostringstream m;
    m << "irregular timestamps (median interval " << sampling.median_interval_s << " s, "
      << 100.0 * sampling.fraction_on_grid << " % on grid): windowed least-squares path";
    notes.push_back(m.str());
    if (!res.skipped_window_times.empty()) {
      std::ostringstream s;
      s << res.skipped_window_times.size() << " windows skipped (" << res.n_too_few
        << " too few samples, " << res.n_rank_deficient
        << " rank-deficient), first at t = " << res.skipped_window_times.front() << " s";
      notes.push_back(s.str());
    }
    for (const char* name : {"q1_std", "p1_std", "q2_std", "p2_std"}) out.extra[name].clear();
    for (const Eigen::Vector4d& s : res.std_error) {
      out.extra["q1_std"].push_back(s[0]);
      out.extra["p1_std"].push_back(s[1]);
      out.extra["q2_std"].push_back(s[2]);
      out.extra["p2_std"].push_back(s[3]);
    }
  }
  out.metadata["mode"] = "free_decay";
  out.metadata["source"] = args.positionals().front();
  for (size_t i = 0; i < notes.size(); ++i) {
    out.metadata["note_" + std::to_string(i + 1)] = notes[i];
    std::cerr << "cvg_ident demod: " << notes[i] << "\n";
  }
  writeSlowRecordCsv(out, args.get("out"));
  std::cerr << "cvg_ident demod: wrote " << out.size() << " slow samples at omega = " << omega
            << " rad/s to " << args.get("out") << "\n";
  return 0;
}

}  // namespace tools
}  // namespace cvg_bench

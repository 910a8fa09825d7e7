// cvg_ident simulate: a simulated record from a resonator preset (interfaces.md).
#include <iostream>
#include <sstream>

#include "cli_args.h"
#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/io/input_checks.h"
#include "cvg_bench/core/io/record_io.h"
#include "cvg_bench/core/model/resonator_preset.h"
#include "cvg_bench/core/simulate/experiment_runner.h"
#include "cvg_bench/core/simulate/whole_angle_simulator.h"
#include "cvg_ident_commands.h"
#include "term_help.h"

namespace cvg_bench {
namespace tools {
namespace {

const char* kHelp =
    "usage: cvg_ident simulate --preset NAME|--config FILE --mode free_decay|forced|whole_angle\n"
    "                          [--raw]\n"
    "                          [--seed N] [--effect NAME=VALUE ...] [--noise STD]\n"
    "                          [--duration S] [--start R,K,THETA] --out FILE\n"
    "Simulates a record of a resonator preset and writes it as CSV with `# omega:`, `# mode:` and\n"
    "the true parameters as `# truth_<name>: value` lines.\n"
    "  --preset NAME     shipped preset (config/resonators/NAME.yaml): mems_ring,\n"
    "                    hrg_hemispherical, quartz_cylinder\n"
    "  --config FILE     a preset YAML file instead (same keys, see the shipped ones)\n"
    "  --mode M          free_decay: drive to the stationary forced oscillation, switch the\n"
    "                    controls off at t = 0, record the decay (t,q1,p1,q2,p2);\n"
    "                    forced: stepped sweep of the detuning, stationary q per step\n"
    "                    (omega0,q1,p1,q2,p2,direction,jump; jump = 1 marks a branch jump of a\n"
    "                    bistable resonator)\n"
    "                    whole_angle: amplitude and quadrature held by control loops, the\n"
    "                    pattern angle walked over 1.5 periods by a base rotation (t,q1,p1,q2,p2\n"
    "                    with # whole_angle_* lines; measure its drift with drift --measured)\n"
    "  --amplitude R --quadrature K --walk RAD_S   whole_angle: held r (default 0.5), k (0) and\n"
    "                    the walk of theta (default 1.5 x pi/2 over the run, and at least 4x\n"
    "                    the largest true drift, so that the pattern cannot lock)\n"
    "  --raw             raw f, g of the full equations (2.3)/(3.1) instead (t,f,g); forced: one\n"
    "                    segment per settled step with columns omega0 and drive_phase_rad\n"
    "  --seed N          seed of the Gaussian measurement noise (default 1)\n"
    "  --effect N=V      set a true parameter (repeatable); the model terms' parameters, u1..u4\n"
    "                    the drive u~, mu the control nonlinearity, eta the 2 omega0 parametric\n"
    "                    terms of (2.1) (raw forced only, 0 = off):\n"
    "{EFFECT_NAMES}\n"
    "  --noise STD       noise std overriding the preset's (q, or f, g with --raw); 0 = none\n"
    "  --duration S      record length [s] overriding the preset's (forced --raw: per step)\n"
    "  --start R,K,THETA free decay only: start from the orbit elements (5.2) amplitude R > 0,\n"
    "                    quadrature K (|K| <= R) and pattern angle THETA [rad] instead of the\n"
    "                    drive's stationary state (e.g. to probe the axes at several angles)\n"
    "  --out FILE        output CSV\n"
    "example: cvg_ident simulate --preset quartz_cylinder --mode forced --effect kappa=2 --out "
    "q.csv\n";

}  // namespace

int runSimulate(const std::vector<std::string>& argv) {
  const CliArgs args(argv,
                     {"preset", "config", "mode", "seed", "out", "noise", "duration", "start",
                      "amplitude", "quadrature", "walk"},
                     {"raw"}, {"effect"});
  if (args.help()) {
    std::cout << withTermLists(kHelp);
    return 0;
  }
  if (!args.positionals().empty())
    throw InputError("unexpected argument '" + args.positionals().front() + "' (see --help)");
  if (args.has("preset") == args.has("config"))
    throw InputError("give exactly one of --preset NAME or --config FILE (see --help)");
  if (!args.has("mode")) throw InputError("--mode free_decay|forced|whole_angle is required");
  if (!args.has("out")) throw InputError("--out FILE is required");
  if (args.has("config")) requireInputFile(args.get("config"), "--config preset file");
  requireOutputFile(args.get("out"), "--out");
  ResonatorPreset preset = args.has("preset") ? loadShippedPreset(args.get("preset"))
                                              : loadResonatorPresetFile(args.get("config"));
  for (const auto& e : args.getAll("effect")) preset.applyEffect(e);
  if (args.get("mode") == "whole_angle") {
    // Amplitude and quadrature held by loops, the pattern walked (whole_angle_simulator.h).
    WholeAngleOptions wa;
    wa.r0 = args.getDouble("amplitude", wa.r0);
    wa.k0 = args.getDouble("quadrature", wa.k0);
    wa.walk_rad_s = args.getDouble("walk", 0.0);
    wa.duration_s = args.getDouble("duration", 0.0);
    wa.noise_std = args.getDouble("noise", -1.0);
    if (args.has("noise") && wa.noise_std < 0) throw InputError("--noise must be >= 0");
    if (args.has("duration") && wa.duration_s <= 0) throw InputError("--duration must be > 0");
    const long seed = args.getInt("seed", 1);
    if (seed < 0) throw InputError("--seed must be >= 0");
    wa.seed = static_cast<std::uint64_t>(seed);
    SlowRecord rec = simulateWholeAngle(preset, wa);
    writeSlowRecordCsv(rec, args.get("out"));
    std::cerr << "simulate: " << rec.size() << " whole-angle samples (walk "
              << rec.metadata.at("whole_angle_walk_rad_s") << " rad/s) -> " << args.get("out")
              << "\n";
    return 0;
  }
  for (const char* o : {"amplitude", "quadrature", "walk"})
    if (args.has(o))
      throw InputError(std::string("--") + o + " applies to --mode whole_angle only");
  SimulationOptions options;
  options.mode = parseExperimentMode(args.get("mode"));
  options.raw = args.has("raw");
  const long seed = args.getInt("seed", 1);
  if (seed < 0) throw InputError("--seed must be >= 0");
  options.seed = static_cast<std::uint64_t>(seed);
  options.noise_std = args.getDouble("noise", -1.0);
  if (args.has("noise") && options.noise_std < 0) throw InputError("--noise must be >= 0");
  options.duration_s = args.getDouble("duration", 0.0);
  if (args.has("duration") && options.duration_s <= 0) throw InputError("--duration must be > 0");
  if (args.has("start")) {
    if (options.mode != ExperimentMode::kFreeDecay)
      throw InputError("--start applies to --mode free_decay only");
    std::istringstream in(args.get("start"));
    std::string item;
    std::vector<double> v;
    while (std::getline(in, item, ',')) {
      try {
        size_t used = 0;
        v.push_back(std::stod(item, &used));
        if (used != item.size()) throw std::invalid_argument(item);
      } catch (const std::exception&) {
        throw InputError("--start: '" + item + "' is not a number (give R,K,THETA)");
      }
    }
    if (v.size() != 3) throw InputError("--start needs R,K,THETA (three numbers)");
    options.free_decay_start.r = v[0];
    options.free_decay_start.k = v[1];
    options.free_decay_start.theta = v[2];
    if (!(v[0] > 0.0)) throw InputError("--start: R must be > 0");
  }

  const AnyRecord rec = simulateExperiment(preset, options);
  const std::string out = args.get("out");
  switch (rec.kind) {
    case RecordKind::kFreeDecay:
      writeSlowRecordCsv(rec.slow, out);
      std::cerr << "simulate: " << rec.slow.size() << " free-decay samples -> " << out << "\n";
      break;
    case RecordKind::kForcedSweep:
      writeSweepRecordCsv(rec.sweep, out);
      std::cerr << "simulate: " << rec.sweep.size() << " sweep points ("
                << rec.sweep.metadata.at("n_jumps") << " jumps) -> " << out << "\n";
      break;
    case RecordKind::kRaw:
      writeRawRecordCsv(rec.raw, out);
      std::cerr << "simulate: " << rec.raw.size() << " raw samples -> " << out << "\n";
      break;
  }
  return 0;
}

}  // namespace tools
}  // namespace cvg_bench

// cvg_ident: the offline tool over the cvg_bench core (no roscore). See interfaces.md.
#include <glog/logging.h>

#include <iostream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "cvg_bench/core/common/errors.h"
#include "cvg_ident_commands.h"

namespace {

const char* kUsage =
    "usage: cvg_ident <subcommand> [options]   (every subcommand has --help)\n"
    "  simulate  --preset NAME|--config FILE --mode free_decay|forced|whole_angle [--raw]\n"
    "            [--seed N] [--effect NAME=VALUE ...] --out FILE\n"
    "  demod     INPUT [--omega W] [--rate HZ] [--columns t=COL,f=COL,g=COL] --out FILE\n"
    "  identify  INPUT --mode free_decay|forced --model TERMS [--method ls|rls|ceres]\n"
    "            [--confidence P] [--omega W] [--angular-gain K] [--json FILE]\n"
    "  drift     --params FILE.json [--r R --k K --theta TH | --theta-grid N] [--json FILE]\n"
    "  drift     --params FILE.json --measured RECORD [--json FILE]   measured vs predicted (5.9)\n"
    "  explain   INPUT --mode free_decay|forced [--json FILE] [--report DIR]\n"
    "  identify|explain INPUT --mode ringdown [--frequency HZ] ...   single-channel ring-downs\n"
    "  simulate  --mode ringdown --out FILE ...                      (see --mode ringdown --help)\n"
    "  identify|explain INPUT --mode response [--columns ...] ...   one mode's frequency response\n"
    "  simulate  --mode response --out FILE ...                      (see --mode response --help)\n"
    "  batch     INPUT...|MANIFEST.csv --mode MODE [--explain] [--jobs N] [--shard I/N] --out DIR\n"
    "            (and batch --merge DIR --out DIR)                  many records, a fleet table\n"
    "exit status: 0 success, 1 analysis failed, 2 bad usage or input\n";

using Command = int (*)(const std::vector<std::string>&);

/// (subcommand, --mode) -> handler for the one-mode records: ring-downs and frequency responses.
const std::map<std::pair<std::string, std::string>, Command> kOneModeCommands = {
    {{"identify", "ringdown"}, cvg_bench::tools::runRingdownIdentify},
    {{"explain", "ringdown"}, cvg_bench::tools::runRingdownExplain},
    {{"simulate", "ringdown"}, cvg_bench::tools::runRingdownSimulate},
    {{"identify", "response"}, cvg_bench::tools::runResponseIdentify},
    {{"explain", "response"}, cvg_bench::tools::runResponseExplain},
    {{"simulate", "response"}, cvg_bench::tools::runResponseSimulate}};

/// The value of the first `--mode X` or `--mode=X` ("" when none; the subcommand checks it).
std::string modeOf(const std::vector<std::string>& args) {
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--mode" && i + 1 < args.size()) return args[i + 1];
    if (args[i].rfind("--mode=", 0) == 0) return args[i].substr(7);
  }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace cvg_bench::tools;
  // Ceres logs failed evaluations through glog; the tool reports outcomes itself (notes, exit
  // codes).
  FLAGS_minloglevel = google::GLOG_FATAL;
  const std::map<std::string, Command> commands = {{"simulate", runSimulate}, {"demod", runDemod},
                                                   {"identify", runIdentify}, {"drift", runDrift},
                                                   {"explain", runExplain},   {"batch", runBatch}};
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    std::cout << kUsage;
    return argc < 2 ? 2 : 0;
  }
  const auto it = commands.find(argv[1]);
  if (it == commands.end()) {
    std::cerr << "cvg_ident: unknown subcommand '" << argv[1] << "'\n" << kUsage;
    return 2;
  }
  try {
    const std::vector<std::string> args(argv + 2, argv + argc);
    // The one-mode modes (cmd_ringdown.cpp, cmd_response.cpp) have their own handlers.
    const auto one_mode = kOneModeCommands.find({it->first, modeOf(args)});
    if (one_mode != kOneModeCommands.end()) return one_mode->second(args);
    return it->second(args);
  } catch (const cvg_bench::InputError& e) {
    std::cerr << "cvg_ident " << argv[1] << ": error: " << e.what() << "\n";
    return 2;
  } catch (const cvg_bench::AnalysisError& e) {
    std::cerr << "cvg_ident " << argv[1] << ": analysis failed: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "cvg_ident " << argv[1] << ": internal error: " << e.what() << "\n";
    return 1;
  }
}

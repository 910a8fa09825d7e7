// Subcommands of the offline tool (the command-line and JSON contract; README.md, "Offline tool").
// Each lives in its own cmd_<name>.cpp, takes the arguments after the subcommand name, and returns
// the exit status (0 success, 1 analysis failed, 2 bad usage or input). Errors may be thrown as
// InputError (2) or AnalysisError (1); the dispatcher prints them.
#pragma once

#include <string>
#include <vector>

namespace cvg_bench {
namespace tools {

int runSimulate(const std::vector<std::string>& args);
int runDemod(const std::vector<std::string>& args);
int runIdentify(const std::vector<std::string>& args);
int runDrift(const std::vector<std::string>& args);
int runExplain(const std::vector<std::string>& args);
// `--mode ringdown` of identify / explain / simulate (cmd_ringdown.cpp).
int runRingdownIdentify(const std::vector<std::string>& args);
int runRingdownExplain(const std::vector<std::string>& args);
int runRingdownSimulate(const std::vector<std::string>& args);
// `--mode response` of identify / explain / simulate (cmd_response.cpp).
int runResponseIdentify(const std::vector<std::string>& args);
int runResponseExplain(const std::vector<std::string>& args);
int runResponseSimulate(const std::vector<std::string>& args);
// Many records through identify/explain, resumable and sharded (cmd_batch.cpp, docs/fleet.md).
int runBatch(const std::vector<std::string>& args);

}  // namespace tools
}  // namespace cvg_bench

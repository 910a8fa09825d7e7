// The data files of `cvg_ident explain --report DIR` (read by scripts/explain_report.py, which
// draws the figures and writes report.md): explain.json, curves.csv (measured vs every model of
// the ladder: integrated averaged trajectories (2.6) for free decay, stationary points (3.3) for
// sweeps, with A, B, phases and orbit elements (5.2)), residuals.csv (baseline and final residual
// projections per block) and signature.csv (binned residual means).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "cvg_bench/core/diagnose/explanation.h"
#include "cvg_bench/core/io/records.h"

namespace cvg_bench {
namespace tools {

/// Writes the files into dir (created if missing). InputError when it cannot be written.
void writeExplainReportFiles(const std::string& dir, const nlohmann::json& explanation_json,
                             const Explanation& x, const SlowRecord* slow, const SweepRecord* sweep,
                             int rk4_substeps);

/// Runs /usr/bin/python3 scripts/explain_report.py DIR; returns false (and says why on stderr)
/// when the figures could not be made (the data files stay).
bool runExplainReportScript(const std::string& dir);

}  // namespace tools
}  // namespace cvg_bench

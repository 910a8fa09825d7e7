// Runs the records of `cvg_ident batch` (docs/fleet.md): each record is one `cvg_ident identify` or
// `explain` process (the same pipeline as a single call; a crash or a hang stays in its record),
// at most `jobs` at a time. A record's outcome goes to DIR/records/NAME.status.json, written last
// and atomically: a record is done when that file is complete and its hashes match, so a killed
// batch resumes where it stopped.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "batch_inputs.h"

namespace cvg_bench {
namespace tools {

struct BatchJob {
  BatchRecord record;
  size_t record_count = 0;        ///< records in the whole list (all shards)
  std::vector<std::string> args;  ///< subcommand and its arguments, without --json
  std::string json_path, log_path, status_path;
  std::string input_hash, settings_hash;
};

struct BatchRunOptions {
  int jobs = 1;
  double timeout_s = 0;  ///< per record; 0 = none
};

struct BatchRunSummary {
  size_t ran = 0, skipped = 0, failed = 0, crashed = 0;
  double seconds = 0;
};

/// True when the record's status file is complete, its hashes match the job's, and it ended with a
/// result (exit 0, 1 or 2; a crash, a kill or a timeout is run again). Exit 0 also needs its JSON.
bool batchJobDone(const BatchJob& job);

/// Runs every job not done (all of them with `force`), printing a progress line to stderr.
BatchRunSummary runBatchJobs(const std::vector<BatchJob>& jobs, const BatchRunOptions& options,
                             bool force);

/// The status file of a record (nullopt-like: an empty object when absent or incomplete).
nlohmann::json readBatchStatus(const std::string& path);

}  // namespace tools
}  // namespace cvg_bench

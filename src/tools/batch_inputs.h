// The records of `cvg_ident batch` (docs/fleet.md): input paths, glob patterns and manifest CSVs
// expanded into one ordered list, each record with a unique output name and the manifest's
// per-record columns; the shard a record belongs to; content hashes for resuming.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace cvg_bench {
namespace tools {

struct BatchRecord {
  size_t index = 0;   ///< position in the expanded list (0-based); fixes every output order
  std::string input;  ///< the path as given (manifest paths resolved against the manifest's folder)
  std::string name;   ///< output stem under DIR/records/, unique over the list
  /// Manifest columns other than the path, in the manifest's order (carried into the fleet table).
  std::vector<std::pair<std::string, std::string>> columns;
  std::string column(const std::string& key) const;
};

/// Expands the positionals of `batch`: a CSV whose header names a `path` (or `input`) column is a
/// manifest (one record a row; `#` lines skipped; quoted fields allowed); a pattern with * ? [ that
/// is not an existing file is globbed (sorted); anything else is one record. Throws InputError with
/// file:line:field for a malformed manifest, or when nothing is left.
std::vector<BatchRecord> expandBatchInputs(const std::vector<std::string>& positionals);

/// Shard I of N (0 <= I < N): the records whose index % N == I (round robin: shards of a list
/// sorted by sample get similar mixes). Throws InputError on a malformed "I/N".
struct Shard {
  long index = 0, count = 1;
  bool contains(size_t record_index) const { return long(record_index % count) == index; }
};
Shard parseShard(const std::string& text);
/// The shard from a Slurm job array (SLURM_ARRAY_TASK_ID - SLURM_ARRAY_TASK_MIN of
/// SLURM_ARRAY_TASK_COUNT) when those variables are set; {0, 1} otherwise. `source` says which.
Shard shardFromEnvironment(std::string& source);

/// FNV-1a 64-bit over a file's bytes / a string, as 16 hex digits (change detection, not security).
std::string hashFile(const std::string& path);
std::string hashString(const std::string& text);

/// Splits one CSV line (comma separated, double quotes with "" escapes).
std::vector<std::string> splitCsvLine(const std::string& line);

}  // namespace tools
}  // namespace cvg_bench

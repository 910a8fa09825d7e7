// Input files of the offline tool: CSV (record_io.h) or rosbag (`.bag`, read with the rosbag API in
// builds with CVG_WITH_ROSBAG, i.e. the catkin build; the core-only build says it cannot).
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/io/record_io.h"
#include "cvg_bench/core/io/records.h"

namespace cvg_bench {
namespace tools {

/// True when the path names a rosbag (ends in ".bag").
bool isBagInput(const std::string& path);

/// Reads a record from a CSV file or a bag. For a bag, `topic` picks the topic (empty = the one
/// topic of the first acceptable kind, in `kinds` order: identify passes {free decay, forced, raw},
/// demod {raw}); for a CSV, a non-empty topic is an InputError. InputError on every problem.
AnyRecord readRecordInput(const std::string& path, const RecordReadOptions& options = {},
                          const std::string& topic = "",
                          const std::vector<RecordKind>& kinds = {
                              RecordKind::kFreeDecay, RecordKind::kForcedSweep, RecordKind::kRaw});

}  // namespace tools
}  // namespace cvg_bench

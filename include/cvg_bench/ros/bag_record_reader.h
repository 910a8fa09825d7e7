// Reading the project's messages from a rosbag into the core's records (interfaces.md "Input
// files":
// `.bag` files are read with the rosbag API, picking the project's message types by topic type or
// by an explicit topic). ROS-free interface: the offline tool includes it (CVG_WITH_ROSBAG builds).
//
//   cvg_bench/SlowState       -> SlowRecord  (free decay; t_s from the first message's stamp)
//   cvg_bench/SweepPoint      -> SweepRecord (forced; direction/jump flags kept)
//   cvg_bench/RawSampleBatch  -> RawRecord   (t_s from the first batch's phase_epoch, else its
//   stamp;
//                                              an `omega0` extra column when a drive is on)
// Every problem is an InputError naming the file (and topic, message index): not a bag, truncated
// or unreadable, no project topic, an ambiguous choice, a wrong topic type, an empty topic, a
// message definition that differs from this build, non-finite values, time going backwards.
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/io/record_io.h"
#include "cvg_bench/core/io/records.h"

namespace cvg_bench {

struct BagReadOptions {
  /// Topic to read; empty = the one topic of the first kind in `kinds` the bag has.
  std::string topic;
  /// Record kinds acceptable to the caller, in order of preference (identify: slow, sweep, raw;
  /// demod: raw only). Must not be empty.
  std::vector<RecordKind> kinds = {RecordKind::kFreeDecay, RecordKind::kForcedSweep,
                                   RecordKind::kRaw};
  /// Raw records: sort samples that arrive out of time order and drop repeated timestamps (counted
  /// in RawRecord::n_reordered / n_duplicates_dropped) instead of failing.
  bool repair_raw_timestamps = false;
};

/// True when the path names a rosbag (ends in ".bag").
bool isBagPath(const std::string& path);

/// Reads one topic of a bag into a record (AnyRecord::kind says which). metadata gets `mode`,
/// `omega` (when known), `topic`, `message_type` and `stamp_origin` (the absolute ros::Time of t =
/// 0, as "sec.nsec").
AnyRecord readRecordBag(const std::string& path, const BagReadOptions& options = {});

/// The topics of a bag with their message types ("topic type count" per line), for messages.
std::string describeBagTopics(const std::string& path);

}  // namespace cvg_bench

// CSV or bag input for the tool's subcommands (see bag_input.h).
#include "bag_input.h"

#include <iostream>

#include "cvg_bench/core/common/errors.h"
#ifdef CVG_WITH_ROSBAG
#include "cvg_bench/core/demod/demodulator.h"
#include "cvg_bench/ros/bag_record_reader.h"
#include "cvg_bench/ros/demodulator_node_options.h"
#endif

namespace cvg_bench {
namespace tools {

bool isBagInput(const std::string& path) {
  return path.size() > 4 && path.compare(path.size() - 4, 4, ".bag") == 0;
}

AnyRecord readRecordInput(const std::string& path, const RecordReadOptions& options,
                          const std::string& topic, const std::vector<RecordKind>& kinds) {
  if (!isBagInput(path)) {
    if (!topic.empty()) throw InputError("--topic applies to .bag input only, not to " + path);
    AnyRecord rec = readRecordCsv(path, options);
    bool acceptable = false;
    for (RecordKind k : kinds) acceptable = acceptable || k == rec.kind;
    if (!acceptable)
      throw InputError(path + ": holds a " + recordKindName(rec.kind) +
                       " record, which this subcommand does not take");
    return rec;
  }
#ifdef CVG_WITH_ROSBAG
  BagReadOptions bag_options;
  bag_options.topic = topic;
  bag_options.kinds = kinds;
  bag_options.repair_raw_timestamps = options.repair_raw_timestamps;
  AnyRecord rec = readRecordBag(path, bag_options);
  const RecordMetadata& md = rec.kind == RecordKind::kRaw           ? rec.raw.metadata
                             : rec.kind == RecordKind::kForcedSweep ? rec.sweep.metadata
                                                                    : rec.slow.metadata;
  const auto missing = md.find("messages_missing_by_sequence");
  if (missing != md.end())
    std::cerr << "cvg_ident: warning: " << path << ": topic '" << md.at("topic")
              << "': " << missing->second
              << " messages missing by header sequence number (the recording dropped them; "
                 "record with launch/record.launch); their span is a gap in the record\n";
  bool wants_slow = false;
  for (RecordKind k : kinds) wants_slow = wants_slow || k == RecordKind::kFreeDecay;
  if (rec.kind != RecordKind::kRaw || !wants_slow) return rec;
  // Offline = live: a raw bag is demodulated as demodulator_node does, with the shipped node
  // settings (config/demodulator.yaml: output rate, filter) and the bag's reference frequency.
  const std::string config = std::string(CVG_BENCH_SOURCE_DIR) + "/config/demodulator.yaml";
  ParamReader reader = ParamReader::fromYamlFile(config);
  const DemodulatorNodeOptions node = loadOptions<DemodulatorNodeOptions>(reader);
  DemodulatorOptions o = node.filter;
  o.omega_rad_s = node.omega_rad_s > 0.0 ? node.omega_rad_s : rec.raw.omega_rad_s;
  const SamplingSummary sampling = summarizeSampling(rec.raw.t_s);
  o.sample_rate_hz =
      node.sample_rate_hz > 0.0 ? node.sample_rate_hz : 1.0 / sampling.median_interval_s;
  if (!(o.omega_rad_s > 0.0) || !sampling.uniform) return rec;  // the subcommand's own path
  AnyRecord slow;
  slow.kind = RecordKind::kFreeDecay;
  slow.slow = demodulateUniform(rec.raw, o);
  slow.slow.source = rec.raw.source;
  slow.slow.omega_rad_s = rec.raw.omega_rad_s;
  if (missing != md.end()) slow.slow.metadata[missing->first] = missing->second;
  slow.slow.metadata["demodulated"] =
      "as demodulator_node with " + config + " at " + std::to_string(o.output_rate_hz) + " Hz";
  return slow;
#else
  throw InputError(path +
                   ": this build of cvg_ident has no rosbag support (core-only build); "
                   "use the catkin build (make build) or export the topic to CSV");
#endif
}

}  // namespace tools
}  // namespace cvg_bench

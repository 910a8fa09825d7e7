// CSV or bag input for the tool's subcommands (see bag_input.h).
#include "bag_input.h"

#include "cvg_bench/core/model/errors.h"
#ifdef CVG_WITH_ROSBAG
#include "cvg_bench/ros/bag_record_reader.h"
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
  return readRecordBag(path, bag_options);
#else
  throw InputError(path +
                   ": this build of cvg_ident has no rosbag support (core-only build); "
                   "use the catkin build (make build) or export the topic to CSV");
#endif
}

}  // namespace tools
}  // namespace cvg_bench

// libFuzzer target: the rosbag record reader (identify/explain/demod on a .bag), every record kind.
#include <cstdint>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/ros/bag_record_reader.h"
#include "fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = cvg_bench_fuzz::writeInput(data, size, ".bag");
  cvg_bench::BagReadOptions o;
  o.kinds = {cvg_bench::RecordKind::kFreeDecay, cvg_bench::RecordKind::kForcedSweep,
             cvg_bench::RecordKind::kRaw};
  o.repair_raw_timestamps = true;
  try {
    const cvg_bench::AnyRecord r = cvg_bench::readRecordBag(path, o);
    (void)r.omegaRadS();
  } catch (const cvg_bench::InputError&) {
  }
  return 0;
}

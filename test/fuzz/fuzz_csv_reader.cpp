// libFuzzer target: the CSV record reader (interfaces.md "Input files"), strict and repairing.
#include <cstdint>
#include <string>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/io/record_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  for (bool repair : {false, true}) {
    cvg_bench::RecordReadOptions o;
    o.repair_raw_timestamps = repair;
    try {
      const cvg_bench::AnyRecord r = cvg_bench::readRecordCsvText(text, "fuzz.csv", o);
      (void)r.omegaRadS();
    } catch (const cvg_bench::InputError&) {
    }
  }
  return 0;
}

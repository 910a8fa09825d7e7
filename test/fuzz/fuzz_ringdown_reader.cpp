// libFuzzer target: the single-channel ring-down CSV reader (interfaces.md "Single-channel
// ring-downs": amplitude or power_db, `#`/`%` comments, instrument headers).
#include <cstdint>
#include <string>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/io/ringdown_record.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const cvg_bench::RingdownRecord r = cvg_bench::readRingdownCsvText(text, "fuzz.csv");
    (void)r;
  } catch (const cvg_bench::InputError&) {
  }
  return 0;
}

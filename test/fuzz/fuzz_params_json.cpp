// libFuzzer target: the `drift --params` JSON reader.
#include <cstdint>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/report/estimate_json.h"
#include "fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = cvg_bench_fuzz::writeInput(data, size, ".json");
  try {
    const cvg_bench::report::ParameterFile f = cvg_bench::report::readParameterFile(path);
    (void)f.values.size();
  } catch (const cvg_bench::InputError&) {
  }
  return 0;
}

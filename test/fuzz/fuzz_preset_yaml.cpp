// libFuzzer target: the resonator preset YAML reader (`simulate --config`).
#include <cstdint>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/model/resonator_preset.h"
#include "fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = cvg_bench_fuzz::writeInput(data, size, ".yaml");
  try {
    const cvg_bench::ResonatorPreset p = cvg_bench::loadResonatorPresetFile(path);
    (void)p.name.size();
  } catch (const cvg_bench::InputError&) {
  }
  return 0;
}

// libFuzzer target: the files `cvg_ident batch` reads back (docs/fleet.md): a manifest CSV
// (expandBatchInputs), a record's status file (readBatchStatus) and a status/record JSON turned
// into a fleet row (fleetRow), as a hand-edited, truncated or foreign file may hold anything. Only
// InputError may leave them.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "../../src/tools/batch_inputs.h"
#include "../../src/tools/batch_runner.h"
#include "../../src/tools/fleet_table.h"
#include "cvg_bench/core/common/errors.h"
#include "fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace cvg_bench::tools;
  const std::string path = cvg_bench_fuzz::writeInput(data, size, "_manifest.csv");
  try {
    const auto records = expandBatchInputs({path});
    for (const auto& r : records)
      if (r.name.empty() || r.input.empty()) __builtin_trap();
  } catch (const cvg_bench::InputError&) {
  }
  readBatchStatus(path);
  const nlohmann::json j = nlohmann::json::parse(data, data + size, nullptr, false);
  if (!j.is_discarded()) {
    fleetRow(FleetEntry{j, j});
    if (j.is_object() && j.contains("status") && j.contains("result"))
      fleetRow(FleetEntry{j["status"], j["result"]});
  }
  return 0;
}

// libFuzzer target: the one-mode frequency-response reader (docs/response.md "Input": named or
// headerless columns, `--columns`, comments) and the sweep splitter on what it reads.
#include <cstdint>
#include <string>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/io/response_record.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  // A first line starting with '@' is the --columns option (the rest of the line).
  std::string columns;
  if (!text.empty() && text[0] == '@') {
    const size_t nl = text.find('\n');
    columns = text.substr(1, nl == std::string::npos ? std::string::npos : nl - 1);
    text = nl == std::string::npos ? "" : text.substr(nl + 1);
  }
  try {
    const cvg_bench::ResponseRecord r = cvg_bench::readResponseText(text, "fuzz.txt", columns);
    const std::vector<int> s = cvg_bench::splitSweeps(r);
    if (s.size() != r.size()) __builtin_trap();
  } catch (const cvg_bench::InputError&) {
  }
  return 0;
}

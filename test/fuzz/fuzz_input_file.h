// Shared by the libFuzzer targets: the readers under test take a file name, so each input is
// written to one temporary file per process first. Only the documented errors (InputError: bad
// input, exit 2; AnalysisError) may leave a reader; anything else, and any sanitizer report, is a
// finding.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

namespace cvg_bench_fuzz {

inline std::string writeInput(const uint8_t* data, size_t size, const char* suffix) {
  static const std::string path =
      std::string("/tmp/cvg_fuzz_") + std::to_string(::getpid()) + suffix;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) __builtin_trap();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) __builtin_trap();
  std::fclose(f);
  return path;
}

}  // namespace cvg_bench_fuzz

// Creates the --report directory of explain (and its parents); InputError when it cannot.
#pragma once

#include <string>

namespace cvg_bench {
namespace tools {

void makeReportDirectory(const std::string& dir);

}  // namespace tools
}  // namespace cvg_bench

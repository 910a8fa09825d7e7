// Placeholder until its issue lands: says so clearly (exit 2).
#include <iostream>

#include "cvg_ident_commands.h"

namespace cvg_bench {
namespace tools {

int runDemod(const std::vector<std::string>&) {
  std::cerr << "cvg_ident demod: not implemented yet in this build\n";
  return 2;
}

}  // namespace tools
}  // namespace cvg_bench

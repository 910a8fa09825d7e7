// --report directories (report_directory.h).
#include "report_directory.h"

#include <sys/stat.h>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace tools {

void makeReportDirectory(const std::string& dir) {
  std::string partial;
  for (size_t i = 0; i <= dir.size(); ++i) {
    if ((i == dir.size() || dir[i] == '/') && !partial.empty()) ::mkdir(partial.c_str(), 0755);
    if (i < dir.size()) partial += dir[i];
  }
  struct stat st;
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
    throw InputError("--report: cannot create directory '" + dir + "'");
}

}  // namespace tools
}  // namespace cvg_bench

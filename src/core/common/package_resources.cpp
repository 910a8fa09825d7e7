#include "cvg_bench/core/common/package_resources.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <system_error>

namespace cvg_bench {
namespace fs = std::filesystem;

std::string executableDirectory() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : exe.parent_path().string();
}

std::vector<std::string> packageResourceRoots() {
  std::vector<fs::path> candidates;
  const std::string exe_dir = executableDirectory();
  if (!exe_dir.empty())
    candidates.push_back(fs::path(exe_dir) / ".." / ".." / "share" / "cvg_bench");
  if (const char* rpp = std::getenv("ROS_PACKAGE_PATH")) {
    std::stringstream ss(rpp);
    std::string entry;
    while (std::getline(ss, entry, ':')) {
      if (entry.empty()) continue;
      if (fs::path(entry).filename() == "cvg_bench") candidates.push_back(entry);
      candidates.push_back(fs::path(entry) / "cvg_bench");
    }
  }
  candidates.push_back(CVG_BENCH_SOURCE_DIR);
  std::vector<std::string> roots;
  for (const auto& c : candidates) {
    std::error_code ec;
    if (!fs::is_regular_file(c / "package.xml", ec)) continue;
    const std::string root = fs::weakly_canonical(c, ec).string();
    if (!ec && std::find(roots.begin(), roots.end(), root) == roots.end()) roots.push_back(root);
  }
  return roots;
}

std::string findPackageResource(const std::string& relative) {
  for (const auto& root : packageResourceRoots()) {
    std::error_code ec;
    const fs::path p = fs::path(root) / relative;
    if (fs::exists(p, ec)) return p.string();
  }
  return "";
}

}  // namespace cvg_bench

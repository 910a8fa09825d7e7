// Where the package's run-time files (presets, scripts, launch and config files) are found, so
// that an installed package works without the source tree it was built from. Candidates, most
// specific first:
//   1. the install space's share/cvg_bench next to the running executable
//      (<prefix>/lib/cvg_bench/<exe> -> <prefix>/share/cvg_bench);
//   2. every entry of ROS_PACKAGE_PATH that is or holds the package `cvg_bench`;
//   3. the source tree this library was compiled from (a development build without ROS).
#pragma once

#include <string>
#include <vector>

namespace cvg_bench {

/// Directory of the running executable (from /proc/self/exe), "" when unknown.
std::string executableDirectory();

/// The package roots above that exist, in that order (no duplicates).
std::vector<std::string> packageResourceRoots();

/// The first existing root/relative (e.g. "config/resonators"), "" when none exists.
std::string findPackageResource(const std::string& relative);

}  // namespace cvg_bench

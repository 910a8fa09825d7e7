#include "cvg_bench/core/io/input_checks.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/number_text.h"
#include "cvg_bench/core/common/sample_median.h"

namespace cvg_bench {
namespace {

namespace fs = std::filesystem;

double median(const std::vector<double>& v) {
  return sampleMedian(v, 0.0);
}

}  // namespace

void requireOmegaInRange(double omega_rad_s, const std::string& what) {
  if (!std::isfinite(omega_rad_s) || !(omega_rad_s > 0.0) || omega_rad_s > kMaxOmegaRadS)
    throw InputError(what + ": omega " + printfGText(omega_rad_s, 6) +
                     " rad/s is out of range (must be > 0 " +
                     "and <= " + printfGText(kMaxOmegaRadS, 6) + " rad/s)");
}

void requireInputFile(const std::string& path, const std::string& what) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (path.empty()) throw InputError(what + ": empty file name");
  if (ec || !fs::exists(st)) throw InputError(path + ": " + what + " does not exist");
  if (fs::is_directory(st)) throw InputError(path + ": " + what + " is a directory, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": " + what + " cannot be opened for reading");
}

void requireOutputFile(const std::string& path, const std::string& what) {
  if (path.empty()) throw InputError(what + ": empty file name");
  std::error_code ec;
  if (fs::is_directory(path, ec))
    throw InputError(path + ": " + what + " is a directory; give a file name");
  fs::path parent = fs::path(path).parent_path();
  if (parent.empty()) parent = ".";
  if (!fs::is_directory(parent, ec))
    throw InputError(path + ": " + what + ": directory " + parent.string() + " does not exist");
  if (fs::exists(path, ec) ? ::access(path.c_str(), W_OK) != 0
                           : ::access(parent.c_str(), W_OK) != 0)
    throw InputError(path + ": " + what + " is not writable");
}

void checkStateColumns(const std::vector<std::pair<std::string, const std::vector<double>*>>& cols,
                       const RowLocator& where) {
  if (cols.empty()) return;
  const size_t n = cols.front().second->size();
  std::vector<double> row_max(n, 0.0);
  for (const auto& c : cols) {
    const std::vector<double>& v = *c.second;
    for (size_t r = 0; r < n; ++r) {
      if (!std::isfinite(v[r]))
        throw InputError(where(r, c.first) + "column '" + c.first + "': " + printfGText(v[r], 6) +
                         " is not finite");
      if (std::fabs(v[r]) > kMaxStateMagnitude)
        throw InputError(where(r, c.first) + "column '" + c.first + "': " + printfGText(v[r], 6) +
                         " [record units] is out of range (|value| > " +
                         printfGText(kMaxStateMagnitude, 6) + ")");
      row_max[r] = std::max(row_max[r], std::fabs(v[r]));
    }
  }
  const double typical = median(row_max);
  if (!(typical > 0.0)) return;  // all-zero records are judged by the data-sufficiency checks
  const double limit = kMaxStateOverTypical * typical;
  for (const auto& c : cols) {
    const std::vector<double>& v = *c.second;
    for (size_t r = 0; r < n; ++r) {
      if (std::fabs(v[r]) > limit)
        throw InputError(where(r, c.first) + "column '" + c.first + "': " + printfGText(v[r], 6) +
                         " [record units] is " + printfGText(std::fabs(v[r]) / typical, 6) +
                         " times the record's typical magnitude " + printfGText(typical, 6) +
                         " (limit " + printfGText(kMaxStateOverTypical, 6) +
                         "x): a corrupted sample");
    }
  }
}

void checkTimeColumn(const std::vector<double>& t_s, const std::string& name,
                     const RowLocator& where) {
  for (size_t r = 0; r < t_s.size(); ++r) {
    if (!std::isfinite(t_s[r]) || std::fabs(t_s[r]) > kMaxTimeS)
      throw InputError(where(r, name) + "time " + printfGText(t_s[r], 6) +
                       " s is out of range (|t| <= " + printfGText(kMaxTimeS, 6) + " s)");
  }
  if (t_s.size() < 3) return;
  std::vector<double> dt(t_s.size() - 1);
  for (size_t r = 1; r < t_s.size(); ++r) dt[r - 1] = t_s[r] - t_s[r - 1];
  const double typical = median(dt);
  if (!(typical > 0.0)) return;
  for (size_t r = 1; r < t_s.size(); ++r) {
    if (dt[r - 1] > kMaxIntervalOverMedian * typical)
      throw InputError(where(r, name) + "time jumps by " + printfGText(dt[r - 1], 6) +
                       " s from the previous " + "sample, " + printfGText(dt[r - 1] / typical, 6) +
                       " times the median interval " + printfGText(typical, 6) + " s (limit " +
                       printfGText(kMaxIntervalOverMedian, 6) + "x): a clock jump");
  }
}

void checkExcitationColumn(const std::vector<double>& omega0_rad_s, const std::string& name,
                           const RowLocator& where) {
  for (size_t r = 0; r < omega0_rad_s.size(); ++r) {
    const double w = omega0_rad_s[r];
    if (!std::isfinite(w) || !(w > 0.0) || w > kMaxOmegaRadS)
      throw InputError(where(r, name) + "column '" + name + "': " + printfGText(w, 6) +
                       " rad/s is out of range (must be > 0 and <= " +
                       printfGText(kMaxOmegaRadS, 6) + " rad/s)");
  }
}

}  // namespace cvg_bench

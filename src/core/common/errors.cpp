#include "cvg_bench/core/common/errors.h"

#include <cmath>
#include <sstream>

namespace cvg_bench {

void requireFinite(double v, const std::string& what) {
  if (!std::isfinite(v)) {
    std::ostringstream s;
    s << what << " must be finite, got " << v;
    throw InputError(s.str());
  }
}

void requirePositive(double v, const std::string& what) {
  requireFinite(v, what);
  if (v <= 0.0) {
    std::ostringstream s;
    s << what << " must be > 0, got " << v;
    throw InputError(s.str());
  }
}

void throwIfInvalid(const std::string& what, const std::vector<std::string>& problems) {
  if (problems.empty()) return;
  std::string message = what + ":";
  for (const auto& p : problems) message += " " + p + ";";
  throw InputError(message);
}

}  // namespace cvg_bench

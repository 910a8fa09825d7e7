#include "cvg_bench/core/common/number_text.h"

#include <cstdio>
#include <sstream>

namespace cvg_bench {

std::string numberText(double v, int precision) {
  std::ostringstream s;
  s.precision(precision);
  s << v;
  return s.str();
}

std::string printfGText(double v, int precision) {
  char buf[64];
  const int n = std::snprintf(buf, sizeof(buf), "%.*g", precision, v);
  if (n < 0) return std::string();
  if (static_cast<size_t>(n) < sizeof(buf)) return std::string(buf, static_cast<size_t>(n));
  std::string long_text(static_cast<size_t>(n) + 1, '\0');
  std::snprintf(&long_text[0], long_text.size(), "%.*g", precision, v);
  long_text.resize(static_cast<size_t>(n));
  return long_text;
}

std::string fixedText(double v, int precision) {
  std::ostringstream s;
  s.precision(precision);
  s << std::fixed << v;
  return s.str();
}

std::string valueWithInterval(double value, double low, double high, int precision,
                              const std::string& unit) {
  std::ostringstream s;
  s.precision(precision);
  s << value;
  if (!unit.empty()) s << " " << unit;
  s << " [" << low << ", " << high << "]";
  return s.str();
}

}  // namespace cvg_bench

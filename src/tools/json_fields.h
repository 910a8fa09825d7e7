// Type-checked reads of fields of JSON files batch did not necessarily write itself (status and
// record files may be hand-edited, truncated or from another version): a missing field or one of
// another type gives the fallback instead of an exception.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace cvg_bench {
namespace tools {

inline std::string stringField(const nlohmann::json& j, const char* key,
                               const std::string& fallback = "") {
  if (!j.is_object()) return fallback;
  const auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : fallback;
}

inline long long intField(const nlohmann::json& j, const char* key, long long fallback) {
  if (!j.is_object()) return fallback;
  const auto it = j.find(key);
  return it != j.end() && (it->is_number_integer() || it->is_number_unsigned())
             ? it->get<long long>()
             : fallback;
}

inline bool boolField(const nlohmann::json& j, const char* key, bool fallback) {
  if (!j.is_object()) return fallback;
  const auto it = j.find(key);
  return it != j.end() && it->is_boolean() ? it->get<bool>() : fallback;
}

}  // namespace tools
}  // namespace cvg_bench

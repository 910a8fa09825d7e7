#include "cli_args.h"

#include <cmath>
#include <cstdlib>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace tools {

CliArgs::CliArgs(const std::vector<std::string>& argv, const std::set<std::string>& value_options,
                 const std::set<std::string>& flag_options,
                 const std::set<std::string>& repeatable_options) {
  for (size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (a == "--help" || a == "-h") {
      help_ = true;
      continue;
    }
    if (a.rfind("--", 0) != 0 || a.size() == 2) {
      positionals_.push_back(a);
      continue;
    }
    std::string key = a.substr(2), val;
    bool has_inline = false;
    const auto eq = key.find('=');
    if (eq != std::string::npos && value_options.count(key.substr(0, eq))) {
      val = key.substr(eq + 1);
      key = key.substr(0, eq);
      has_inline = true;
    }
    if (flag_options.count(key)) {
      values_[key].push_back("1");
    } else if (value_options.count(key) || repeatable_options.count(key)) {
      if (!has_inline) {
        if (i + 1 >= argv.size()) throw InputError("option --" + key + " needs a value");
        val = argv[++i];
      }
      if (values_.count(key) && !repeatable_options.count(key))
        throw InputError("option --" + key + " given twice");
      values_[key].push_back(val);
    } else {
      throw InputError("unknown option --" + key + " (see --help)");
    }
  }
}

bool CliArgs::has(const std::string& name) const {
  return values_.count(name) > 0;
}

std::string CliArgs::get(const std::string& name, const std::string& fallback) const {
  auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second.back();
}

double CliArgs::getDouble(const std::string& name, double fallback) const {
  if (!has(name)) return fallback;
  const std::string s = get(name);
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !std::isfinite(v))
    throw InputError("option --" + name + " needs a finite number, got '" + s + "'");
  return v;
}

long CliArgs::getInt(const std::string& name, long fallback) const {
  if (!has(name)) return fallback;
  const std::string s = get(name);
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0')
    throw InputError("option --" + name + " needs an integer, got '" + s + "'");
  return v;
}

std::vector<std::string> CliArgs::getAll(const std::string& name) const {
  auto it = values_.find(name);
  return it == values_.end() ? std::vector<std::string>{} : it->second;
}

}  // namespace tools
}  // namespace cvg_bench

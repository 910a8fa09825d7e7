// Minimal command-line parsing for cvg_ident subcommands: positionals, `--key value`, `--flag`,
// and repeatable options. Errors are cvg_bench::InputError (exit status 2).
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

namespace cvg_bench {
namespace tools {

class CliArgs {
 public:
  /// value_options take a value, flag_options do not, repeatable ones may appear many times.
  CliArgs(const std::vector<std::string>& argv, const std::set<std::string>& value_options,
          const std::set<std::string>& flag_options,
          const std::set<std::string>& repeatable_options = {});
  bool has(const std::string& name) const;
  std::string get(const std::string& name, const std::string& fallback = "") const;
  double getDouble(const std::string& name, double fallback) const;
  long getInt(const std::string& name, long fallback) const;
  std::vector<std::string> getAll(const std::string& name) const;
  const std::vector<std::string>& positionals() const { return positionals_; }
  bool help() const { return help_; }

 private:
  std::map<std::string, std::vector<std::string>> values_;
  std::vector<std::string> positionals_;
  bool help_ = false;
};

}  // namespace tools
}  // namespace cvg_bench

// Reads node settings once at start-up, from the ROS parameter server (a node's private namespace)
// or from a YAML map (config/*.yaml, for tests without roscore), collecting EVERY problem (wrong
// type, unknown key) instead of stopping at the first. Absent keys keep the caller's default.
#pragma once

#include <ros/node_handle.h>
#include <yaml-cpp/yaml.h>

#include <memory>
#include <set>
#include <string>
#include <vector>

namespace cvg_bench {

class ParamReader {
 public:
  /// Parameters under the node handle's namespace (use a private handle "~").
  explicit ParamReader(const ros::NodeHandle& nh);
  /// Parameters of a YAML map; source names the file in messages.
  ParamReader(const YAML::Node& map, const std::string& source);
  /// The YAML file's top-level map (its syntax errors are listed in problems()).
  static ParamReader fromYamlFile(const std::string& path);

  void get(const std::string& key, double& value);
  void get(const std::string& key, int& value);
  void get(const std::string& key, bool& value);
  void get(const std::string& key, std::string& value);

  /// Problems found so far: wrong types, plus (YAML only) keys nobody asked for, once
  /// finishUnknownKeyCheck() has run.
  const std::vector<std::string>& problems() const { return problems_; }
  /// Lists the YAML keys no get() asked for as problems (misspelt settings must not pass silently).
  void finishUnknownKeyCheck();
  /// "file.yaml" or the node's namespace, for messages.
  const std::string& source() const { return source_; }

 private:
  template <class T>
  void getImpl(const std::string& key, T& value, const char* type_name);

  std::unique_ptr<ros::NodeHandle> nh_;
  YAML::Node map_;
  std::string source_;
  std::set<std::string> asked_;
  std::vector<std::string> problems_;
};

/// Options of type T (with load(ParamReader&) and validate()) read from the reader; throws
/// InputError listing every problem (reader's and validate()'s) at once, one per line.
std::string joinProblems(const std::string& what, const std::vector<std::string>& problems);
void throwIfProblems(const std::string& what, const std::vector<std::string>& problems);

template <class T>
T loadOptions(ParamReader& reader) {
  T options;
  options.load(reader);
  reader.finishUnknownKeyCheck();
  std::vector<std::string> problems = reader.problems();
  for (const auto& p : options.validate()) problems.push_back(reader.source() + ": " + p);
  throwIfProblems("invalid settings", problems);
  return options;
}

}  // namespace cvg_bench

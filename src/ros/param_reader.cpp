// Start-up parameter reading with all problems collected (see param_reader.h).
#include "cvg_bench/ros/param_reader.h"

#include <ros/param.h>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {

ParamReader::ParamReader(const ros::NodeHandle& nh)
    : nh_(new ros::NodeHandle(nh)), source_(nh.getNamespace()) {}

ParamReader::ParamReader(const YAML::Node& map, const std::string& source)
    : map_(map), source_(source) {
  if (map_ && !map_.IsNull() && !map_.IsMap()) problems_.push_back(source + ": not a YAML map");
}

ParamReader ParamReader::fromYamlFile(const std::string& path) {
  try {
    return ParamReader(YAML::LoadFile(path), path);
  } catch (const YAML::Exception& e) {
    ParamReader r(YAML::Node(), path);
    r.problems_.push_back(path + ":" + std::to_string(e.mark.line + 1) + ":" +
                          std::to_string(e.mark.column + 1) + ": " + e.msg);
    return r;
  }
}

template <class T>
void ParamReader::getImpl(const std::string& key, T& value, const char* type_name) {
  asked_.insert(key);
  if (nh_) {
    if (!nh_->hasParam(key)) return;
    T v;
    if (nh_->getParam(key, v)) {
      value = v;
      return;
    }
    problems_.push_back(source_ + "/" + key + ": expected " + type_name);
    return;
  }
  if (!map_ || !map_.IsMap() || !map_[key]) return;
  try {
    value = map_[key].template as<T>();
  } catch (const YAML::Exception&) {
    problems_.push_back(source_ + ":" + std::to_string(map_[key].Mark().line + 1) + ": " + key +
                        ": expected " + type_name);
  }
}

void ParamReader::get(const std::string& key, double& value) {
  getImpl(key, value, "a number");
}
void ParamReader::get(const std::string& key, int& value) {
  getImpl(key, value, "an integer");
}
void ParamReader::get(const std::string& key, bool& value) {
  getImpl(key, value, "true or false");
}
void ParamReader::get(const std::string& key, std::string& value) {
  getImpl(key, value, "a string");
}

void ParamReader::finishUnknownKeyCheck() {
  if (nh_) {
    std::vector<std::string> names;
    if (!ros::param::getParamNames(names)) return;
    std::string prefix = nh_->getNamespace();
    if (prefix.empty() || prefix.back() != '/') prefix += "/";
    std::set<std::string> reported;
    for (const auto& name : names) {
      if (name.compare(0, prefix.size(), prefix) != 0) continue;
      const std::string key =
          name.substr(prefix.size(), name.find('/', prefix.size()) - prefix.size());
      if (!asked_.count(key) && reported.insert(key).second)
        problems_.push_back(prefix + key + ": unknown setting");
    }
    return;
  }
  if (!map_ || !map_.IsMap()) return;
  for (const auto& kv : map_) {
    const std::string key = kv.first.as<std::string>();
    if (!asked_.count(key))
      problems_.push_back(source_ + ":" + std::to_string(kv.first.Mark().line + 1) +
                          ": unknown setting '" + key + "'");
  }
}

std::string joinProblems(const std::string& what, const std::vector<std::string>& problems) {
  std::string out = what + " (" + std::to_string(problems.size()) + " problem" +
                    (problems.size() == 1 ? "" : "s") + "):";
  for (const auto& p : problems) out += "\n  " + p;
  return out;
}

void throwIfProblems(const std::string& what, const std::vector<std::string>& problems) {
  if (!problems.empty()) throw InputError(joinProblems(what, problems));
}

}  // namespace cvg_bench

#include "cvg_bench/core/model/resonator_preset.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <set>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/package_resources.h"

namespace cvg_bench {
namespace {

const std::vector<std::string> kDriveNames = {"u1", "u2", "u3", "u4"};

/// Model parameters a preset may set: every term's parameters except the drive.
std::vector<std::string> modelParameterNames() {
  std::vector<std::string> names;
  for (const auto& term_name : knownModelTermNames()) {
    for (const auto& p : makeModelTerm(term_name)->parameterNames()) {
      if (std::find(kDriveNames.begin(), kDriveNames.end(), p) == kDriveNames.end())
        names.push_back(p);
    }
  }
  return names;
}

std::string at(const YAML::Node& node) {
  const YAML::Mark m = node.Mark();
  if (m.line < 0) return "";
  return std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1) + ": ";
}

/// Reads the keys of one YAML map through the given setters; unknown keys and bad values are
/// collected as problems.
class SectionReader {
 public:
  SectionReader(const std::string& path, std::vector<std::string>& problems)
      : path_(path), problems_(problems) {}

  using Setter = std::function<void(const YAML::Node&)>;

  void read(const YAML::Node& map, const std::string& section,
            const std::map<std::string, Setter>& setters) {
    if (!map.IsMap()) {
      problems_.push_back(path_ + ":" + at(map) + "'" + section + "' must be a map of key: value");
      return;
    }
    for (const auto& kv : map) {
      if (!kv.first.IsScalar()) {  // a map or list used as a key (`? [a, b]: 1`)
        problems_.push_back(path_ + ":" + at(kv.first) + "a key in " + section + " is not text");
        continue;
      }
      const std::string key = kv.first.as<std::string>();
      const auto it = setters.find(key);
      if (it == setters.end()) {
        std::string known;
        for (const auto& s : setters) known += (known.empty() ? "" : ", ") + s.first;
        problems_.push_back(path_ + ":" + at(kv.first) + "unknown key '" + key + "' in " + section +
                            " (known: " + known + ")");
        continue;
      }
      it->second(kv.second);
    }
  }

  Setter number(double& target, const std::string& what) {
    return [this, &target, what](const YAML::Node& n) {
      try {
        target = n.as<double>();
        if (!std::isfinite(target))
          problems_.push_back(path_ + ":" + at(n) + what + " is not finite");
      } catch (const YAML::Exception&) {
        problems_.push_back(path_ + ":" + at(n) + what + " must be a number");
      }
    };
  }
  Setter integer(int& target, const std::string& what) {
    return [this, &target, what](const YAML::Node& n) {
      try {
        target = n.as<int>();
      } catch (const YAML::Exception&) {
        problems_.push_back(path_ + ":" + at(n) + what + " must be an integer");
      }
    };
  }
  Setter boolean(bool& target, const std::string& what) {
    return [this, &target, what](const YAML::Node& n) {
      try {
        target = n.as<bool>();
      } catch (const YAML::Exception&) {
        problems_.push_back(path_ + ":" + at(n) + what + " must be true or false");
      }
    };
  }
  Setter text(std::string& target, const std::string& what) {
    return [this, &target, what](const YAML::Node& n) {
      if (!n.IsScalar()) {
        problems_.push_back(path_ + ":" + at(n) + what + " must be text");
        return;
      }
      target = n.as<std::string>();
    };
  }

 private:
  std::string path_;
  std::vector<std::string>& problems_;
};

std::string joinProblems(const std::string& head, const std::vector<std::string>& problems) {
  std::string s = head;
  for (const auto& p : problems) s += "\n  " + p;
  return s;
}

}  // namespace

std::vector<std::string> effectNames() {
  std::vector<std::string> names = modelParameterNames();
  names.insert(names.end(), kDriveNames.begin(), kDriveNames.end());
  names.push_back("mu");
  names.push_back("eta");
  return names;
}

std::vector<std::string> ResonatorPreset::validate() const {
  std::vector<std::string> p;
  auto positive = [&p](double v, const std::string& what) {
    if (!(v > 0.0) || !std::isfinite(v))
      p.push_back(what + " must be > 0, got " + std::to_string(v));
  };
  auto non_negative = [&p](double v, const std::string& what) {
    if (!(v >= 0.0) || !std::isfinite(v))
      p.push_back(what + " must be >= 0, got " + std::to_string(v));
  };
  if (name.empty()) p.push_back("name is empty");
  positive(omega_rad_s, "omega_rad_s");
  const auto known = modelParameterNames();
  for (const auto& kv : parameters) {
    if (std::find(known.begin(), known.end(), kv.first) == known.end())
      p.push_back("unknown parameter '" + kv.first + "'");
    else if (!std::isfinite(kv.second))
      p.push_back("parameter " + kv.first + " is not finite");
  }
  const auto gamma = parameters.find("gamma");
  if (gamma == parameters.end() || !(gamma->second > 0.0))
    p.push_back("parameters.gamma must be > 0 (an undamped resonator never settles or decays)");
  if (!drive_u_tilde.allFinite()) p.push_back("controls u1..u4 must be finite");
  if (!std::isfinite(mu)) p.push_back("controls.mu must be finite");
  non_negative(eta, "controls.eta");
  non_negative(noise_q_std, "noise.q_std");
  non_negative(noise_fg_std, "noise.fg_std");
  if (steps_per_period < 4) p.push_back("integrator.steps_per_period must be >= 4");
  positive(decay_duration_s, "free_decay.duration_s");
  positive(decay_sample_rate_hz, "free_decay.sample_rate_hz");
  positive(decay_raw_duration_s, "free_decay.raw_duration_s");
  if (!std::isfinite(decay_drive_detuning_rad_s))
    p.push_back("free_decay.drive_detuning_rad_s must be finite");
  else if (omega_rad_s > 0 && !(omega_rad_s + decay_drive_detuning_rad_s > 0))
    p.push_back("free_decay.drive_detuning_rad_s makes the drive frequency <= 0");
  positive(raw_sample_rate_hz, "integrator.raw_sample_rate_hz");
  if (omega_rad_s > 0 && raw_sample_rate_hz > 0 && raw_sample_rate_hz <= omega_rad_s / M_PI)
    p.push_back("integrator.raw_sample_rate_hz " + std::to_string(raw_sample_rate_hz) +
                " is below the Nyquist rate omega / pi = " + std::to_string(omega_rad_s / M_PI));
  if (!std::isfinite(sweep_lambda_min_rad_s) || !std::isfinite(sweep_lambda_max_rad_s) ||
      !(sweep_lambda_min_rad_s < sweep_lambda_max_rad_s))
    p.push_back("forced.lambda_min_rad_s must be < forced.lambda_max_rad_s (both finite)");
  else if (omega_rad_s > 0 && !(omega_rad_s + sweep_lambda_min_rad_s > 0))
    p.push_back("forced.lambda_min_rad_s makes the drive frequency <= 0");
  if (sweep_points < 2) p.push_back("forced.points must be >= 2");
  positive(sweep_settle_time_s, "forced.settle_time_s");
  positive(sweep_settle_tolerance, "forced.settle_tolerance");
  positive(sweep_raw_duration_s, "forced.raw_duration_s");
  non_negative(sweep_raw_settle_s, "forced.raw_settle_s");
  return p;
}

void ResonatorPreset::applyEffect(const std::string& effect, double value) {
  if (!std::isfinite(value)) throw InputError("--effect " + effect + ": value must be finite");
  const auto drive = std::find(kDriveNames.begin(), kDriveNames.end(), effect);
  if (drive != kDriveNames.end()) {
    drive_u_tilde[drive - kDriveNames.begin()] = value;
  } else if (effect == "mu") {
    mu = value;
  } else if (effect == "eta") {
    if (value < 0) throw InputError("--effect eta: must be >= 0 (0 = off)");
    eta = value;
  } else {
    const auto known = modelParameterNames();
    if (std::find(known.begin(), known.end(), effect) == known.end()) {
      std::string list;
      for (const auto& n : effectNames()) list += (list.empty() ? "" : ", ") + n;
      throw InputError("--effect: unknown name '" + effect + "' (known: " + list + ")");
    }
    parameters[effect] = value;
  }
}

void ResonatorPreset::applyEffect(const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--effect needs NAME=VALUE, got '" + assignment + "'");
  const std::string value = assignment.substr(eq + 1);
  char* end = nullptr;
  const double v = std::strtod(value.c_str(), &end);
  if (value.empty() || *end != '\0')
    throw InputError("--effect " + assignment + ": '" + value + "' is not a number");
  applyEffect(assignment.substr(0, eq), v);
}

std::string ResonatorPreset::truthModelSpec(ExperimentMode mode, bool skip_inapplicable) const {
  std::string spec = "linear";
  for (const auto& term_name : knownModelTermNames()) {
    if (term_name == "linear" || term_name == "controls") continue;
    const auto term = makeModelTerm(term_name);
    bool nonzero = false;
    for (const auto& p : term->parameterNames()) {
      const auto it = parameters.find(p);
      if (it != parameters.end() && it->second != 0.0) nonzero = true;
    }
    if (!nonzero) continue;
    if (!term->appliesTo(mode) && skip_inapplicable) continue;
    if (!term->appliesTo(mode))
      throw InputError("effect '" + term_name + "' does not exist in " + experimentModeName(mode) +
                       " mode: set it to 0 (e.g. --effect " + term->parameterNames().front() +
                       "=0)");
    spec += "+" + term_name;
  }
  return spec;
}

Eigen::VectorXd ResonatorPreset::truthParameters(const ResonatorModel& model) const {
  ParameterValues values = parameters;
  if (model.mode() == ExperimentMode::kForced) {
    for (int i = 0; i < 4; ++i) values[kDriveNames[i]] = drive_u_tilde[i];
  }
  return model.parameterVector(values);
}

ResonatorPreset loadResonatorPresetFile(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw InputError(path + ": cannot open preset file");
  } catch (const YAML::ParserException& e) {
    throw InputError(path + ":" + std::to_string(e.mark.line + 1) + ":" +
                     std::to_string(e.mark.column + 1) + ": YAML syntax error: " + e.msg);
  }
  ResonatorPreset p;
  p.name = std::filesystem::path(path).stem().string();
  std::vector<std::string> problems;
  SectionReader r(path, problems);
  using Setter = SectionReader::Setter;
  std::map<std::string, Setter> parameter_setters;
  for (const auto& n : modelParameterNames()) {
    parameter_setters[n] = [&p, &r, n](const YAML::Node& node) {
      double v = 0.0;
      r.number(v, "parameters." + n)(node);
      p.parameters[n] = v;
    };
  }
  const std::map<std::string, Setter> controls = {
      {"u1", r.number(p.drive_u_tilde[0], "controls.u1")},
      {"u2", r.number(p.drive_u_tilde[1], "controls.u2")},
      {"u3", r.number(p.drive_u_tilde[2], "controls.u3")},
      {"u4", r.number(p.drive_u_tilde[3], "controls.u4")},
      {"mu", r.number(p.mu, "controls.mu")},
      {"eta", r.number(p.eta, "controls.eta")}};
  const std::map<std::string, Setter> noise = {
      {"q_std", r.number(p.noise_q_std, "noise.q_std")},
      {"fg_std", r.number(p.noise_fg_std, "noise.fg_std")}};
  const std::map<std::string, Setter> integrator = {
      {"steps_per_period", r.integer(p.steps_per_period, "integrator.steps_per_period")},
      {"raw_sample_rate_hz", r.number(p.raw_sample_rate_hz, "integrator.raw_sample_rate_hz")}};
  const std::map<std::string, Setter> free_decay = {
      {"duration_s", r.number(p.decay_duration_s, "free_decay.duration_s")},
      {"sample_rate_hz", r.number(p.decay_sample_rate_hz, "free_decay.sample_rate_hz")},
      {"raw_duration_s", r.number(p.decay_raw_duration_s, "free_decay.raw_duration_s")},
      {"drive_detuning_rad_s",
       r.number(p.decay_drive_detuning_rad_s, "free_decay.drive_detuning_rad_s")}};
  const std::map<std::string, Setter> forced = {
      {"lambda_min_rad_s", r.number(p.sweep_lambda_min_rad_s, "forced.lambda_min_rad_s")},
      {"lambda_max_rad_s", r.number(p.sweep_lambda_max_rad_s, "forced.lambda_max_rad_s")},
      {"points", r.integer(p.sweep_points, "forced.points")},
      {"settle_time_s", r.number(p.sweep_settle_time_s, "forced.settle_time_s")},
      {"settle_tolerance", r.number(p.sweep_settle_tolerance, "forced.settle_tolerance")},
      {"down_sweep", r.boolean(p.sweep_down, "forced.down_sweep")},
      {"raw_duration_s", r.number(p.sweep_raw_duration_s, "forced.raw_duration_s")},
      {"raw_settle_s", r.number(p.sweep_raw_settle_s, "forced.raw_settle_s")}};
  const std::map<std::string, Setter> top = {
      {"name", r.text(p.name, "name")},
      {"description", r.text(p.description, "description")},
      {"omega_rad_s", r.number(p.omega_rad_s, "omega_rad_s")},
      {"parameters", [&](const YAML::Node& n) { r.read(n, "parameters", parameter_setters); }},
      {"controls", [&](const YAML::Node& n) { r.read(n, "controls", controls); }},
      {"noise", [&](const YAML::Node& n) { r.read(n, "noise", noise); }},
      {"integrator", [&](const YAML::Node& n) { r.read(n, "integrator", integrator); }},
      {"free_decay", [&](const YAML::Node& n) { r.read(n, "free_decay", free_decay); }},
      {"forced", [&](const YAML::Node& n) { r.read(n, "forced", forced); }}};
  try {
    r.read(root, "the preset", top);
  } catch (const YAML::Exception& e) {  // any conversion the setters did not anticipate
    problems.push_back(path + ":" + std::to_string(e.mark.line + 1) + ":" +
                       std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
  for (const auto& v : p.validate()) problems.push_back(path + ": " + v);
  if (!problems.empty()) throw InputError(joinProblems("invalid preset " + path + ":", problems));
  return p;
}

std::string presetDirectory() {
  namespace fs = std::filesystem;
  if (const char* env = std::getenv("CVG_BENCH_PRESET_DIR")) return env;
  // The installed or source package (package_resources.h).
  const std::string shipped = findPackageResource("config/resonators");
  if (!shipped.empty()) return shipped;
  return (fs::current_path() / "config" / "resonators").string();
}

std::vector<std::string> shippedPresetNames() {
  namespace fs = std::filesystem;
  std::vector<std::string> names;
  const fs::path dir = presetDirectory();
  if (!fs::is_directory(dir)) return names;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ".yaml") names.push_back(e.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

ResonatorPreset loadShippedPreset(const std::string& name) {
  const auto names = shippedPresetNames();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    throw InputError("unknown preset '" + name + "' (known in " + presetDirectory() + ": " +
                     (list.empty() ? "none" : list) + ")");
  }
  return loadResonatorPresetFile(presetDirectory() + "/" + name + ".yaml");
}

}  // namespace cvg_bench

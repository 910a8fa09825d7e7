#include "cvg_bench/report/estimate_json.h"

#include <cmath>
#include <fstream>
#include <iostream>

#include "cvg_bench/core/model/errors.h"

namespace cvg_bench {
namespace report {
namespace {

nlohmann::json parameterToJson(const ParameterEstimate& p) {
  return {{"value", p.value}, {"std", p.std_error}, {"ci_low", p.ci_low}, {"ci_high", p.ci_high}};
}

/// Which method made the intervals, the residuals' serial correlation, near-collinearity.
void addIntervalDiagnostics(const Estimate& e, nlohmann::json* out) {
  nlohmann::json& j = *out;
  if (!e.interval_method_id.empty()) {
    j["interval_method_id"] = e.interval_method_id;
    j["residual_correlation"] = {{"lag1", e.residual_lag1},
                                 {"lag1_expected_independent", e.residual_lag1_expected},
                                 {"z", e.residual_lag1_z},
                                 {"correlated", e.residual_correlated},
                                 {"noise_model", e.noise_model}};
  }
  if (!e.vif.empty()) {
    nlohmann::json weak = nlohmann::json::array();
    for (const auto& w : e.weak_directions)
      weak.push_back({{"direction_column_normalized", w.first}, {"singular_value", w.second}});
    j["identifiability"] = {{"condition_number", e.condition_number},
                            {"vif", e.vif},
                            {"weak_directions", weak},
                            {"not_identified", e.not_identified}};
  }
  j["not_identified"] = e.not_identified;
  for (const auto& name : e.not_identified) {
    if (!j["parameters"].contains(name)) continue;
    j["parameters"][name]["identified"] = false;
    j["parameters"][name]["note"] =
        "not identified by this record (see identifiable_combinations and identifiability)";
  }
  if (!e.derived_method.empty()) j["derived_method"] = e.derived_method;
}

}  // namespace

nlohmann::json estimateToJson(const Estimate& e) {
  nlohmann::json j;
  j["mode"] = experimentModeName(e.mode);
  j["model"] = e.model;
  j["method"] = e.method;
  j["omega"] = e.omega_rad_s;
  j["n_equations"] = e.n_equations;
  j["n_params"] = e.n_params;
  j["rank"] = e.rank;
  j["dof"] = e.dof;
  j["unidentifiable"] = e.unidentifiable;
  if (!e.identifiability_note.empty()) j["identifiability_note"] = e.identifiability_note;
  j["sigma"] = e.sigma;
  j["confidence"] = e.confidence;
  nlohmann::json params = nlohmann::json::object();
  for (const auto& name : e.names) {
    auto it = e.parameters.find(name);
    if (it != e.parameters.end()) params[name] = parameterToJson(it->second);
  }
  for (const auto& kv : e.parameters)
    if (!params.contains(kv.first)) params[kv.first] = parameterToJson(kv.second);
  j["parameters"] = params;
  nlohmann::json derived = nlohmann::json::object();
  for (const auto& kv : e.derived) derived[kv.first] = kv.second.value;
  j["derived"] = derived;
  nlohmann::json derived_ci = nlohmann::json::object();
  for (const auto& kv : e.derived) derived_ci[kv.first] = parameterToJson(kv.second);
  j["derived_ci"] = derived_ci;
  if (e.covariance.size() > 0) {
    nlohmann::json rows = nlohmann::json::array();
    for (int r = 0; r < e.covariance.rows(); ++r) {
      nlohmann::json row = nlohmann::json::array();
      for (int c = 0; c < e.covariance.cols(); ++c) row.push_back(e.covariance(r, c));
      rows.push_back(row);
    }
    j["covariance"] = {{"names", e.names}, {"matrix", rows}};
  }
  if (!e.parameters_paper.empty()) {
    nlohmann::json paper = nlohmann::json::object();
    for (const auto& kv : e.parameters_paper) paper[kv.first] = parameterToJson(kv.second);
    j["parameters_paper_2_11"] = paper;
  }
  if (!e.interval_method.empty()) j["interval_method"] = e.interval_method;
  j["interval_dof"] = e.interval_dof;
  if (!e.combinations.empty()) {
    nlohmann::json comb = nlohmann::json::object();
    for (const auto& kv : e.combinations) comb[kv.first] = parameterToJson(kv.second);
    j["identifiable_combinations"] = comb;
  }
  if (!e.singular_values.empty()) j["singular_values"] = e.singular_values;
  addIntervalDiagnostics(e, &j);
  j["notes"] = e.notes;
  return j;
}

ParameterFile readParameterFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open parameter file");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(path + ": not valid JSON (" + e.what() + ")");
  }
  ParameterFile f;
  if (!j.is_object() || !j.contains("parameters") || !j["parameters"].is_object())
    throw InputError(path + ": needs an object member \"parameters\"");
  if (!j.contains("omega") || !j["omega"].is_number())
    throw InputError(path + ": needs a number member \"omega\" (natural frequency, rad/s)");
  f.omega_rad_s = j["omega"].get<double>();
  requirePositive(f.omega_rad_s, path + ": omega");
  for (const auto& kv : j["parameters"].items()) {
    double v;
    if (kv.value().is_number()) {
      v = kv.value().get<double>();
    } else if (kv.value().is_object() && kv.value().contains("value") &&
               kv.value()["value"].is_number()) {
      v = kv.value()["value"].get<double>();
    } else {
      throw InputError(path + ": parameter '" + kv.key() +
                       "' needs a number or {\"value\": number}");
    }
    requireFinite(v, path + ": parameter " + kv.key());
    f.values[kv.key()] = v;
  }
  if (j.contains("dof") && j["dof"].is_number_integer()) f.dof = j["dof"].get<int>();
  // The intervals of "parameters" use interval_dof (the honest covariance's quantile).
  if (j.contains("interval_dof") && j["interval_dof"].is_number_integer())
    f.dof = j["interval_dof"].get<int>();
  if (j.contains("confidence") && j["confidence"].is_number())
    f.confidence = j["confidence"].get<double>();
  if (j.contains("covariance") && j["covariance"].is_object()) {
    const auto& c = j["covariance"];
    if (!c.contains("names") || !c.contains("matrix"))
      throw InputError(path + ": covariance needs \"names\" and \"matrix\"");
    f.cov_names = c["names"].get<std::vector<std::string>>();
    const size_t n = f.cov_names.size();
    const auto& m = c["matrix"];
    if (!m.is_array() || m.size() != n) throw InputError(path + ": covariance matrix is not n x n");
    f.covariance.resize(n, n);
    for (size_t r = 0; r < n; ++r) {
      if (!m[r].is_array() || m[r].size() != n)
        throw InputError(path + ": covariance matrix is not n x n");
      for (size_t col = 0; col < n; ++col) {
        f.covariance(r, col) = m[r][col].get<double>();
        requireFinite(f.covariance(r, col), path + ": covariance entry");
      }
    }
  }
  return f;
}

void writeJsonFile(const nlohmann::json& j, const std::string& path) {
  if (path == "-") {
    std::cout << j.dump(2) << "\n";
    return;
  }
  std::ofstream out(path);
  if (!out) throw InputError(path + ": cannot write");
  out << j.dump(2) << "\n";
}

}  // namespace report
}  // namespace cvg_bench

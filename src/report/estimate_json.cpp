#include "cvg_bench/report/estimate_json.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <fstream>
#include <iostream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/sample_median.h"
#include "cvg_bench/core/io/input_checks.h"

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
      // Written symmetric: sandwich products leave round-off asymmetry of ~1e-7 relative.
      for (int c = 0; c < e.covariance.cols(); ++c)
        row.push_back(0.5 * (e.covariance(r, c) + e.covariance(c, r)));
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

namespace {

/// The covariance member: names (strings, each a parameter of the file), an n x n matrix of numbers
/// with non-negative variances on the diagonal, symmetric, and correlations within [-1, 1].
void readCovariance(const nlohmann::json& c, const std::string& path, ParameterFile* f) {
  if (!c.is_object() || !c.contains("names") || !c.contains("matrix"))
    throw InputError(path + ": covariance needs \"names\" and \"matrix\"");
  const auto& names = c["names"];
  if (!names.is_array()) throw InputError(path + ": covariance.names must be an array of names");
  for (size_t i = 0; i < names.size(); ++i) {
    if (!names[i].is_string())
      throw InputError(path + ": covariance.names[" + std::to_string(i) + "] is not a string");
    const std::string name = names[i].get<std::string>();
    if (!f->values.count(name))
      throw InputError(path + ": covariance.names[" + std::to_string(i) + "] '" + name +
                       "' is not one of the file's parameters");
    for (const auto& earlier : f->cov_names)
      if (earlier == name) throw InputError(path + ": covariance.names: '" + name + "' twice");
    f->cov_names.push_back(name);
  }
  const size_t n = f->cov_names.size();
  const auto& m = c["matrix"];
  if (!m.is_array() || m.size() != n)
    throw InputError(path + ": covariance.matrix is not " + std::to_string(n) + " x " +
                     std::to_string(n));
  f->covariance.resize(n, n);
  for (size_t r = 0; r < n; ++r) {
    if (!m[r].is_array() || m[r].size() != n)
      throw InputError(path + ": covariance.matrix row " + std::to_string(r) + " is not " +
                       std::to_string(n) + " numbers");
    for (size_t col = 0; col < n; ++col) {
      const std::string at =
          path + ": covariance.matrix[" + std::to_string(r) + "][" + std::to_string(col) + "]";
      if (!m[r][col].is_number()) throw InputError(at + " is not a number");
      f->covariance(r, col) = m[r][col].get<double>();
      requireFinite(f->covariance(r, col), at);
    }
  }
  for (size_t r = 0; r < n; ++r) {
    const double vr = f->covariance(r, r);
    if (vr < 0.0)
      throw InputError(path + ": covariance.matrix[" + std::to_string(r) + "][" +
                       std::to_string(r) + "]: variance of " + f->cov_names[r] + " is negative (" +
                       std::to_string(vr) + ")");
    for (size_t col = 0; col < r; ++col) {
      const double a = f->covariance(r, col), b = f->covariance(col, r);
      const double bound = std::sqrt(vr * f->covariance(col, col));
      const double tol = 1e-6 * (bound + std::fabs(a) + std::fabs(b)) + 1e-300;
      if (std::fabs(a - b) > tol)
        throw InputError(path + ": covariance.matrix is not symmetric at [" + std::to_string(r) +
                         "][" + std::to_string(col) + "]");
      if (std::fabs(a) > bound * (1.0 + 1e-9) + 1e-300)
        throw InputError(path + ": covariance.matrix[" + std::to_string(r) + "][" +
                         std::to_string(col) + "]: |covariance| of " + f->cov_names[r] + ", " +
                         f->cov_names[col] + " exceeds the product of their standard deviations");
    }
  }
  // Pairwise bounds do not make a matrix a covariance: its correlation matrix (over the entries
  // with a positive variance) must have no negative eigenvalue beyond rounding.
  std::vector<Eigen::Index> kept;
  for (size_t r = 0; r < n; ++r)
    if (f->covariance(r, r) > 0.0) kept.push_back(static_cast<Eigen::Index>(r));
  if (kept.size() > 1) {
    Eigen::MatrixXd corr(kept.size(), kept.size());
    for (size_t a = 0; a < kept.size(); ++a)
      for (size_t b = 0; b < kept.size(); ++b)
        corr(a, b) = 0.5 * (f->covariance(kept[a], kept[b]) + f->covariance(kept[b], kept[a])) /
                     std::sqrt(f->covariance(kept[a], kept[a]) * f->covariance(kept[b], kept[b]));
    // Rounding in a near-singular covariance (Ceres's, of a near-collinear model) leaves
    // eigenvalues of -1e-6 relative; a matrix that is not a covariance has them of order one.
    const Eigen::VectorXd ev =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(corr, Eigen::EigenvaluesOnly).eigenvalues();
    const double smallest = ev.minCoeff();
    if (smallest < -1e-3 * ev.maxCoeff())
      throw InputError(path +
                       ": covariance.matrix is not positive semi-definite (its correlation "
                       "matrix has the eigenvalue " +
                       std::to_string(smallest) + ")");
  }
}

int readDof(const nlohmann::json& j, const char* key, const std::string& path) {
  if (!j[key].is_number_integer() || j[key].get<long long>() < 0 ||
      j[key].get<long long>() > 1000000000LL)
    throw InputError(path + ": \"" + key +
                     "\" must be a non-negative integer (0 = normal quantile)");
  return static_cast<int>(j[key].get<long long>());
}

}  // namespace

ParameterFile readParameterFile(const std::string& path) {
  requireInputFile(path, "parameter file");
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open parameter file");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": not valid JSON (" + e.what() + ")");
  }
  return parameterFileFromJson(std::move(j), path);
}

ParameterFile parameterFileFromJson(nlohmann::json j, const std::string& path) {
  ParameterFile f;
  // explain --json: the record's own state, median r and k of its measured windows (orbit_reading).
  if (j.is_object() && j.contains("measured") && j["measured"].is_object() &&
      j["measured"].contains("windows") && j["measured"]["windows"].is_array()) {
    std::vector<double> r, k;
    for (const auto& w : j["measured"]["windows"])
      if (w.is_object() && w.contains("r") && w["r"].is_number() && w.contains("k") &&
          w["k"].is_number() && std::isfinite(w["r"].get<double>()) &&
          std::isfinite(w["k"].get<double>()) && w["r"].get<double>() > 0.0) {
        r.push_back(w["r"].get<double>());
        k.push_back(w["k"].get<double>());
      }
    if (!r.empty()) {
      f.has_record_state = true;
      f.record_r = sampleMedian(r);
      f.record_k = sampleMedian(k);
    }
  }
  // explain --json: the selected model's estimate is its "final" member (interfaces.md).
  if (j.is_object() && !j.contains("parameters") && j.contains("final") && j["final"].is_object()) {
    nlohmann::json final_estimate = j["final"];
    j = std::move(final_estimate);
  }
  if (j.is_object() && j.contains("mode") && j["mode"].is_string() &&
      (j["mode"] == "ringdown" || j["mode"] == "response"))
    throw InputError(path + ": a " + j["mode"].get<std::string>() +
                     " estimate (one mode) has no pattern drift; drift needs a two-mode model "
                     "(identify or explain --mode free_decay|forced)");
  if (!j.is_object() || !j.contains("parameters") || !j["parameters"].is_object())
    throw InputError(path +
                     ": needs an object member \"parameters\" (identify --json) or "
                     "\"final\" (explain --json)");
  // A rank-deficient estimate (identify exit 1, explain "does not determine"): its values along the
  // null space are arbitrary, so a drift or Q from it would be a number that means nothing (#25).
  if (j.contains("rank") && j["rank"].is_number_integer() && j.contains("n_params") &&
      j["n_params"].is_number_integer() && j["rank"].get<long>() < j["n_params"].get<long>()) {
    std::string list;
    if (j.contains("unidentifiable") && j["unidentifiable"].is_array())
      for (const auto& u : j["unidentifiable"])
        if (u.is_string()) list += (list.empty() ? "" : ", ") + u.get<std::string>();
    throw InputError(path + ": the estimate is rank-deficient (rank " +
                     std::to_string(j["rank"].get<long>()) + " of " +
                     std::to_string(j["n_params"].get<long>()) +
                     (list.empty() ? "" : "; not identified: " + list) +
                     "): the record does not determine its parameters, so no drift or Q follows "
                     "from it; identify from a longer record or several decays");
  }
  if (!j.contains("omega") || !j["omega"].is_number())
    throw InputError(path + ": needs a number member \"omega\" (natural frequency, rad/s)");
  f.omega_rad_s = j["omega"].get<double>();
  requireOmegaInRange(f.omega_rad_s, path + ": \"omega\"");
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
  if (j.contains("dof")) f.dof = readDof(j, "dof", path);
  // The intervals of "parameters" use interval_dof (the honest covariance's quantile).
  if (j.contains("interval_dof")) f.dof = readDof(j, "interval_dof", path);
  if (j.contains("confidence")) {
    if (!j["confidence"].is_number() || !(j["confidence"].get<double>() > 0.0) ||
        !(j["confidence"].get<double>() < 1.0))
      throw InputError(path + ": \"confidence\" must be a number in (0, 1)");
    f.confidence = j["confidence"].get<double>();
  }
  if (j.contains("covariance") && !j["covariance"].is_null())
    readCovariance(j["covariance"], path, &f);
  if (j.contains("model") && j["model"].is_string()) f.model = j["model"].get<std::string>();
  if (j.contains("derived_ci") && j["derived_ci"].is_object())
    for (const auto& kv : j["derived_ci"].items()) {
      const nlohmann::json& d = kv.value();
      if (!d.is_object()) continue;
      bool ok = true;
      for (const char* key : {"value", "std", "ci_low", "ci_high"})
        ok = ok && d.contains(key) && d[key].is_number();
      if (!ok) continue;
      ParameterEstimate pe;
      pe.value = d["value"].get<double>();
      pe.std_error = d["std"].get<double>();
      pe.ci_low = d["ci_low"].get<double>();
      pe.ci_high = d["ci_high"].get<double>();
      f.derived_ci[kv.key()] = pe;
    }
  return f;
}

UncertainParameters uncertainParameters(const ParameterFile& pf) {
  UncertainParameters up;
  up.values = pf.values;
  up.cov_names = pf.cov_names;
  up.covariance = pf.covariance;
  up.dof = pf.dof;
  up.confidence = pf.confidence;
  return up;
}

void writeJsonFile(const nlohmann::json& j, const std::string& path) {
  if (path == "-") {
    std::cout << j.dump(2) << "\n";
    return;
  }
  requireOutputFile(path, "JSON output");
  std::ofstream out(path);
  if (!out) throw InputError(path + ": cannot write");
  out << j.dump(2) << "\n";
  out.close();
  if (!out) throw InputError(path + ": write failed (disk full?)");
}

}  // namespace report
}  // namespace cvg_bench

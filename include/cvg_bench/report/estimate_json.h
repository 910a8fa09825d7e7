// JSON form of an estimate (interfaces.md "JSON output") and reading it back for `drift`.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "cvg_bench/core/estimate/estimate.h"
#include "cvg_bench/core/estimate/uncertainty/derived_uncertainty.h"
#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {
namespace report {

/// The identify JSON of interfaces.md (plus "dof", "method", "covariance", "notes").
nlohmann::json estimateToJson(const Estimate& e);

/// A parameter file as `drift` reads it: the identify JSON ({"omega", "parameters": {name:
/// {"value", ...}}, optional "covariance" {"names", "matrix"}}) or a flat {"omega", "parameters":
/// {name: number}}. Throws InputError naming the file and the problem.
struct ParameterFile {
  double omega_rad_s = 0.0;
  ParameterValues values;
  std::vector<std::string> cov_names;  ///< empty when the file has no covariance
  Eigen::MatrixXd covariance;
  int dof = 0;  ///< degrees of freedom for Student-t (0: normal quantile)
  double confidence = 0.95;
  std::string model;  ///< the file's "model" ("" when absent)
  /// The file's "derived_ci" (identify / explain's section-4 figures, each from what the record
  /// identifies); empty when absent (hand-written parameters).
  std::map<std::string, ParameterEstimate> derived_ci;
  /// explain --json: the record's median amplitude r and quadrature k over its measured windows
  /// (drift's default state); has_record_state false otherwise.
  bool has_record_state = false;
  double record_r = 0.0, record_k = 0.0;
};
ParameterFile readParameterFile(const std::string& path);
/// The same from parsed JSON (`path` names it in errors).
ParameterFile parameterFileFromJson(nlohmann::json j, const std::string& path);

/// The file's values with their covariance, as the delta-method functions take them.
UncertainParameters uncertainParameters(const ParameterFile& pf);

/// Writes JSON to path ("-" = stdout), pretty-printed; throws InputError if it cannot be written.
void writeJsonFile(const nlohmann::json& j, const std::string& path);

}  // namespace report
}  // namespace cvg_bench

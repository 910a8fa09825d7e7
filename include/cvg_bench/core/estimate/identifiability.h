// Identifiability of a regression: which parameters, or combinations, the data cannot separate,
// and why in words, from the null space of the column-equilibrated regression matrix.
// Example (docs/paper.md item 11): a pure standing wave (q2 = p2 = 0 throughout) gives rank 4 of 8
// in the linear model; only gamma+b_c, nu+b_s, c_m+h_c, n-h_s are determined.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace cvg_bench {

/// An identifiable linear combination sum_j coefficients_j z_j (in parameter units).
struct ParameterCombination {
  std::string name;              ///< e.g. "gamma+b_c", "n-h_s", "c_m+0.5*h_c"
  Eigen::VectorXd coefficients;  ///< length k
};

struct IdentifiabilityReport {
  int rank = 0;
  int num_params = 0;
  /// Parameters that enter the null space (cannot be estimated individually).
  std::vector<std::string> unidentifiable;
  /// Combinations of the unidentifiable parameters that ARE determined (reduced row-echelon basis).
  std::vector<ParameterCombination> combinations;
  /// Why, in words (empty at full rank).
  std::string note;
};

/// Facts about the data used to explain a rank deficiency (accumulated sample by sample).
struct ExcitationSummary {
  double max_amplitude = 0.0;  ///< max |q|
  double min_amplitude = 0.0;  ///< min |q|
  double max_mode1 = 0.0;      ///< max sqrt(q1^2 + p1^2)
  double max_mode2 = 0.0;      ///< max sqrt(q2^2 + p2^2)
  long num_points = 0;         ///< samples / sweep points
  void add(const Eigen::Vector4d& q);
  /// (max |q| - min |q|) / max |q| (0 without data).
  double amplitudeSpread() const;
};
/// The summary of a whole record's samples.
ExcitationSummary summarizeExcitation(const std::vector<Eigen::Vector4d>& q);

/// names: parameter names (z order); null_space: k x (k - rank), parameter units, and
/// column_norms: the regression matrix's column norms (both from LeastSquaresSolution). The
/// analysis runs in column-equilibrated units; null-space entries below coefficient_tolerance
/// count as 0.
IdentifiabilityReport analyzeIdentifiability(const std::vector<std::string>& names,
                                             const Eigen::MatrixXd& null_space,
                                             const Eigen::VectorXd& column_norms,
                                             const ExcitationSummary& excitation,
                                             double coefficient_tolerance = 1e-6);

}  // namespace cvg_bench

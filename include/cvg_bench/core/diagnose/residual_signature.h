// What a fitted model gets wrong, read from its equation-error residuals (2.8)/(3.4).
//
// Each 4-equation block's residual e = y - D z is projected on the two physical directions of the
// slow state q = (q1, p1, q2, p2) at the block (complex form a = q1 + i p1, b = q2 + i p2):
//   radial      e . q  / |q|   (amplitude-rate error: damping-like mismodelling)
//   tangential  e . Jq / |q|   (phase-rate error: frequency-like mismodelling),
// Jq = (-p1, q1, -p2, q2) = i (a, b). The signature correlates both with amplitude^2 (|q|^2),
// amplitude^4, time (free decay) or detuning lambda (forced), and the pattern angle theta (5.2);
// e.g. a missing cubic stiffness leaves a tangential residual growing with amplitude^2, a missing
// frequency drift one growing with time, a missing nonlinear damping a radial one with amplitude^2.
// Free-decay blocks share samples (docs/paper.md item 10): correlations and their p-values use
// every `stride`-th block (stride >= 3 makes the noise of the blocks used independent).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "cvg_bench/core/model/model_term.h"

namespace cvg_bench {

/// One block's residual and the variables it is compared with.
struct BlockResidual {
  double abscissa = 0.0;  ///< time since start [s] (free decay) or omega0 [rad/s] (forced)
  double detuning = 0.0;  ///< lambda = omega0 - omega [rad/s] (forced; 0 in free decay)
  Eigen::Vector4d e = Eigen::Vector4d::Zero();  ///< y - D z of the block
  Eigen::Vector4d q = Eigen::Vector4d::Zero();  ///< slow state at the block
  double radial = 0.0;                          ///< e . q / |q| (equation units)
  double tangential = 0.0;                      ///< e . Jq / |q| (equation units)
  double amp2 = 0.0;                            ///< |q|^2
  double theta = 0.0;                           ///< pattern angle (5.2) [rad]
};

/// Splits the stacked residual vector (4 entries per block) into blocks with their projections.
/// q_blocks and abscissa have one entry per block; detuning may be empty (free decay).
std::vector<BlockResidual> blockResiduals(const Eigen::VectorXd& residuals,
                                          const std::vector<Eigen::Vector4d>& q_blocks,
                                          const std::vector<double>& abscissa,
                                          const std::vector<double>& detuning);

/// Binned mean of a residual component against a variable (for the report's signature plot).
struct SignatureBin {
  double center = 0.0;  ///< mean of the variable in the bin
  double mean = 0.0;    ///< mean residual component
  double sem = 0.0;     ///< its standard error (from the blocks used)
  int count = 0;
};

struct SignatureEntry {
  std::string variable;      ///< "amplitude^2", "amplitude^4", "time", "detuning", "theta"
  std::string component;     ///< "radial" or "tangential"
  double correlation = 0.0;  ///< Pearson correlation over the blocks used
  double p_value = 1.0;      ///< two-sided, Student t with n_used - 2 dof
  int n_used = 0;
  std::vector<SignatureBin> bins;
};

struct ResidualSignature {
  std::vector<SignatureEntry> entries;
  /// The entry with the smallest p-value (nullptr when empty).
  const SignatureEntry* strongest() const;
  /// Entries with p < alpha / entries.size() (Bonferroni), in words; "no structure" otherwise.
  std::string describe(double alpha) const;
};

/// The signature of blocks (see the header comment). stride >= 1, num_bins >= 2.
ResidualSignature residualSignature(const std::vector<BlockResidual>& blocks, ExperimentMode mode,
                                    int stride, int num_bins);

/// Wald-Wolfowitz runs test of the signs of a sequence about its median (zeros and values equal
/// to the median dropped): too few runs means systematic structure. Normal approximation.
struct RunsTestResult {
  int n = 0;             ///< values used
  int runs = 0;          ///< observed runs
  double expected = 0;   ///< expected runs under independence
  double z = 0.0;        ///< (runs - expected) / sd
  double p_value = 1.0;  ///< one-sided: P(Z <= z) (too few runs)
};
RunsTestResult runsTest(const std::vector<double>& ordered_values);

}  // namespace cvg_bench

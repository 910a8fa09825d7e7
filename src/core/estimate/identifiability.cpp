#include "cvg_bench/core/estimate/identifiability.h"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "cvg_bench/core/model/model_term.h"

namespace cvg_bench {
namespace {

// An amplitude law's parameter (declared by its ModelTerm): constant amplitude cannot separate it.
bool isNonlinear(const std::string& name) {
  return isAmplitudeLawParameter(name);
}

std::string coefficientText(double c, bool first) {
  if (std::fabs(c - 1.0) < 1e-6) return first ? "" : "+";
  if (std::fabs(c + 1.0) < 1e-6) return "-";
  char buf[32];
  std::snprintf(buf, sizeof(buf), first ? "%.6g*" : "%+.6g*", c);
  return buf;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

}  // namespace

void ExcitationSummary::add(const Eigen::Vector4d& q) {
  const double a = q.norm();
  max_amplitude = num_points == 0 ? a : std::max(max_amplitude, a);
  min_amplitude = num_points == 0 ? a : std::min(min_amplitude, a);
  max_mode1 = std::max(max_mode1, std::hypot(q[0], q[1]));
  max_mode2 = std::max(max_mode2, std::hypot(q[2], q[3]));
  ++num_points;
}

double ExcitationSummary::amplitudeSpread() const {
  return max_amplitude > 0.0 ? (max_amplitude - min_amplitude) / max_amplitude : 0.0;
}

ExcitationSummary summarizeExcitation(const std::vector<Eigen::Vector4d>& q) {
  ExcitationSummary s;
  for (const auto& x : q) s.add(x);
  return s;
}

IdentifiabilityReport analyzeIdentifiability(const std::vector<std::string>& names,
                                             const Eigen::MatrixXd& null_space,
                                             const Eigen::VectorXd& column_norms,
                                             const ExcitationSummary& excitation,
                                             double coefficient_tolerance) {
  IdentifiabilityReport rep;
  const int k = static_cast<int>(names.size());
  const int m = static_cast<int>(null_space.cols());
  rep.num_params = k;
  rep.rank = k - m;
  if (m == 0) return rep;
  Eigen::VectorXd scale = column_norms;
  for (int j = 0; j < k; ++j)
    if (!(scale[j] > 0.0)) scale[j] = 1.0;
  // Null space in equilibrated units (w = scale .* z), orthonormalized.
  const Eigen::MatrixXd ns_raw = scale.asDiagonal() * null_space;
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(ns_raw);
  const Eigen::MatrixXd ns = qr.householderQ() * Eigen::MatrixXd::Identity(k, m);
  std::vector<int> involved;
  for (int j = 0; j < k; ++j) {
    if (ns.row(j).norm() > coefficient_tolerance) {
      involved.push_back(j);
      rep.unidentifiable.push_back(names[j]);
    }
  }
  // Combinations c (over the involved parameters) orthogonal to the null space are determined.
  const int p = static_cast<int>(involved.size());
  Eigen::MatrixXd ns_s(p, m);
  for (int i = 0; i < p; ++i) ns_s.row(i) = ns.row(involved[i]);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(ns_s, Eigen::ComputeFullU);
  int r = 0;
  for (int i = 0; i < svd.singularValues().size(); ++i)
    if (svd.singularValues()[i] > coefficient_tolerance) ++r;
  const int nc = p - r;
  if (nc > 0) {
    // Rows: combinations in parameter units (c_z = c_w .* scale), then reduced row-echelon form.
    Eigen::MatrixXd comb = svd.matrixU().rightCols(nc).transpose();
    for (int i = 0; i < p; ++i) comb.col(i) *= scale[involved[i]];
    int row = 0;
    for (int col = 0; col < p && row < nc; ++col) {
      Eigen::Index piv;
      const double best = comb.col(col).segment(row, nc - row).cwiseAbs().maxCoeff(&piv);
      if (best <= coefficient_tolerance * comb.cwiseAbs().maxCoeff()) continue;
      comb.row(row).swap(comb.row(row + piv));
      comb.row(row) /= comb(row, col);
      for (int i = 0; i < nc; ++i)
        if (i != row) comb.row(i) -= comb(i, col) * comb.row(row);
      ++row;
    }
    for (int i = 0; i < nc; ++i) {
      ParameterCombination c;
      c.coefficients = Eigen::VectorXd::Zero(k);
      bool first = true;
      for (int j = 0; j < p; ++j) {
        const double v = comb(i, j);
        if (std::fabs(v) < coefficient_tolerance) continue;
        c.coefficients[involved[j]] = v;
        c.name += coefficientText(v, first) + names[involved[j]];
        first = false;
      }
      if (!c.name.empty()) rep.combinations.push_back(c);
    }
  }
  // Why, in words.
  std::string why;
  const double tiny = 1e-12 * excitation.max_amplitude;
  if (excitation.max_amplitude <= 0.0) {
    why = "the data are all zero";
  } else if (excitation.max_mode2 <= tiny) {
    why =
        "no excitation of the second mode: q2 = p2 = 0 throughout, so the defects along the two "
        "axes cannot be told apart (a single standing wave at a pattern angle of 0); add a run at "
        "another pattern angle (e.g. pi/8) and identify the runs together";
  } else if (excitation.max_mode1 <= tiny) {
    why =
        "no excitation of the first mode: q1 = p1 = 0 throughout, so the defects along the two "
        "axes cannot be told apart; add a run at another pattern angle (e.g. pi/8)";
  } else if (excitation.amplitudeSpread() < 1e-9 &&
             std::any_of(rep.unidentifiable.begin(), rep.unidentifiable.end(), isNonlinear)) {
    why =
        "the amplitude is constant over the data, so amplitude-dependent terms cannot be told "
        "from the linear ones; use data over a range of amplitudes";
  } else {
    why =
        "the data do not excite enough independent directions of the model; vary the pattern "
        "angle, the amplitude or the detuning, or drop terms from the model";
  }
  rep.note = "rank " + std::to_string(rep.rank) + " of " + std::to_string(k) + ": " + why +
             ". Not separable: " + join(rep.unidentifiable) + ".";
  if (!rep.combinations.empty()) {
    std::vector<std::string> cn;
    for (const auto& c : rep.combinations) cn.push_back(c.name);
    rep.note += " Determined combinations: " + join(cn) + ".";
  }
  return rep;
}

}  // namespace cvg_bench

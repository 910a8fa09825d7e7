#include "cvg_bench/core/estimate/collinearity.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace {

/// Column-normalized loadings below this are not named in a weak direction's text; as
/// analyzeIdentifiability's coefficient tolerance on the weak space it also decides which
/// parameters enter the identified combinations reported beside the ones not identified (and drops
/// their coefficients below it). A reporting choice: it changes what the report names and which
/// combinations it lists, never a parameter's fitted value or interval. Set by hand (commit
/// efb8987), no recorded evidence; the collinearity report takes no options struct, so it stays a
/// constant here.
constexpr double kShownCoefficient = 0.05;

std::string directionText(const std::vector<std::string>& names, const Eigen::VectorXd& v) {
  std::vector<int> order(v.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return std::fabs(v[a]) > std::fabs(v[b]); });
  // Sign: the largest loading positive.
  const double sign = v[order[0]] < 0 ? -1.0 : 1.0;
  std::string s;
  for (int j : order) {
    if (std::fabs(v[j]) < kShownCoefficient) break;
    char buf[64];
    std::snprintf(buf, sizeof(buf), s.empty() ? "%.3g*%s" : " %+.3g*%s", sign * v[j],
                  names[j].c_str());
    s += buf;
  }
  return s;
}

}  // namespace

CollinearityReport analyzeCollinearity(const std::vector<std::string>& names,
                                       const Eigen::MatrixXd& jacobian, int n_reported) {
  const Eigen::Index p = jacobian.cols();
  if (static_cast<Eigen::Index>(names.size()) != p || p < 1 || n_reported > p)
    throw InputError("collinearity: " + std::to_string(names.size()) + " names for " +
                     std::to_string(p) + " columns");
  Eigen::VectorXd norms = jacobian.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < p; ++j)
    if (!(norms[j] > 0.0)) norms[j] = 1.0;
  const Eigen::MatrixXd js = jacobian * norms.cwiseInverse().asDiagonal();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(js, Eigen::ComputeThinV);
  const Eigen::VectorXd s = svd.singularValues();
  const Eigen::MatrixXd& v = svd.matrixV();
  CollinearityReport rep;
  rep.column_norms = norms;
  const double inf = std::numeric_limits<double>::infinity();
  rep.condition_number = s[s.size() - 1] > 0.0 ? s[0] / s[s.size() - 1] : inf;
  rep.vif.assign(p, 0.0);
  for (Eigen::Index j = 0; j < p; ++j) {
    double sum = 0.0;
    for (Eigen::Index i = 0; i < s.size(); ++i)
      sum += s[i] > 0.0 ? v(j, i) * v(j, i) / (s[i] * s[i]) : (v(j, i) != 0.0 ? inf : 0.0);
    rep.vif[j] = sum;
  }
  std::vector<int> weak_cols;
  for (Eigen::Index i = 0; i < s.size(); ++i) {
    if (!(s[i] < kWeakSingularValue)) continue;
    WeakDirection w;
    w.singular_value = s[i];
    w.text = directionText(names, v.col(i));
    w.coefficients = (norms.cwiseInverse().asDiagonal() * v.col(i)).normalized();
    rep.weak.push_back(w);
    weak_cols.push_back(static_cast<int>(i));
  }
  rep.weak_space.resize(p, static_cast<Eigen::Index>(rep.weak.size()));
  for (size_t c = 0; c < rep.weak.size(); ++c) rep.weak_space.col(c) = rep.weak[c].coefficients;
  for (int j = 0; j < n_reported; ++j)
    if (rep.vif[j] >= kNotIdentifiedVif) rep.not_identified.push_back(names[j]);
  return rep;
}

void reportCollinearity(const CollinearityReport& report, const std::vector<std::string>& names,
                        const Eigen::VectorXd& values, const Eigen::MatrixXd& covariance,
                        const ExcitationSummary& excitation, double s_p, Estimate* e) {
  e->vif.clear();
  e->weak_directions.clear();
  for (int j = 0; j < e->n_params && j < static_cast<int>(report.vif.size()); ++j)
    e->vif[names[j]] = report.vif[j];
  e->condition_number = report.condition_number;
  for (const auto& w : report.weak) e->weak_directions.emplace_back(w.text, w.singular_value);
  e->not_identified = report.not_identified;
  if (report.not_identified.empty()) return;
  // The weak directions play the null space's part: what is orthogonal to them is determined.
  const IdentifiabilityReport comb = analyzeIdentifiability(
      names, report.weak_space, report.column_norms, excitation, kShownCoefficient);
  std::string text;
  for (const auto& c : comb.combinations) {
    const double v = c.coefficients.dot(values);
    const double var = c.coefficients.dot(covariance * c.coefficients);
    ParameterEstimate p;
    p.value = v;
    p.std_error = std::sqrt(std::max(0.0, var));
    p.ci_low = v - s_p * p.std_error;
    p.ci_high = v + s_p * p.std_error;
    e->combinations[c.name] = p;
    text += (text.empty() ? "" : ", ") + c.name;
  }
  char cond[32];
  std::snprintf(cond, sizeof(cond), "%.3g", report.condition_number);
  std::string list, dirs;
  for (const auto& n : report.not_identified) {
    char buf[96];
    std::snprintf(buf, sizeof(buf), "%s (VIF %.3g)", n.c_str(), e->vif[n]);
    list += (list.empty() ? "" : ", ") + std::string(buf);
  }
  for (const auto& w : report.weak) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), " (singular value %.3g)", w.singular_value);
    dirs += (dirs.empty() ? "" : "; ") + w.text + buf;
  }
  e->identifiability_note =
      "near-collinear columns (condition number " + std::string(cond) +
      " of the column-normalized Jacobian): not identified by this record: " + list +
      ". Weakly identified direction(s), column-normalized: " + dirs + "." +
      (text.empty() ? std::string() : " Identified combinations: " + text + ".") +
      " The values of the parameters not identified are not estimates of their physical values.";
}

}  // namespace cvg_bench

#include "cvg_bench/core/diagnose/model_diagnosis.h"

#include <Eigen/SVD>
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/fisher_f.hpp>
#include <cmath>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {

double fUpperTail(double f, int df1, int df2) {
  if (!std::isfinite(f) || df1 < 1) return std::isinf(f) && f > 0 ? 0.0 : 1.0;
  if (f <= 0.0) return 1.0;
  if (df2 <= 0) {
    const boost::math::chi_squared dist(df1);
    return boost::math::cdf(boost::math::complement(dist, f * df1));
  }
  const boost::math::fisher_f dist(df1, df2);
  return boost::math::cdf(boost::math::complement(dist, f));
}

WaldTestResult waldTest(const Estimate& extended, const std::vector<std::string>& tested) {
  const int m = static_cast<int>(tested.size());
  std::vector<int> idx;
  for (const auto& name : tested) {
    const auto it = std::find(extended.names.begin(), extended.names.end(), name);
    if (it == extended.names.end())
      throw InputError("Wald test: '" + name + "' is not a parameter of model " + extended.model);
    idx.push_back(static_cast<int>(it - extended.names.begin()));
  }
  if (extended.covariance.rows() != static_cast<long>(extended.names.size()))
    throw InputError("Wald test: the estimate of " + extended.model + " has no covariance");
  Eigen::VectorXd za(m);
  Eigen::MatrixXd caa(m, m);
  for (int i = 0; i < m; ++i) {
    za[i] = extended.values[idx[i]];
    for (int j = 0; j < m; ++j) caa(i, j) = extended.covariance(idx[i], idx[j]);
  }
  // Pseudo-inverse by symmetric eigen/SVD: a rank-deficient block tests only what is determined.
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(caa, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd sv = svd.singularValues();
  const double tol = sv.size() ? sv[0] * 1e-12 : 0.0;
  int rank = 0;
  double w = 0.0;
  const Eigen::VectorXd uz = svd.matrixU().transpose() * za;
  for (int i = 0; i < sv.size(); ++i) {
    if (sv[i] > tol && sv[i] > 0.0) {
      ++rank;
      w += uz[i] * uz[i] / sv[i];
    }
  }
  WaldTestResult r;
  r.df1 = rank;
  r.df2 = extended.interval_dof;
  if (rank == 0) return r;
  r.f_statistic = w / rank;
  r.p_value = fUpperTail(r.f_statistic, r.df1, r.df2);
  return r;
}

double deltaBic(double rss_base, double rss_extended, long n_equations, int added_parameters) {
  if (!(rss_base > 0.0) || !(rss_extended > 0.0) || n_equations < 1) return 0.0;
  const double n = static_cast<double>(n_equations);
  return n * std::log(rss_extended / rss_base) + added_parameters * std::log(n);
}

}  // namespace cvg_bench

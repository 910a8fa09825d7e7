#include "cvg_bench/core/estimate/ceres_refinement.h"

#include <ceres/ceres.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <functional>
#include <mutex>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/demod/demodulator_noise.h"
#include "cvg_bench/core/estimate/collinearity.h"
#include "cvg_bench/core/estimate/dense_solver_options.h"
#include "cvg_bench/core/estimate/identifiability.h"
#include "cvg_bench/core/estimate/least_squares_solver.h"
#include "cvg_bench/core/estimate/output_error_forced.h"
#include "cvg_bench/core/estimate/output_error_free_decay.h"
#include "cvg_bench/core/estimate/uncertainty/derived_uncertainty.h"
#include "cvg_bench/core/estimate/uncertainty/fitted_residual_ar1.h"
#include "cvg_bench/core/estimate/uncertainty/hac_covariance.h"
#include "cvg_bench/core/estimate/uncertainty/residual_serial_correlation.h"
#include "cvg_bench/core/estimate/uncertainty/student_t.h"

namespace cvg_bench {

std::vector<std::string> CeresOptions::validate() const {
  std::vector<std::string> p;
  if (!(confidence > 0 && confidence < 1)) p.push_back("confidence must be in (0, 1)");
  if (max_iterations < 1) p.push_back("max_iterations must be >= 1");
  if (!(function_tolerance > 0)) p.push_back("function_tolerance must be > 0");
  if (!(likelihood_tolerance >= 0)) p.push_back("likelihood_tolerance must be >= 0");
  if (likelihood_tolerance_min_samples < 0)
    p.push_back("likelihood_tolerance_min_samples must be >= 0");
  if (!(parameter_tolerance > 0)) p.push_back("parameter_tolerance must be > 0");
  if (!(gradient_tolerance > 0)) p.push_back("gradient_tolerance must be > 0");
  if (rk4_substeps < 1 || rk4_substeps > 1000) p.push_back("rk4_substeps must be in 1..1000");
  if (coarse_samples < 0) p.push_back("coarse_samples must be >= 0");
  if (!std::isfinite(known_mu)) p.push_back("known_mu must be finite");
  if (!std::isfinite(mu_start)) p.push_back("mu_start must be finite");
  if (!(max_dropped_fraction >= 0 && max_dropped_fraction < 1))
    p.push_back("max_dropped_fraction must be in [0, 1)");
  if (!(angular_gain_k > 0 && std::isfinite(angular_gain_k)))
    p.push_back("angular_gain_k must be finite and > 0");
  if (!(rank_tolerance > 0 && rank_tolerance < 1)) p.push_back("rank_tolerance must be in (0, 1)");
  if (!(min_reciprocal_condition_number > 0 && min_reciprocal_condition_number < 1))
    p.push_back("min_reciprocal_condition_number must be in (0, 1)");
  for (const auto& s : stationary.validate()) p.push_back(s);
  return p;
}

namespace {

void requireValid(const CeresOptions& options) {
  const auto problems = options.validate();
  if (problems.empty()) return;
  std::string all = "invalid Ceres options:";
  for (const auto& s : problems) all += " " + s + ";";
  throw InputError(all);
}

/// The start estimate's values in the model's z order (every model parameter must be present).
Eigen::VectorXd startVector(const ResonatorModel& model, const Estimate& start) {
  if (static_cast<int>(start.names.size()) != start.values.size())
    throw InputError("start estimate: names and values differ in length");
  Eigen::VectorXd z(model.numParameters());
  for (int i = 0; i < model.numParameters(); ++i) {
    const auto& name = model.parameterNames()[i];
    const auto it = std::find(start.names.begin(), start.names.end(), name);
    if (it == start.names.end())
      throw InputError("start estimate lacks parameter '" + name + "' of model " + model.spec());
    z[i] = start.values[it - start.names.begin()];
  }
  if (!z.allFinite()) throw InputError("start estimate has non-finite values");
  return z;
}

double startMu(const Estimate& start, const CeresOptions& options) {
  const auto it = std::find(start.names.begin(), start.names.end(), ResonatorModel::muName());
  if (it != start.names.end()) {
    const double v = start.values[it - start.names.begin()];
    if (std::isfinite(v)) return v;
  }
  return options.mu_start;
}

/// What the estimate is built from once Ceres has finished.
struct FittedProblem {
  /// The problem whose Jacobian gives rank and covariance (may differ from the solved one only in
  /// how derivatives are taken).
  ceres::Problem* problem = nullptr;
  std::vector<double*> blocks;  ///< parameter blocks, reported ones first
  std::vector<int> block_sizes;
  std::vector<std::string> all_names;  ///< flattened names of all unknowns
  int n_reported = 0;                  ///< leading unknowns reported as parameters
  /// Per flattened unknown: the blocks hold unknown / scale (empty = no scaling).
  Eigen::VectorXd scale;
  const std::vector<Eigen::Vector4d>* q = nullptr;  ///< measured points (excitation summary)
  /// Free decay from a demodulator: correlation rho_l of the noise on each slow variable between
  /// samples l apart (demodulator_noise.h); residual rows are 4 per sample, time-ordered. Empty =
  /// white noise.
  std::vector<double> noise_correlation;
  /// Free decay: the residuals and the Jacobian of the unscaled unknowns written straight into
  /// dense storage (no sparse copy); empty = through ceres::Problem::Evaluate.
  std::function<bool(Eigen::MatrixXd*, Eigen::VectorXd*)> evaluate_dense;
};

/// n_residuals: the scalar residuals behind the cost (4 a sample or sweep point), which scale
/// CeresOptions::likelihood_tolerance to Ceres's relative function tolerance.
void solveOrThrow(ceres::Problem* problem, const CeresOptions& options, long n_residuals,
                  ceres::Solver::Summary* summary) {
  DenseSolverStop stop{options.max_iterations, options.function_tolerance,
                       options.parameter_tolerance, options.gradient_tolerance};
  if (n_residuals >= 4 * options.likelihood_tolerance_min_samples)
    stop.function_tolerance = std::max(
        stop.function_tolerance, options.likelihood_tolerance / static_cast<double>(n_residuals));
  ceres::Solve(denseSolverOptions(stop), problem, summary);
  if (!summary->IsSolutionUsable())
    throw AnalysisError("Ceres refinement found no usable solution (" +
                        std::string(ceres::TerminationTypeToString(summary->termination_type)) +
                        "): " + summary->message);
}

Eigen::MatrixXd denseJacobian(const ceres::CRSMatrix& crs) {
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) j(r, crs.cols[k]) = crs.values[k];
  }
  return j;
}

std::string fmt3(double v) {
  std::ostringstream s;
  s.precision(3);
  s << v;
  return s.str();
}

/// Lag-1 correlation of the residual 4-blocks (one sample / sweep point apart).
double blockLagOne(const Eigen::VectorXd& r) {
  const long n = r.size();
  const double ss = r.squaredNorm();
  if (n <= 8 || !(ss > 0.0)) return 0.0;
  return r.tail(n - 4).dot(r.head(n - 4)) / ss;
}

/// The dense Jacobian at the solution holds 4N x p doubles (the solve itself holds nothing of
/// size N): refinements running concurrently (explain's batches of candidate fits) take turns
/// for it, so that the peak memory stays that of one; the results do not depend on the order.
std::mutex& denseJacobianTurn() {
  static std::mutex turn;
  return turn;
}

/// Residuals, Jacobian (unscaled unknowns) and unknowns at the solution. Free decay: n, p, cost
/// and lag1 come from the solve's pass at the solution, and the per-sample rows (j, residuals)
/// are written only when a noise model needs them (dense()).
struct AtSolution {
  long n = 0;  ///< residuals
  int p = 0;   ///< unknowns
  Eigen::MatrixXd j;
  Eigen::VectorXd residuals;
  Eigen::VectorXd x;      ///< all unknowns, unscaled
  Eigen::VectorXd scale;  ///< blocks hold x / scale
  double cost = 0.0;
  double lag1 = 0.0;  ///< lag-1 correlation of the residual 4-blocks (blockLagOne)
  std::unique_lock<std::mutex> turn;
};

/// a->j and a->residuals, written once (free decay: by the forward sensitivities).
void dense(const FittedProblem& fp, AtSolution* a) {
  if (a->j.size() > 0 || !fp.evaluate_dense) return;
  a->turn = std::unique_lock<std::mutex>(denseJacobianTurn());
  if (!fp.evaluate_dense(&a->j, &a->residuals))
    throw AnalysisError("Ceres refinement: residuals cannot be evaluated at the solution");
}

AtSolution evaluateAtSolution(const FittedProblem& fp) {
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = fp.blocks;
  AtSolution a;
  std::vector<double> residuals;
  ceres::CRSMatrix crs;
  if (!fp.problem->Evaluate(eo, &a.cost, &residuals, nullptr, &crs))
    throw AnalysisError("Ceres refinement: residuals cannot be evaluated at the solution");
  a.j = denseJacobian(crs);
  a.scale = fp.scale.size() == a.j.cols() ? fp.scale : Eigen::VectorXd::Ones(a.j.cols());
  a.j = a.j * a.scale.cwiseInverse().asDiagonal();  // with respect to the unscaled unknowns
  if (!a.j.allFinite())
    throw AnalysisError("Ceres refinement: non-finite Jacobian at the solution");
  a.residuals = Eigen::Map<const Eigen::VectorXd>(residuals.data(), residuals.size());
  a.x.resize(a.j.cols());
  for (size_t b = 0, o = 0; b < fp.blocks.size(); o += fp.block_sizes[b], ++b)
    a.x.segment(o, fp.block_sizes[b]) =
        Eigen::Map<const Eigen::VectorXd>(fp.blocks[b], fp.block_sizes[b]);
  a.x = a.x.cwiseProduct(a.scale);
  a.n = a.j.rows();
  a.p = static_cast<int>(a.j.cols());
  a.lag1 = blockLagOne(a.residuals);
  return a;
}

/// Numerical rank from the column-equilibrated Jacobian (same convention as the LS estimators).
struct RankAnalysis {
  int rank = 0;
  Eigen::VectorXd norms, s;
  Eigen::MatrixXd v;
};

RankAnalysis numericalRank(const Eigen::MatrixXd& j, double tolerance) {
  RankAnalysis r;
  r.norms = j.colwise().norm().transpose();
  for (Eigen::Index c = 0; c < r.norms.size(); ++c)
    if (r.norms[c] == 0.0) r.norms[c] = 1.0;
  const Eigen::VectorXd inv_norms = r.norms.cwiseInverse();
  if (j.cols() <= kMaxModelParameters) {
    // Same singular values and V as the SVD of the tall matrix, from its triangular factor
    // folded in by rows (no copy of the n x p Jacobian).
    IncrementalQr qr(static_cast<int>(j.cols()));
    constexpr Eigen::Index kRows = 256;
    for (Eigen::Index r0 = 0; r0 < j.rows(); r0 += kRows) {
      const Eigen::Index len = std::min(kRows, j.rows() - r0);
      qr.addRows(j.middleRows(r0, len) * inv_norms.asDiagonal(), Eigen::VectorXd::Zero(len));
    }
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(qr.rAug().topLeftCorner(j.cols(), j.cols()),
                                                Eigen::ComputeFullV);
    r.s = svd.singularValues();
    r.v = svd.matrixV();
  } else {
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(j * inv_norms.asDiagonal(), Eigen::ComputeFullV);
    r.s = svd.singularValues();
    r.v = svd.matrixV();
  }
  for (Eigen::Index i = 0; i < r.s.size(); ++i)
    if (r.s[i] > tolerance * r.s[0]) ++r.rank;
  return r;
}

/// The same from the triangular factor R of J (J = Q R: the same column norms, and R D the same
/// singular values and V as J D), e.g. folded sample by sample by the solve.
RankAnalysis rankFromFactor(const Eigen::MatrixXd& factor, double tolerance) {
  RankAnalysis r;
  r.norms = factor.colwise().norm().transpose();
  for (Eigen::Index c = 0; c < r.norms.size(); ++c)
    if (r.norms[c] == 0.0) r.norms[c] = 1.0;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(factor * r.norms.cwiseInverse().asDiagonal(),
                                              Eigen::ComputeFullV);
  r.s = svd.singularValues();
  r.v = svd.matrixV();
  for (Eigen::Index i = 0; i < r.s.size(); ++i)
    if (r.s[i] > tolerance * r.s[0]) ++r.rank;
  return r;
}

/// (J'J)^+ in the unscaled unknowns: ceres::Covariance, or the truncated SVD of the
/// column-equilibrated Jacobian where Ceres refuses.
Eigen::MatrixXd unscaledCovariance(const FittedProblem& fp, const AtSolution& a,
                                   const RankAnalysis& r, const CeresOptions& options,
                                   Estimate* e) {
  const int p = a.p;
  const char* kRefusedNote =
      "covariance from the SVD of the column-equilibrated Jacobian (ceres::Covariance judged "
      "J'J too ill-conditioned before equilibration)";
  if (r.rank == p && r.s.size() == p && r.s[p - 1] > 0.0) {
    // Full rank: (J'J)^-1 from the SVD already taken (ceres::Covariance would evaluate and copy
    // the n x p Jacobian again). Its DENSE_SVD refuses when the singular values of the Jacobian
    // of the stored (scaled) blocks fall below sqrt(min_reciprocal_condition_number) of the
    // largest; the result is this same formula then, with the note.
    const Eigen::VectorXd sv =
        Eigen::JacobiSVD<Eigen::MatrixXd>(r.s.asDiagonal() * r.v.transpose() *
                                          r.norms.cwiseProduct(a.scale).asDiagonal())
            .singularValues();
    if (!(sv[p - 1] >= std::sqrt(options.min_reciprocal_condition_number) * sv[0]))
      e->notes.push_back(kRefusedNote);
    const Eigen::MatrixXd w =
        r.norms.cwiseInverse().asDiagonal() * r.v * r.s.cwiseInverse().asDiagonal();
    return w * w.transpose();
  }
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  co.null_space_rank = p - r.rank;
  co.min_reciprocal_condition_number = options.min_reciprocal_condition_number;
  ceres::Covariance covariance(co);
  std::vector<const double*> cblocks(fp.blocks.begin(), fp.blocks.end());
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> cov(p, p);
  if (covariance.Compute(cblocks, fp.problem) &&
      covariance.GetCovarianceMatrix(cblocks, cov.data()))
    return a.scale.asDiagonal() * Eigen::MatrixXd(cov) * a.scale.asDiagonal();
  // ceres::Covariance refused (its condition test runs on the unequilibrated J'J).
  const Eigen::MatrixXd v = r.v.leftCols(r.rank);
  const Eigen::VectorXd inv_s2 = r.s.head(r.rank).cwiseAbs2().cwiseInverse();
  e->notes.push_back(kRefusedNote);
  return r.norms.cwiseInverse().asDiagonal() * v * inv_s2.asDiagonal() * v.transpose() *
         r.norms.cwiseInverse().asDiagonal();
}

/// J' Sigma J for residual rows 4 per sample, Sigma_{i,i+4l} = rho_l (l = 1..rho.size(), 4 l < n):
/// J'J + sum_l rho_l (A_l + A_l'), A_l = J[0, n-4l)' J[4l, n). Column by column: w = sum_l rho_l
/// (column shifted by 4 l rows), then J' w is column b of sum_l rho_l A_l. A geometric rho
/// (rho_l = rho_1^l, the fitted AR(1)) sums by a backward recursion, O(n) per column whatever the
/// number of lags; other lists directly, O(n L).
Eigen::MatrixXd correlatedGram(const Eigen::MatrixXd& j, const std::vector<double>& rho) {
  const long n = j.rows();
  Eigen::MatrixXd gram = j.transpose() * j;
  long lags = 0;
  while (lags < static_cast<long>(rho.size()) && 4 * (lags + 1) < n) ++lags;
  if (lags == 0) return gram;
  const double r1 = rho[0];
  bool geometric = lags >= 3 && r1 != 0.0;
  for (long l = 1; l < lags && geometric; ++l)
    geometric = std::abs(rho[l] - rho[l - 1] * r1) <= 1e-12 * std::abs(rho[l]);
  const double tail = geometric ? rho[lags - 1] * r1 : 0.0;
  const long reach = 4 * (lags + 1);
  Eigen::VectorXd w(n);
  for (Eigen::Index b = 0; b < j.cols(); ++b) {
    const auto x = j.col(b);
    if (geometric) {
      // w_i = sum_{l=1..L} r^l x_{i+4l} = r (x_{i+4} + w_{i+4}) - r^{L+1} x_{i+4(L+1)}.
      for (long i = n - 1; i >= 0; --i) {
        double v = i + 4 < n ? r1 * (x[i + 4] + w[i + 4]) : 0.0;
        if (i + reach < n) v -= tail * x[i + reach];
        w[i] = v;
      }
    } else {
      w.setZero();
      for (long l = 1; l <= lags; ++l) w.head(n - 4 * l) += rho[l - 1] * x.tail(n - 4 * l);
    }
    const Eigen::VectorXd v = j.transpose() * w;
    gram.col(b) += v;
    gram.row(b) += v.transpose();
  }
  return gram;
}

/// Covariance of all unknowns: white (iid), the record's stated noise correlation, or HAC when
/// the residuals' lag-1 correlation rejects what the assumed noise predicts.
struct CeresCovariance {
  Eigen::MatrixXd cov;
  std::string method, id;
};

CeresCovariance outputErrorCovariance(const FittedProblem& fp, AtSolution& a,
                                      const Eigen::MatrixXd& unscaled, int dof, Estimate* e) {
  const long n = a.n;
  CeresCovariance out;
  out.cov = (2.0 * a.cost / dof) * unscaled;
  out.id = "iid";
  out.method = "output error (Ceres): sigma^2 (J'J)^+ by ceres::Covariance DENSE_SVD, Student-t";
  // The null: white residuals, or the stated correlation rho_1 with Bartlett's variance factor.
  double expected = 0.0, factor = 1.0;
  for (size_t l = 0; l < fp.noise_correlation.size(); ++l)
    factor += 2.0 * fp.noise_correlation[l] * fp.noise_correlation[l];
  if (!fp.noise_correlation.empty()) expected = fp.noise_correlation[0];
  const SerialCorrelationTest test = testLagOne(a.lag1, expected, factor, n / 4);
  e->residual_lag1 = test.lag1;
  e->residual_lag1_expected = test.expected;
  e->residual_lag1_z = test.z;
  e->residual_correlated = test.correlated;
  e->noise_model = "white";
  std::vector<double> rho = fp.noise_correlation;
  std::string source = "stated by the record (demodulator)";
  std::string id = "demod_correlation";
  if (test.correlated && n % 4 == 0) {
    if (fp.noise_correlation.empty() && test.lag1 > 0.0) {
      // A noise model: AR(1) on each slow variable with rho = the residuals' lag-1 correlation
      // (rho_l = rho^l kept while > 1e-3). Under AR(1) rho = 0.9 this holds 95 % coverage where
      // the HAC sandwich on ~10^3 samples gives ~0.90 (correlated_intervals_test).
      // The fit removes mostly slow noise, so the residuals' lag-1 correlation understates rho:
      // corrected by its expectation under the fit (fitted_residual_ar1.h).
      rho.clear();
      dense(fp, &a);
      const double r1 = std::min(fittedResidualAr1(a.j, unscaled, 4, test.lag1), 0.995);
      for (double v = r1; v > 1e-3 && static_cast<long>(rho.size()) < n / 8; v *= r1)
        rho.push_back(v);
      source = "AR(1) fitted to the residuals' lag-1 correlation " + fmt3(test.lag1) +
               " (corrected for the fit)";
      id = "ar1_fitted";
    } else if (n / 4 > 3 * a.p) {
      dense(fp, &a);
      const HacCovariance hac = hacCovarianceBlocked(a.j, a.residuals, 4);
      out.cov = hac.covariance;
      out.id = "hac_bartlett_andrews";
      e->noise_model = "serially correlated residuals (lag-1 correlation " + fmt3(test.lag1) +
                       ", z = " + fmt3(test.z) + " against " + fmt3(expected) + ")";
      out.method = "output error (Ceres): " + hac.method + ", Student-t";
      return out;
    }
  }
  if (rho.empty()) return out;
  // Noise correlation Sigma (same channel, samples l apart: rho_l): with C = (J'J)^+ and
  // S = J' Sigma J, cov = sigma^2 C S C and E[RSS] = sigma^2 (n - tr(C S)).
  dense(fp, &a);
  const Eigen::MatrixXd s_mat = correlatedGram(a.j, rho);
  const double effective_dof = n - (unscaled * s_mat).trace();
  if (!(effective_dof > 0.0)) {
    e->notes.push_back(
        "the noise correlation leaves no degrees of freedom (n - tr(C J' Sigma J) <= 0): "
        "white-noise covariance reported, too narrow for correlated samples");
    return out;
  }
  const double sigma2_sample = 2.0 * a.cost / effective_dof;  // noise variance of one sample
  out.cov = sigma2_sample * unscaled * s_mat * unscaled;
  out.cov = 0.5 * (out.cov + out.cov.transpose());
  out.id = id;
  e->noise_model =
      source + ": rho_1 = " + fmt3(rho[0]) + ", " + std::to_string(rho.size()) + " lag(s)";
  out.method =
      "output error (Ceres): sigma^2 C J' Sigma J C, C = (J'J)^+ by ceres::Covariance "
      "DENSE_SVD, Sigma the noise correlation " +
      source + " (rho_1 = " + fmt3(rho[0]) + ", " + std::to_string(rho.size()) +
      " lags; the white-noise formula is ~15 % too narrow on demodulated samples), Student-t";
  return out;
}

/// Exact rank deficiency (identifiability.h) or near-collinearity (collinearity.h).
void fillIdentifiability(const FittedProblem& fp, const AtSolution& a, const RankAnalysis& r,
                         const Eigen::MatrixXd& cov, double s_p, Estimate* e) {
  const int p = a.p;
  e->unidentifiable.clear();
  e->not_identified.clear();
  e->identifiability_note.clear();
  e->combinations.clear();
  if (r.rank == p) {
    // S V' diag(norms) has the Gram J'J: the SVD already taken, without the n rows again.
    const Eigen::MatrixXd factor = r.s.asDiagonal() * r.v.transpose() * r.norms.asDiagonal();
    reportCollinearity(analyzeCollinearity(fp.all_names, factor, fp.n_reported), fp.all_names, a.x,
                       cov, summarizeExcitation(*fp.q), s_p, e);
    return;
  }
  Eigen::MatrixXd null_space = r.norms.cwiseInverse().asDiagonal() * r.v.rightCols(p - r.rank);
  null_space.colwise().normalize();
  const IdentifiabilityReport report =
      analyzeIdentifiability(fp.all_names, null_space, r.norms, summarizeExcitation(*fp.q));
  e->unidentifiable = report.unidentifiable;
  e->identifiability_note = report.note;
  for (const auto& c : report.combinations)
    e->combinations[c.name] =
        interval(c.coefficients.dot(a.x), c.coefficients.dot(cov * c.coefficients), s_p);
  e->notes.push_back("rank-deficient output-error fit (rank " + std::to_string(r.rank) + " of " +
                     std::to_string(p) +
                     "): intervals of the unidentifiable parameters are not meaningful");
}

/// The reported parameters' values, covariance and Student-t intervals (dof = n - rank).
void fillIntervals(const FittedProblem& fp, const AtSolution& a, const RankAnalysis& r,
                   const CeresCovariance& cc, const CeresOptions& options, double s_p,
                   Estimate* e) {
  const int n = static_cast<int>(a.n), p = a.p;
  const int k = fp.n_reported;
  const int dof = n - r.rank;
  e->method = "ceres";
  e->n_equations = n;
  e->n_params = k;
  e->rank = std::max(0, r.rank - (p - k));
  e->dof = dof;
  e->sigma = std::sqrt(2.0 * a.cost / dof);
  e->confidence = options.confidence;
  e->names.assign(fp.all_names.begin(), fp.all_names.begin() + k);
  e->values = a.x.head(k);
  e->covariance = cc.cov.topLeftCorner(k, k);
  e->parameters.clear();
  for (int i = 0; i < k; ++i) e->parameters[e->names[i]] = interval(a.x[i], cc.cov(i, i), s_p);
  e->interval_method = cc.method;
  e->interval_method_id = cc.id;
  e->interval_dof = dof;
  e->covariance_paper.resize(0, 0);
  e->parameters_paper.clear();
  e->singular_values.assign(r.s.data(), r.s.data() + r.s.size());
  e->rank_tolerance = options.rank_tolerance;
}

void requireDegreesOfFreedom(long n, int rank) {
  if (n - rank < 1)
    throw AnalysisError("Ceres refinement: no degrees of freedom left (" + std::to_string(n) +
                        " residuals, rank " + std::to_string(rank) + ")");
}

/// Covariance (outputErrorCovariance), intervals (fillIntervals), identifiability and derived
/// quantities of the fitted problem, given its rank.
void finishEstimate(const FittedProblem& fp, const CeresOptions& options, AtSolution a,
                    const RankAnalysis& r, Estimate* e) {
  const int n = static_cast<int>(a.n);
  requireDegreesOfFreedom(n, r.rank);
  const int dof = n - r.rank;
  const Eigen::MatrixXd unscaled = unscaledCovariance(fp, a, r, options, e);
  const CeresCovariance cc = outputErrorCovariance(fp, a, unscaled, dof, e);
  const double s_p = studentQuantile(options.confidence, dof);
  fillIntervals(fp, a, r, cc, options, s_p, e);
  fillIdentifiability(fp, a, r, cc.cov, s_p, e);
  e->derived.clear();
  e->derived_method.clear();
  if (options.derive_quantities) deriveFromIdentified(e, e->omega_rad_s, options.angular_gain_k);
}

/// Forced sweeps: the Jacobian evaluated densely through the problem, then as above.
void finishEstimate(const FittedProblem& fp, const CeresOptions& options, Estimate* e) {
  AtSolution a = evaluateAtSolution(fp);
  const RankAnalysis r = numericalRank(a.j, options.rank_tolerance);
  finishEstimate(fp, options, std::move(a), r, e);
}

void checkTimes(const SlowRecord& record) {
  const std::string where = record.source.empty() ? "free-decay record" : record.source;
  if (record.q.size() != record.t_s.size())
    throw InputError(where + ": times and slow variables differ in length");
  for (size_t i = 0; i < record.size(); ++i) {
    if (!std::isfinite(record.t_s[i]) || !record.q[i].allFinite())
      throw InputError(where + ": non-finite value in sample " + std::to_string(i));
    if (i > 0 && !(record.t_s[i] > record.t_s[i - 1]))
      throw InputError(where + ": times not strictly increasing at sample " + std::to_string(i));
  }
}

std::string formatQ(const double* q) {
  std::ostringstream s;
  s.precision(6);
  s << "(" << q[0] << ", " << q[1] << ", " << q[2] << ", " << q[3] << ")";
  return s.str();
}

std::string solverNote(const ceres::Solver::Summary& summary) {
  std::ostringstream s;
  s.precision(6);
  s << "Ceres " << ceres::TerminationTypeToString(summary.termination_type) << " after "
    << summary.iterations.size() - 1 << " iterations, cost " << summary.initial_cost << " -> "
    << summary.final_cost;
  return s.str();
}

/// Stride of the coarse start (CeresOptions::coarse_samples): record size / coarse_samples,
/// capped so that one RK4 step on the coarse grid times the fastest slow rate (the largest
/// singular value of A = slowJacobian (2.6) at the first sample and the start z; amplitude terms
/// only shrink as the record decays) stays <= 0.05 (RK4 error per step ~ 0.05^5 / 120).
size_t coarseStride(const ResonatorModel& model, const Eigen::VectorXd& z, const SlowRecord& record,
                    const CeresOptions& options) {
  const size_t n = record.size();
  if (options.coarse_samples <= 0 || n < 4 * static_cast<size_t>(options.coarse_samples)) return 1;
  size_t stride = n / static_cast<size_t>(options.coarse_samples);
  const double step_s = (record.t_s.back() - record.t_s.front()) /
                        (static_cast<double>(n - 1) * options.rk4_substeps);
  const Eigen::Matrix4d a = model.slowJacobian(record.q.front(), SlowContext{0.0, 0.0}, z);
  const double rate = Eigen::JacobiSVD<Eigen::Matrix4d>(a).singularValues()[0];
  if (rate > 0.0 && step_s > 0.0)
    stride = std::min<size_t>(stride, static_cast<size_t>(std::max(1.0, 0.05 / (rate * step_s))));
  return std::max<size_t>(1, stride);
}

/// Every `stride`-th sample from the first (same t0, so q(t0) means the same).
SlowRecord everyNth(const SlowRecord& record, size_t stride) {
  SlowRecord coarse;
  coarse.omega_rad_s = record.omega_rad_s;
  coarse.source = record.source;
  for (size_t i = 0; i < record.size(); i += stride) {
    coarse.t_s.push_back(record.t_s[i]);
    coarse.q.push_back(record.q[i]);
  }
  return coarse;
}

const char* kSigmaNote =
    "sigma is the RMS misfit of the measured slow variables (units of q), not the equation units "
    "of the LS sigma-hat (2.10)";

// The free-decay solve (FreeDecayRefinement's constructor) in its steps.

/// Step 1: the record checked (checkTimes) and long enough for the model's k parameters and the
/// 4 initial values.
void checkFreeDecayRecord(const ResonatorModel& model, const SlowRecord& record) {
  checkTimes(record);
  const int k = model.numParameters();
  if (4 * static_cast<int>(record.size()) <= k + 4)
    throw InputError("free-decay record has " + std::to_string(record.size()) +
                     " samples: too few for " + std::to_string(k) +
                     " parameters + 4 initial values");
}

/// Step 2: unknowns scaled to O(1): z_j = z_scale_j x_j with z_scale_j = max(|start_j|, its
/// standard error), q(t0) = q0_scale x_q with q0_scale = the record's largest |q|. z, q0: the
/// scaled starting point.
void scaleUnknowns(const ResonatorModel& model, const Estimate& start, const SlowRecord& record,
                   const Eigen::VectorXd& z_start, Eigen::VectorXd* z_scale, double* q0_scale,
                   Eigen::VectorXd* z, Eigen::Vector4d* q0) {
  const int k = model.numParameters();
  z_scale->resize(k);
  for (int i = 0; i < k; ++i) {
    const auto it = start.parameters.find(model.parameterNames()[i]);
    const double se = it != start.parameters.end() && std::isfinite(it->second.std_error)
                          ? it->second.std_error
                          : 0.0;
    (*z_scale)[i] = std::max(std::abs(z_start[i]), se);
    if (!((*z_scale)[i] > 0)) (*z_scale)[i] = 1.0;
  }
  *q0_scale = 0.0;
  for (const auto& q : record.q) *q0_scale = std::max(*q0_scale, q.norm());
  if (!(*q0_scale > 0)) *q0_scale = 1.0;
  *z = z_start.cwiseQuotient(*z_scale);
  // q(t0): the start's fitted one where it has one (a nested model's refined fit), else the
  // first measured sample.
  const bool start_has_state =
      start.initial_slow_state.size() == 4 && start.initial_slow_state.allFinite();
  *q0 =
      (start_has_state ? Eigen::Vector4d(start.initial_slow_state) : record.q.front()) / *q0_scale;
}

/// Step 3: a long record: the same problem on every s-th sample first (a start near the optimum
/// costs the whole record a few iterations instead of tens). z, q0 move to its solution when it
/// succeeds. Returns the note on it, empty when there was no coarse fit.
std::string coarseStart(const ResonatorModel& model, const SlowRecord& record,
                        const CeresOptions& options, const Eigen::VectorXd& z_start,
                        const Eigen::VectorXd& z_scale, double q0_scale, Eigen::VectorXd* z,
                        Eigen::Vector4d* q0) {
  std::string coarse_note;
  const size_t stride = coarseStride(model, z_start, record, options);
  if (stride > 1) {
    const SlowRecord coarse = everyNth(record, stride);
    ceres::Problem coarse_problem;
    Eigen::VectorXd zc = *z;
    Eigen::Vector4d qc = *q0;
    coarse_problem.AddResidualBlock(
        makeFreeDecaySquareRootCost(model, coarse, options.rk4_substeps, z_scale, q0_scale)
            .release(),
        nullptr, zc.data(), qc.data());
    ceres::Solver::Summary coarse_summary;
    try {
      solveOrThrow(&coarse_problem, options, 4 * static_cast<long>(coarse.size()), &coarse_summary);
      *z = zc;
      *q0 = qc;
      coarse_note = "start from the same fit on every " + std::to_string(stride) + "th sample (" +
                    std::to_string(coarse.size()) + " samples, " +
                    std::to_string(coarse_summary.iterations.size() - 1) + " iterations)";
    } catch (const AnalysisError& err) {
      coarse_note = std::string("the fit on every ") + std::to_string(stride) +
                    "th sample failed, started from the given estimate: " + err.what();
    }
  }
  return coarse_note;
}

/// Step 4: solved in square-root form (k + 5 residuals, the per-sample rows folded as they are
/// made). Its last pass with Jacobians (pass) is normally at the solution: rank, sigma and the
/// residuals' lag-1 correlation come from it (else from one more pass there).
void solveSquareRoot(const ResonatorModel& model, const SlowRecord& record,
                     const CeresOptions& options, const Eigen::VectorXd& z_scale, double q0_scale,
                     Eigen::VectorXd* z, Eigen::Vector4d* q0, SquareRootPass* pass,
                     ceres::Solver::Summary* summary) {
  const int k = model.numParameters();
  ceres::Problem square_root;
  auto cost =
      makeFreeDecaySquareRootCost(model, record, options.rk4_substeps, z_scale, q0_scale, pass);
  ceres::CostFunction* cost_ptr = cost.get();
  square_root.AddResidualBlock(cost.release(), nullptr, z->data(), q0->data());
  solveOrThrow(&square_root, options, 4 * static_cast<long>(record.size()), summary);
  Eigen::VectorXd x(k + 4);
  x << *z, *q0;
  if (pass->x.size() != x.size() || pass->x != x) {
    std::vector<double> residuals(k + 5), jz((k + 5) * k), jq((k + 5) * 4);
    const double* params[2] = {z->data(), q0->data()};
    double* jacobians[2] = {jz.data(), jq.data()};
    if (!cost_ptr->Evaluate(params, residuals.data(), jacobians) || pass->x != x)
      throw AnalysisError("Ceres refinement: residuals cannot be evaluated at the solution");
  }
}

/// Step 5: the pass's triangular factor R of J with respect to the unscaled unknowns (the
/// scaled blocks' R times the inverse scales).
void unscaledFactor(const SquareRootPass& pass, const Eigen::VectorXd& z_scale, double q0_scale,
                    Eigen::MatrixXd* factor) {
  const Eigen::Index k = z_scale.size();
  Eigen::VectorXd scale(k + 4);
  scale << z_scale, Eigen::Vector4d::Constant(q0_scale);
  *factor = pass.r_aug.topLeftCorner(k + 4, k + 4).triangularView<Eigen::Upper>();
  *factor = *factor * scale.cwiseInverse().asDiagonal();
}

/// Step 6a: the solved estimate's identity and notes (the start's, then how it was refined).
void describeFreeDecaySolve(const Estimate& start, const SlowRecord& record,
                            const CeresOptions& options, const ResonatorModel& model,
                            const Eigen::Vector4d& q0, double q0_scale,
                            const std::string& coarse_note, const ceres::Solver::Summary& summary,
                            Estimate* e) {
  *e = start;
  e->mode = ExperimentMode::kFreeDecay;
  e->model = model.spec();
  if (e->omega_rad_s <= 0) e->omega_rad_s = record.omega_rad_s;
  e->notes.push_back(
      "output-error refinement of the " +
      (start.method.empty() ? std::string("given") : start.method) +
      " estimate: averaged model (2.6) integrated by RK4 on the record's time grid (" +
      std::to_string(options.rk4_substeps) +
      " step(s) per sample interval), Jacobian by forward sensitivities");
  const Eigen::Vector4d q0_fitted = q0_scale * q0;
  e->initial_slow_state = q0_fitted;
  e->notes.push_back("fitted initial slow variables q(t0) = " + formatQ(q0_fitted.data()) +
                     " (4 nuisance unknowns, not in parameters)");
  e->notes.push_back(kSigmaNote);
  if (!coarse_note.empty()) e->notes.push_back(coarse_note);
  e->notes.push_back(solverNote(summary));
}

/// Step 6b: without the covariance yet: values, sigma, rank and dof (as fillIntervals sets
/// them); n residuals, ss their sum of squares, r the rank of the k + 4 unknowns.
void setSolvedValues(const ResonatorModel& model, const CeresOptions& options, long n,
                     const RankAnalysis& r, double ss, const Eigen::VectorXd& z,
                     const Eigen::VectorXd& z_scale, Estimate* e) {
  const int k = model.numParameters();
  e->method = "ceres";
  e->n_equations = static_cast<int>(n);
  e->n_params = k;
  e->rank = std::max(0, r.rank - 4);
  e->dof = static_cast<int>(n) - r.rank;
  e->sigma = std::sqrt(ss / e->dof);
  e->confidence = options.confidence;
  e->names = model.parameterNames();
  e->values = z.cwiseProduct(z_scale);
  e->covariance.resize(0, 0);
  e->parameters.clear();
  e->covariance_paper.resize(0, 0);
  e->parameters_paper.clear();
  e->interval_method.clear();
  e->interval_method_id.clear();
  e->derived.clear();
  e->derived_method.clear();
  e->singular_values.assign(r.s.data(), r.s.data() + r.s.size());
}

}  // namespace

/// What the free-decay finish needs of the solve.
struct FreeDecayRefinement::State {
  const SlowRecord* record = nullptr;
  CeresOptions options;
  ResonatorModel model{"linear", ExperimentMode::kFreeDecay};
  Eigen::VectorXd z, z_scale;  ///< solution (scaled block) and scale
  Eigen::Vector4d q0 = Eigen::Vector4d::Zero();
  double q0_scale = 1.0;
  SquareRootPass pass;     ///< the pass over the record at the solution
  Eigen::MatrixXd factor;  ///< R of J with respect to the unscaled unknowns
  Estimate solved;
};

FreeDecayRefinement::FreeDecayRefinement(const SlowRecord& record, const Estimate& start,
                                         const CeresOptions& options) {
  // 1. Options, start and record checked; the model.
  requireValid(options);
  if (start.mode != ExperimentMode::kFreeDecay)
    throw InputError("refineWithCeres: start estimate is not a free-decay estimate");
  auto st = std::make_shared<State>();
  st->record = &record;
  st->options = options;
  st->model =
      ResonatorModel(start.model.empty() ? "linear" : start.model, ExperimentMode::kFreeDecay);
  const ResonatorModel& model = st->model;
  checkFreeDecayRecord(model, record);
  // 2. Unknowns scaled to O(1), and their starting point.
  const Eigen::VectorXd z_start = startVector(model, start);
  scaleUnknowns(model, start, record, z_start, &st->z_scale, &st->q0_scale, &st->z, &st->q0);
  // 3. A long record: a coarse fit first.
  const std::string coarse_note =
      coarseStart(model, record, options, z_start, st->z_scale, st->q0_scale, &st->z, &st->q0);
  // 4. The whole record in square-root form.
  ceres::Solver::Summary summary;
  solveSquareRoot(model, record, options, st->z_scale, st->q0_scale, &st->z, &st->q0, &st->pass,
                  &summary);
  // 5. Factor and rank at the solution.
  unscaledFactor(st->pass, st->z_scale, st->q0_scale, &st->factor);
  const RankAnalysis r = rankFromFactor(st->factor, options.rank_tolerance);
  const long n = 4 * static_cast<long>(record.size());
  requireDegreesOfFreedom(n, r.rank);
  // 6. The solved estimate (no covariance yet).
  describeFreeDecaySolve(start, record, options, model, st->q0, st->q0_scale, coarse_note, summary,
                         &st->solved);
  setSolvedValues(model, options, n, r, st->pass.ss, st->z, st->z_scale, &st->solved);
  state_ = st;
}

const Estimate& FreeDecayRefinement::solved() const {
  return state_->solved;
}

Estimate FreeDecayRefinement::finish() const {
  const State& st = *state_;
  const SlowRecord& record = *st.record;
  const CeresOptions& options = st.options;
  const ResonatorModel& model = st.model;
  const int k = model.numParameters();
  Eigen::VectorXd z = st.z;
  Eigen::Vector4d q0 = st.q0;
  // The per-sample problem: ceres::Covariance of a rank-deficient fit evaluates it.
  ceres::Problem problem;
  problem.AddResidualBlock(
      makeFreeDecayOutputErrorCost(model, record, options.rk4_substeps,
                                   TrajectoryDerivative::kSensitivity, st.z_scale, st.q0_scale)
          .release(),
      nullptr, z.data(), q0.data());
  FittedProblem fp;
  fp.problem = &problem;
  fp.blocks = {z.data(), q0.data()};
  fp.block_sizes = {k, 4};
  fp.all_names = model.parameterNames();
  for (const char* n : {"q1_0", "p1_0", "q2_0", "p2_0"}) fp.all_names.push_back(n);
  fp.n_reported = k;
  fp.scale.resize(k + 4);
  fp.scale << st.z_scale, Eigen::Vector4d::Constant(st.q0_scale);
  fp.q = &record.q;
  fp.noise_correlation = noiseCorrelationFromMetadata(record.metadata);
  // The per-sample rows (a noise model other than white needs them) from the same exact
  // sensitivities.
  fp.evaluate_dense = [&](Eigen::MatrixXd* j, Eigen::VectorXd* r) {
    return evaluateFreeDecayOutputError(model, record, options.rk4_substeps,
                                        z.cwiseProduct(st.z_scale), st.q0_scale * q0, j, r);
  };
  AtSolution a;
  a.n = 4 * static_cast<long>(record.size());
  a.p = k + 4;
  a.cost = 0.5 * st.pass.ss;
  a.scale = fp.scale;
  a.x.resize(k + 4);
  a.x << z, q0;
  a.x = a.x.cwiseProduct(a.scale);
  a.lag1 = a.n <= 8 || !(st.pass.ss > 0.0) ? 0.0 : st.pass.lag_one / st.pass.ss;
  Estimate e = st.solved;
  finishEstimate(fp, options, std::move(a), rankFromFactor(st.factor, options.rank_tolerance), &e);
  return e;
}

Estimate refineWithCeres(const SlowRecord& record, const Estimate& start,
                         const CeresOptions& options) {
  return FreeDecayRefinement(record, start, options).finish();
}

Estimate refineWithCeres(const SweepRecord& record, const Estimate& start,
                         const CeresOptions& options) {
  requireValid(options);
  if (start.mode != ExperimentMode::kForced)
    throw InputError("refineWithCeres: start estimate is not a forced-sweep estimate");
  const ResonatorModel model(start.model.empty() ? "linear" : start.model, ExperimentMode::kForced);
  const std::string where = record.source.empty() ? "forced sweep" : record.source;
  const double omega = start.omega_rad_s > 0 ? start.omega_rad_s : record.omega_rad_s;
  if (!(omega > 0 && std::isfinite(omega)))
    throw InputError(where + ": natural frequency omega unknown (give --omega or '# omega:')");
  if (record.q.size() != record.omega0_rad_s.size())
    throw InputError(where + ": drive frequencies and slow variables differ in length");
  for (size_t j = 0; j < record.size(); ++j) {
    if (!(record.omega0_rad_s[j] > 0) || !std::isfinite(record.omega0_rad_s[j]) ||
        !record.q[j].allFinite())
      throw InputError(where + ": bad value (non-finite or omega0 <= 0) at point " +
                       std::to_string(j));
  }
  const bool estimate_mu = model.estimatesMu();
  const int k = model.numParameters();
  const int n_unknowns = k + (estimate_mu ? 1 : 0);

  Eigen::VectorXd z = startVector(model, start);
  double mu = estimate_mu ? startMu(start, options) : options.known_mu;
  ceres::Problem problem;
  std::vector<Eigen::Vector4d> used_q;
  int dropped = 0;
  std::string first_failure;
  for (size_t j = 0; j < record.size(); ++j) {
    auto cost = std::make_unique<ForcedPointOutputError>(
        model, detuningRate(omega, record.omega0_rad_s[j]), record.q[j], estimate_mu,
        options.known_mu, options.stationary);
    const StationaryPoint sp = cost->modelPoint(z, mu);
    if (!sp.converged) {
      if (first_failure.empty()) first_failure = "point " + std::to_string(j) + ": " + sp.failure;
      ++dropped;
      continue;
    }
    used_q.push_back(record.q[j]);
    if (estimate_mu) {
      problem.AddResidualBlock(cost.release(), nullptr, z.data(), &mu);
    } else {
      problem.AddResidualBlock(cost.release(), nullptr, z.data());
    }
  }
  if (dropped > options.max_dropped_fraction * record.size())
    throw AnalysisError(where +
                        ": the stationary equations (3.3) cannot be solved at the start "
                        "estimate for " +
                        std::to_string(dropped) + " of " + std::to_string(record.size()) +
                        " points (" + first_failure + ")");
  if (4 * static_cast<int>(used_q.size()) <= n_unknowns)
    throw InputError(where + ": " + std::to_string(used_q.size()) + " usable points: too few for " +
                     std::to_string(n_unknowns) + " unknowns");
  ceres::Solver::Summary summary;
  solveOrThrow(&problem, options, 4 * static_cast<long>(used_q.size()), &summary);

  Estimate e = start;
  e.mode = ExperimentMode::kForced;
  e.model = model.spec();
  e.omega_rad_s = omega;
  e.notes.push_back(
      "output-error refinement of the " +
      (start.method.empty() ? std::string("given") : start.method) +
      " estimate: model stationary points of (3.3) by Newton, analytic derivatives by the "
      "implicit function theorem");
  if (estimate_mu)
    e.notes.push_back("control nonlinearity mu estimated jointly with u~ (bilinear, (3.2))");
  else if (options.known_mu != 0.0)
    e.notes.push_back("control nonlinearity mu = " + std::to_string(options.known_mu) + " (known)");
  if (dropped > 0)
    e.notes.push_back(std::to_string(dropped) +
                      " sweep point(s) left out: no stationary solution "
                      "at the start estimate (" +
                      first_failure + ")");
  e.notes.push_back(kSigmaNote);
  e.notes.push_back(solverNote(summary));

  FittedProblem fp;
  fp.problem = &problem;
  fp.blocks = {z.data()};
  fp.block_sizes = {k};
  fp.all_names = model.parameterNames();
  if (estimate_mu) {
    fp.blocks.push_back(&mu);
    fp.block_sizes.push_back(1);
    fp.all_names.push_back(ResonatorModel::muName());
  }
  fp.n_reported = n_unknowns;
  fp.q = &used_q;
  finishEstimate(fp, options, &e);
  return e;
}

}  // namespace cvg_bench

#include "cvg_bench/core/estimate/identification.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/number_text.h"
#include "cvg_bench/core/demod/demodulator_noise.h"
#include "cvg_bench/core/estimate/collinearity.h"
#include "cvg_bench/core/estimate/data_sufficiency.h"
#include "cvg_bench/core/estimate/forced_regression.h"
#include "cvg_bench/core/estimate/free_decay_regression.h"
#include "cvg_bench/core/estimate/identifiability.h"
#include "cvg_bench/core/estimate/internal/block_gram_accumulator.h"
#include "cvg_bench/core/estimate/internal/regression_block_ops.h"
#include "cvg_bench/core/estimate/least_squares_solver.h"
#include "cvg_bench/core/estimate/recursive_least_squares.h"
#include "cvg_bench/core/estimate/uncertainty/correlated_noise_gram.h"
#include "cvg_bench/core/estimate/uncertainty/derived_uncertainty.h"
#include "cvg_bench/core/estimate/uncertainty/free_decay_noise_propagation.h"
#include "cvg_bench/core/estimate/uncertainty/hac_covariance.h"
#include "cvg_bench/core/estimate/uncertainty/residual_serial_correlation.h"
#include "cvg_bench/core/estimate/uncertainty/student_t.h"
#include "cvg_bench/core/estimate/uncertainty/sweep_noise_ar1.h"
#include "cvg_bench/core/model/stationary_solver.h"

namespace cvg_bench {
namespace {

/// Calls the visitor with (record index, block) for every block of the stacked system, in order.
using BlockSink = std::function<void(int, const RegressionBlock&)>;
using BlockStream = std::function<void(const BlockSink&)>;

/// What the estimator needs to know about the system besides its blocks.
struct SystemInfo {
  ExperimentMode mode = ExperimentMode::kFreeDecay;
  std::string model;
  std::vector<std::string> names;
  int max_lag_blocks = 2;  ///< error correlation extends this many blocks (same record only)
  long num_clusters = 0;   ///< forced: number of independent sweep points
  double omega_rad_s = 0.0;
  std::vector<std::string> notes;
  /// Free decay: the model (for d(D(q) z)/dq of the honest covariance); null for stacked systems.
  const ResonatorModel* resonator = nullptr;
  /// Free decay: the noise correlation the record states (demodulator_noise.h); empty = unknown.
  std::vector<double> noise_correlation;
  /// Forced: the known control nonlinearity mu, and whether the system is one sweep (the AR(1)
  /// along the sweep is estimated on one record only).
  double mu = 0.0;
  bool single_record = false;
};

/// ExcitationSummary of the centre samples, accumulated in squares (no square roots per sample).
struct SquaredExcitation {
  double max_sq = 0.0, min_sq = 0.0, max_mode1_sq = 0.0, max_mode2_sq = 0.0;
  long count = 0;
  void add(const Eigen::Vector4d& q) {
    const double m1 = q[0] * q[0] + q[1] * q[1], m2 = q[2] * q[2] + q[3] * q[3], a = m1 + m2;
    max_sq = count == 0 ? a : std::max(max_sq, a);
    min_sq = count == 0 ? a : std::min(min_sq, a);
    max_mode1_sq = std::max(max_mode1_sq, m1);
    max_mode2_sq = std::max(max_mode2_sq, m2);
    ++count;
  }
  ExcitationSummary summary() const {
    ExcitationSummary s;
    s.max_amplitude = std::sqrt(max_sq);
    s.min_amplitude = std::sqrt(min_sq);
    s.max_mode1 = std::sqrt(max_mode1_sq);
    s.max_mode2 = std::sqrt(max_mode2_sq);
    s.num_points = count;
    return s;
  }
};

template <class Record>
std::vector<const Record*> pointersTo(const std::vector<Record>& records) {
  std::vector<const Record*> p;
  for (const auto& r : records) p.push_back(&r);
  return p;
}

void throwIfInvalid(const IdentificationOptions& o) {
  cvg_bench::throwIfInvalid("invalid identification options", o.validate());
}

/// Pass 1: QR of the whole system (and RLS over the same blocks); fills the estimate's size, rank
/// and values.
struct SolvedSystem {
  LeastSquaresSolution ls;
  Eigen::MatrixXd r;  ///< k x k triangular factor (for the collinearity analysis)
  long n = 0;
  ExcitationSummary excitation;
};

/// What pass 1 folds in: the QR of all blocks, the excitation and, for method rls, block RLS
/// (2.12) initialised by QR on the first `m_init` blocks.
struct FirstPass {
  FirstPass(int k, const IdentificationOptions& opt)
      : rls(opt.method == "rls"),
        m_init(opt.rls_init_blocks > 0 ? opt.rls_init_blocks : std::max(2 * k, 8)),
        qr(k),
        qr_init(k),
        filter(k, opt.rls_forgetting) {}
  bool rls;
  int m_init;
  IncrementalQr qr, qr_init;
  BlockRecursiveLeastSquares filter;
  SquaredExcitation excitation;
  bool rls_failed = false;
};

void foldBlocks(const BlockStream& stream, FirstPass* p) {
  long block_no = 0;
  stream([&](int, const RegressionBlock& b) {
    p->qr.addBlock(*b.d, b.y);
    p->excitation.add(b.q);
    if (p->rls && !p->rls_failed) {
      if (block_no < p->m_init) {
        p->qr_init.addBlock(*b.d, b.y);
      } else {
        if (!p->filter.initialized()) {
          try {
            p->filter.initialize(p->qr_init.rAug(), p->qr_init.numRows());
          } catch (const AnalysisError&) {
            p->rls_failed = true;
          }
        }
        if (!p->rls_failed) p->filter.update(*b.d, b.y);
      }
    }
    ++block_no;
  });
}

/// The estimate's size, rank, options and the batch LS values.
void describeSolution(const SolvedSystem& s, const SystemInfo& info,
                      const IdentificationOptions& opt, Estimate* e) {
  const LeastSquaresSolution& ls = s.ls;
  e->mode = info.mode;
  e->model = info.model;
  e->method = opt.method;
  e->omega_rad_s = info.omega_rad_s;
  e->n_equations = static_cast<int>(s.n);
  e->n_params = static_cast<int>(info.names.size());
  e->rank = ls.rank;
  e->dof = static_cast<int>(s.n - ls.rank);
  e->confidence = opt.confidence;
  e->names = info.names;
  e->rank_tolerance = opt.rank_tolerance;
  e->singular_values.assign(ls.singular_values.data(),
                            ls.singular_values.data() + ls.singular_values.size());
  e->notes = info.notes;
  e->values = ls.z;
}

/// Method rls: the filter's values where it ran, else the batch LS answer with the reason.
void applyRls(FirstPass& p, const LeastSquaresSolution& ls, int k, const IdentificationOptions& opt,
              Estimate* e) {
  if (p.rls_failed || !p.filter.initialized() || ls.rank < k) {
    e->notes.push_back("RLS not run: the first " + std::to_string(p.m_init) +
                       " blocks (or the whole record) do not determine all parameters; "
                       "batch LS result reported");
    e->method = "ls";
    return;
  }
  e->values = p.filter.z();
  e->notes.push_back(
      "block RLS (2.12) with the corrected pairing y_{i+1} - D_{i+1} z_i "
      "(docs/paper.md item 9), initialised by QR on the first " +
      std::to_string(p.m_init) + " blocks, forgetting factor " + numberText(opt.rls_forgetting, 6) +
      "; paper's prediction bound (sigma_e = sigma) " +
      numberText(p.filter.predictionSigmaBound(p.filter.sigma()), 6));
}

SolvedSystem solveSystem(const BlockStream& stream, const SystemInfo& info,
                         const IdentificationOptions& opt, Estimate* e) {
  const int k = static_cast<int>(info.names.size());
  FirstPass pass(k, opt);
  foldBlocks(stream, &pass);
  SolvedSystem s;
  s.n = pass.qr.numRows();
  if (s.n <= k)
    throw InputError(std::to_string(s.n) + " equations for " + std::to_string(k) +
                     " parameters of model " + info.model + ": more data needed (n > k)");
  s.r = pass.qr.rAug().topLeftCorner(k, k);
  s.ls = solveTriangular(pass.qr.rAug(), s.n, opt.rank_tolerance);
  s.excitation = pass.excitation.summary();
  describeSolution(s, info, opt, e);
  if (pass.rls) applyRls(pass, s.ls, k, opt, e);
  return s;
}

/// The honest covariance of z-hat, its Student-t dof and the residual sum of squares.
struct HonestCovariance {
  Eigen::MatrixXd covariance;  ///< empty: the paper's (2.11)
  int dof = 0;
  double rss = 0.0;
};

void recordCorrelationTest(const SerialCorrelationTest& t, Estimate* e) {
  e->residual_lag1 = t.lag1;
  e->residual_lag1_expected = t.expected;
  e->residual_lag1_z = t.z;
  e->residual_correlated = t.correlated;
}

/// Pass 2 of free decay: residual sum, residual correlations, the sensitivities of the equation
/// errors to the noise on q (free_decay_noise_propagation.h) and the envelope fit.
struct ResidualPass {
  double rss = 0.0;
  long blocks = 0;
  std::vector<double> corr;  ///< residual correlations at lags 1..residual_ar1_lags
  long steps = 0;
};

ResidualPass residualPass(const BlockStream& stream, const Eigen::VectorXd& z, int k, int max_lag,
                          FreeDecayNoisePropagation* propagation, Estimate* e) {
  ResidualPass out;
  ResidualLagAccumulator lags(max_lag);
  Eigen::VectorXd env_num = Eigen::VectorXd::Zero(k);
  double env_den = 0.0;
  bool record_start = true;
  stream([&](int, const RegressionBlock& b) {
    if (record_start) lags.startRecord();
    const Eigen::Vector4d r = blockResidual(*b.d, z, b.y);
    out.rss += r.squaredNorm();
    lags.add(r);
    propagation->add(b);
    env_num.noalias() += b.d->transpose() * b.q;
    env_den += b.q.squaredNorm() * (b.t_next - b.t_prev);
    ++out.blocks;
    record_start = b.last_in_record;
  });
  if (env_den > 0.0) e->envelope_coefficients = -env_num / env_den;
  out.corr = lags.correlations();
  out.steps = lags.steps();
  return out;
}

/// The noise model on q: the record's stated correlation, AR(1) fitted to the residual
/// correlations when the lag-1 test rejects independence, else white.
NoiseCorrelation freeDecayNoiseModel(const SystemInfo& info, const SerialCorrelationTest& test,
                                     const std::vector<double>& corr, Estimate* e) {
  NoiseCorrelation rho;
  if (!info.noise_correlation.empty()) {
    rho.lags = info.noise_correlation;
    e->interval_method_id = "demod_correlation";
    e->noise_model = "stated by the record (demodulator): " + rho.describe();
  } else if (test.correlated) {
    rho.ar1 = fitDifferencedAr1(corr);
    e->interval_method_id = "eiv_ar1";
    e->noise_model = "AR(1) on each slow variable, " + rho.describe() +
                     " fitted to the residual correlations at lags 1-" +
                     std::to_string(corr.size());
  } else {
    e->interval_method_id = "eiv_white";
    e->noise_model = "white";
  }
  return rho;
}

/// Pass 3 (correlated noise only): the sensitivities again, correlated (correlated_noise_gram.h).
Eigen::MatrixXd correlatedMeat(const BlockStream& stream, const SystemInfo& info,
                               const Eigen::VectorXd& z, int k, const NoiseCorrelation& rho) {
  FreeDecayNoisePropagation again(*info.resonator, z);
  CorrelatedSensitivityGram gram(k, rho);
  again.setSampleSink([&](const RegressionBlockMatrix& w, bool first) { gram.add(w, first); });
  stream([&](int, const RegressionBlock& b) { again.add(b); });
  return gram.sum();
}

/// Free decay (2.7): errors in variables, noise on q white, AR(1) (fitted to the residual
/// correlations when the lag-1 test rejects independence) or the record's stated correlation.
HonestCovariance freeDecayCovariance(const BlockStream& stream, const SystemInfo& info,
                                     const SolvedSystem& s, const IdentificationOptions& opt,
                                     Estimate* e) {
  const int k = static_cast<int>(info.names.size());
  const Eigen::VectorXd z = e->values;
  const Eigen::MatrixXd& c = s.ls.unscaled_covariance;
  const int dof_paper = static_cast<int>(s.n - s.ls.rank);
  HonestCovariance h;
  h.dof = dof_paper;
  FreeDecayNoisePropagation propagation(*info.resonator, z);
  const ResidualPass pass = residualPass(stream, z, k, opt.residual_ar1_lags, &propagation, e);
  h.rss = pass.rss;
  const std::vector<double>& corr = pass.corr;
  const SerialCorrelationTest test = testLagOne(corr[0], 0.0, 1.5, pass.steps);
  recordCorrelationTest(test, e);
  const NoiseCorrelation rho = freeDecayNoiseModel(info, test, corr, e);
  Eigen::MatrixXd meat;
  double gain = propagation.noiseGain();
  if (rho.white()) {
    meat = propagation.sensitivityGram();
  } else {
    // E[RSS] gains 2 rho_2 tr(A_i,i-1 A_i,i+1') ~ -32 rho_2 per equation block (A ~ -/+2 I; the
    // w G parts of A are O(h ||G||) and left out).
    meat = correlatedMeat(stream, info, z, k, rho);
    gain -= 32.0 * rho.at(2) * static_cast<double>(pass.blocks);
  }
  const double sigma_q2 = gain > 0.0 ? h.rss / gain * static_cast<double>(s.n) / dof_paper : 0.0;
  h.covariance = sigma_q2 * c * meat * c;
  e->interval_method =
      "errors-in-variables covariance of the differenced regression: sigma_q^2 C (sum_m,m' "
      "rho_|m-m'| W_m W_m') C, W_m = sum_i D-bar_i' de_i/dq_m (samples shared by neighbouring "
      "equations of (2.7), docs/paper.md item 10), noise on q " +
      e->noise_model + ", sigma_q from the residuals";
  e->notes.push_back(
      "noise on q implied by the residuals: sigma_q = " + numberText(std::sqrt(sigma_q2), 6) +
      "; residual lag-1 correlation " + numberText(test.lag1, 6) +
      " (z = " + numberText(test.z, 6) + "; white noise on q predicts 0), lag-2 " +
      numberText(corr[1], 6) + " (white: -0.5)");
  return h;
}

/// Forced, one sweep: noise correlated along the sweep (sweep_noise_ar1.h). With the linearized
/// output errors r_j = A_j^{-1} F(q_j), A_j = dF/dq (stationary_solver.h), e_j = -A_j dq_j and
/// Cov(dq_a, dq_b) = sigma^2 rho^|a - b| I:
///   Cov(z) = sigma^2 C (sum_ab rho^|a - b| H_a H_b') C,   H_a = D_a' A_a,  C = (D'D)^-1,
/// the double sum by the recursion S_b = rho S_{b-1} + H_b (sum_b S_b H_b' + H_b S_b' - H_b H_b'),
/// sigma^2 = sum |r_j|^2 / (4 N - k). False (nothing changed) when the noise is white, a point sits
/// at a fold (A_j singular) or the system's residuals are not -F (a check, 1e-6 relative).
bool sweepAr1Covariance(const BlockStream& stream, const SystemInfo& info, const SolvedSystem& s,
                        Estimate* e, HonestCovariance* h) {
  if (!info.single_record || info.resonator == nullptr) return false;
  const int k = static_cast<int>(info.names.size());
  const Eigen::VectorXd z = e->values;
  const SlowContext ctx{0.0, info.mu};
  std::vector<Eigen::Vector4d> r;
  std::vector<double> amp2, abscissa;
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, 4>> hs;
  bool usable = true;
  stream([&](int, const RegressionBlock& b) {
    if (!usable) return;
    const double rate = detuningRate(info.omega_rad_s, b.abscissa);
    const Eigen::Vector4d f = stationaryResidual(*info.resonator, b.q, ctx, z, rate);
    const Eigen::Vector4d res = blockResidual(*b.d, z, b.y);
    if ((res + f).norm() > 1e-6 * (f.norm() + res.norm()) + 1e-300) return void(usable = false);
    const Eigen::Matrix4d a = stationaryJacobian(*info.resonator, b.q, ctx, z, rate);
    const Eigen::JacobiSVD<Eigen::Matrix4d> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
    if (!(svd.singularValues()(3) > 1e-9 * svd.singularValues()(0))) return void(usable = false);
    r.push_back(svd.solve(f));
    amp2.push_back(b.q.squaredNorm());
    abscissa.push_back(b.abscissa);
    hs.push_back(b.d->transpose() * a);
  });
  const long m = static_cast<long>(r.size());
  if (!usable || m < 2 || 4 * m <= k) return false;
  const SweepAr1 ar = sweepNoiseAr1(r, amp2, abscissa);
  if (!(ar.rho > 0.0)) return false;
  double ss = 0.0;
  for (const auto& v : r) ss += v.squaredNorm();
  const double sigma2 = ss / static_cast<double>(4 * m - k);
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(k, k), acc = Eigen::MatrixXd::Zero(k, 4);
  for (long b = 0; b < m; ++b) {
    acc = ar.rho * acc + hs[b];
    meat += acc * hs[b].transpose() + hs[b] * acc.transpose() - hs[b] * hs[b].transpose();
  }
  const Eigen::MatrixXd& c = s.ls.unscaled_covariance;
  h->covariance = sigma2 * c * (0.5 * (meat + meat.transpose())) * c;
  h->dof = static_cast<int>(std::max(1L, m - 1));
  e->interval_method_id = "sweep_ar1_output_error";
  e->noise_model = ar.description;
  e->interval_method =
      "sigma^2 C (sum_ab rho^|a-b| D_a' A_a A_b' D_b) C: equation errors -A_j dq_j of the "
      "linearized stationary equations, dq AR(1) along the sweep (" +
      ar.description + "), sigma from the output errors A_j^-1 F(q_j), t with N-1 dof";
  return true;
}

/// Forced sweeps (3.5): per-point (cluster) sandwich; HAC over the points in sweep order when
/// their residuals are serially correlated; the parametric AR(1) covariance above when one sweep's
/// quiet points show noise correlated along it (HAC with a data-chosen bandwidth on 40-80 points
/// covered 0.84 at rho 0.9, SE/RMS down to 0.5: docs/validation_independent.md).
HonestCovariance sweepCovariance(const BlockStream& stream, const SystemInfo& info,
                                 const SolvedSystem& s, Estimate* e) {
  const int k = static_cast<int>(info.names.size());
  const Eigen::VectorXd z = e->values;
  const Eigen::MatrixXd& c = s.ls.unscaled_covariance;
  const int dof_paper = static_cast<int>(s.n - s.ls.rank);
  HonestCovariance h;
  // sum of sc sc' with sc = D_j' r_j: four points' scores are the rows of one Gram block.
  BlockGramAccumulator meat(k);
  RegressionBlockMatrix scores = RegressionBlockMatrix::Zero(4, k);
  long points = 0;
  ResidualLagAccumulator lags(1);
  int in_block = 0, last_record = -1;
  stream([&](int record, const RegressionBlock& b) {
    if (record != last_record) lags.startRecord();
    last_record = record;
    const Eigen::Vector4d r = blockResidual(*b.d, z, b.y);
    h.rss += r.squaredNorm();
    lags.add(r);
    scores.row(in_block).noalias() = r.transpose() * (*b.d);
    ++points;
    if (++in_block == 4) {
      meat.add(scores);
      in_block = 0;
    }
  });
  if (in_block > 0) {
    scores.bottomRows(4 - in_block).setZero();
    meat.add(scores);
  }
  const SerialCorrelationTest test = testLagOne(lags.correlations()[0], 0.0, 1.0, lags.steps());
  recordCorrelationTest(test, e);
  h.dof = static_cast<int>(std::max(1L, info.num_clusters - 1));
  if (sweepAr1Covariance(stream, info, s, e, &h)) return h;
  if (test.correlated && points >= 3 * k) {
    // Second pass only when HAC is needed: the per-point scores in order (points x k).
    Eigen::MatrixXd g(points, k);
    long row = 0;
    stream([&](int, const RegressionBlock& b) {
      g.row(row++).noalias() = blockResidual(*b.d, z, b.y).transpose() * (*b.d);
    });
    const HacCovariance hac = hacCovarianceFromScores(g, s.ls.r_pinv, s.n, s.ls.rank);
    h.covariance = hac.covariance;
    e->interval_method_id = "hac_bartlett_andrews";
    e->noise_model = "serially correlated over the sweep points (lag-1 residual correlation " +
                     numberText(test.lag1, 6) + ", z = " + numberText(test.z, 6) + ")";
    e->interval_method = hac.method + " over the sweep points in order, t with G-1 dof";
    return h;
  }
  const double g = static_cast<double>(std::max(2L, info.num_clusters));
  const double factor = g / (g - 1.0) * static_cast<double>(s.n - 1) / dof_paper;
  h.covariance = factor * c * meat.sum() * c;
  e->interval_method_id = "cluster_sandwich";
  e->noise_model = "independent between sweep points";
  e->interval_method =
      "per-point (cluster) sandwich (D'D)^-1 D' Omega D (D'D)^-1, Omega block-diagonal from the "
      "residuals (noisy q enters y and D of a point), x G/(G-1) (n-1)/(n-k), t with G-1 dof";
  return h;
}

/// A stacked free-decay system carries no sample structure: the paper's (2.11).
HonestCovariance paperOnly(const BlockStream& stream, const Estimate& e) {
  HonestCovariance h;
  stream([&](int, const RegressionBlock& b) {
    h.rss += blockResidual(*b.d, e.values, b.y).squaredNorm();
  });
  h.dof = e.dof;
  return h;
}

/// Intervals of the parameters and the paper's (2.11) beside them; identifiability (exact rank
/// and near-collinear) decides which parameters get a plain interval.
void fillIntervals(const SolvedSystem& s, HonestCovariance h, const SystemInfo& info,
                   const IdentificationOptions& opt, Estimate* e) {
  const int k = static_cast<int>(info.names.size());
  const int dof_paper = static_cast<int>(s.n - s.ls.rank);
  e->sigma = std::sqrt(h.rss / dof_paper);
  e->covariance_paper = e->sigma * e->sigma * s.ls.unscaled_covariance;
  if (h.covariance.size() == 0) {
    h.covariance = e->covariance_paper;
    h.dof = dof_paper;
    e->interval_method = "paper (2.11) (a stacked system carries no sample structure)";
    e->interval_method_id = "paper_2_11";
  }
  h.covariance = 0.5 * (h.covariance + h.covariance.transpose());
  for (int j = 0; j < k; ++j) {
    if (!(h.covariance(j, j) >= 0.0) || !std::isfinite(h.covariance(j, j))) {
      h.covariance = e->covariance_paper;
      h.dof = dof_paper;
      e->interval_method = "paper (2.11) (the sandwich was not positive; too few equations)";
      e->interval_method_id = "paper_2_11";
      break;
    }
  }
  e->covariance = h.covariance;
  e->interval_dof = h.dof;
  const double sp_paper = studentQuantile(opt.confidence, dof_paper);
  const double sp_honest = studentQuantile(opt.confidence, h.dof);
  e->notes.push_back("\"parameters\" intervals: " + e->interval_method +
                     "; \"parameters_paper_2_11\": the paper's (2.11), sigma-hat^2 (D'D)^-1 with "
                     "Student-t at n-k dof, which assumes independent equation errors");

  if (s.ls.rank < k) {
    const IdentifiabilityReport idr =
        analyzeIdentifiability(info.names, s.ls.null_space, s.ls.column_norms, s.excitation);
    e->unidentifiable = idr.unidentifiable;
    e->identifiability_note = idr.note;
    for (const auto& comb : idr.combinations)
      e->combinations[comb.name] =
          interval(comb.coefficients.dot(e->values),
                   comb.coefficients.dot(e->covariance * comb.coefficients), sp_honest);
  } else {
    reportCollinearity(analyzeCollinearity(info.names, s.r, k), info.names, e->values,
                       e->covariance, s.excitation, sp_honest, e);
  }
  for (int j = 0; j < k; ++j) {
    const std::string& name = info.names[j];
    if (std::find(e->unidentifiable.begin(), e->unidentifiable.end(), name) !=
        e->unidentifiable.end())
      continue;
    e->parameters[name] = interval(e->values[j], e->covariance(j, j), sp_honest);
    e->parameters_paper[name] = interval(e->values[j], e->covariance_paper(j, j), sp_paper);
  }
}

Estimate runEstimator(const BlockStream& stream, const SystemInfo& info,
                      const IdentificationOptions& opt) {
  Estimate e;
  const SolvedSystem s = solveSystem(stream, info, opt, &e);
  HonestCovariance h;
  if (info.mode == ExperimentMode::kFreeDecay && info.resonator != nullptr) {
    h = freeDecayCovariance(stream, info, s, opt, &e);
  } else if (info.mode == ExperimentMode::kForced) {
    h = sweepCovariance(stream, info, s, &e);
  } else {
    h = paperOnly(stream, e);
  }
  fillIntervals(s, h, info, opt, &e);
  if (opt.derive_quantities) deriveFromIdentified(&e, info.omega_rad_s, opt.angular_gain_k);
  return e;
}

double resolveOmega(double option, double record, bool required, const std::string& src) {
  if (option > 0.0) return option;
  if (record > 0.0) return record;
  if (required)
    throw InputError(src +
                     ": the natural frequency omega is unknown (no '# omega:' line); give "
                     "--omega");
  return 0.0;
}

BlockStream streamOf(const StackedSystem& s) {
  return [&s](const BlockSink& sink) {
    const int k = static_cast<int>(s.names.size());
    RegressionBlockMatrix d(4, k);
    RegressionBlock b;
    b.d = &d;
    for (int i = 0; i < s.numBlocks(); ++i) {
      d = s.d.middleRows(4 * i, 4);
      b.y = s.y.segment<4>(4 * i);
      b.q.setZero();
      b.q[0] = s.amplitude.empty() ? 1.0 : s.amplitude[i];
      b.abscissa = s.abscissa[i];
      b.index = i;
      sink(s.record_index.empty() ? 0 : s.record_index[i], b);
    }
  };
}

}  // namespace

std::vector<std::string> IdentificationOptions::validate() const {
  std::vector<std::string> p;
  if (method != "ls" && method != "rls")
    p.push_back("method must be ls or rls (ceres: refineWithCeres), got '" + method + "'");
  if (!(confidence > 0.0 && confidence < 1.0))
    p.push_back("confidence must lie in (0, 1), got " + numberText(confidence, 6));
  if (!(std::isfinite(omega_rad_s) && omega_rad_s >= 0.0 && omega_rad_s <= 1e10))
    p.push_back("omega must be in [0, 1e10] rad/s (0 = from the record), got " +
                numberText(omega_rad_s, 6));
  if (!(std::isfinite(angular_gain_k) && angular_gain_k > 0.0))
    p.push_back("angular gain K must be finite and > 0, got " + numberText(angular_gain_k, 6));
  if (!std::isfinite(mu)) p.push_back("mu must be finite");
  if (!(rank_tolerance > 0.0 && rank_tolerance < 1.0))
    p.push_back("rank tolerance must lie in (0, 1), got " + numberText(rank_tolerance, 6));
  if (!(uniform_time_tolerance > 0.0 && uniform_time_tolerance < 1.0))
    p.push_back("uniform time tolerance must lie in (0, 1), got " +
                numberText(uniform_time_tolerance, 6));
  if (rls_init_blocks < 0) p.push_back("RLS initial blocks must be >= 0 (0 = automatic)");
  if (!(rls_forgetting > 0.0 && rls_forgetting <= 1.0))
    p.push_back("RLS forgetting factor must lie in (0, 1], got " + numberText(rls_forgetting, 6));
  if (residual_ar1_lags < 2)
    p.push_back("residual AR(1) lags must be >= 2, got " + std::to_string(residual_ar1_lags));
  return p;
}

namespace {

std::string recordName(const SlowRecord& r, size_t k) {
  return r.source.empty() ? "record " + std::to_string(k + 1) : r.source;
}

/// Stacked free decays must be of one resonator and each counted once: a record given twice would
/// narrow every interval as if it were new data. Without a given omega their natural frequencies
/// must agree within 100 ppm (a resonator's drift with temperature; the first record's is used),
/// or be unknown in all; a given omega (--omega) is the common one.
void requireOneResonator(const std::vector<const SlowRecord*>& records, double option_omega) {
  for (size_t k = 1; k < records.size(); ++k) {
    const SlowRecord& r = *records[k];
    for (size_t j = 0; j < k; ++j)
      if (records[j] == records[k] || (!r.source.empty() && r.source == records[j]->source))
        throw InputError(recordName(r, k) +
                         ": given twice; a record counted twice would narrow every interval as if "
                         "it were new data");
    if (option_omega > 0.0) continue;
    const double w0 = records.front()->omega_rad_s, w = r.omega_rad_s;
    if (!std::isfinite(w) || !(std::fabs(w - w0) <= 1e-4 * std::max(std::fabs(w0), std::fabs(w))))
      throw InputError(recordName(r, k) + ": omega " + numberText(w, 6) + " rad/s differs from " +
                       recordName(*records.front(), 0) + "'s " + numberText(w0, 6) +
                       " rad/s by more than 100 ppm: stacked records must be of one resonator; "
                       "give their common --omega (raw records each get their own estimate)");
  }
}

/// Free decay over records given by pointer (the single-record overload copies nothing).
Estimate identifyFreeDecayRecords(const std::vector<const SlowRecord*>& records,
                                  const IdentificationOptions& options) {
  throwIfInvalid(options);
  if (records.empty()) throw InputError("no free-decay record given");
  const ResonatorModel model(options.model, ExperimentMode::kFreeDecay);
  SystemInfo info;
  info.mode = ExperimentMode::kFreeDecay;
  info.model = model.spec();
  info.names = model.parameterNames();
  info.max_lag_blocks = 2;
  info.resonator = &model;
  info.omega_rad_s = resolveOmega(options.omega_rad_s, records[0]->omega_rad_s, false, "");
  info.noise_correlation = noiseCorrelationFromMetadata(records[0]->metadata);
  requireOneResonator(records, options.omega_rad_s);
  std::vector<bool> simpson(records.size());
  for (size_t r = 0; r < records.size(); ++r) {
    const SlowRecord& rec = *records[r];
    validateFreeDecayRecord(rec);
    if (records.size() == 1) requireSufficientData(rec, model.numParameters());
    simpson[r] = hasUniformTimes(rec, options.uniform_time_tolerance);
    info.notes.push_back(
        (rec.source.empty() ? "record " + std::to_string(r) : rec.source) + ": " +
        std::to_string(rec.size()) + " samples, integral of D(q) over [t_{i-1}, t_{i+1}] by " +
        (simpson[r] ? "Simpson's rule (uniform times)" : "the trapezoid rule (irregular times)") +
        ", y_i = 2 (q_{i+1} - q_{i-1}) (factor 1/2 of (2.7) kept)");
    const std::vector<size_t> gaps = timeGapsOf(rec);
    if (!gaps.empty()) {
      std::string where;
      for (size_t g = 0; g < gaps.size() && g < 5; ++g)
        where += (g ? ", " : "") + numberText(rec.t_s[gaps[g]], 6) + " -> " +
                 numberText(rec.t_s[gaps[g] + 1], 6) + " s";
      info.notes.push_back(
          (rec.source.empty() ? "record " + std::to_string(r) : rec.source) + ": " +
          std::to_string(gaps.size()) + " gap(s) in time (a step over 5x the median: " + where +
          (gaps.size() > 5 ? ", ..." : "") +
          "): the equations spanning them are left out, not integrated across the gap");
    }
  }
  if (records.size() > 1)
    info.notes.push_back(std::to_string(records.size()) +
                         " records stacked into one regression (each keeps its own time origin "
                         "and lags; no equation joins two records)");
  const BlockStream stream = [&](const BlockSink& sink) {
    for (size_t r = 0; r < records.size(); ++r) {
      forEachValidatedFreeDecayBlock(model, *records[r], simpson[r], [&](const RegressionBlock& b) {
        sink(static_cast<int>(r), b);
      });
    }
  };
  return runEstimator(stream, info, options);
}

}  // namespace

Estimate identifyFreeDecay(const SlowRecord& record, const IdentificationOptions& options) {
  return identifyFreeDecayRecords({&record}, options);
}

Estimate identifyFreeDecay(const std::vector<SlowRecord>& records,
                           const IdentificationOptions& options) {
  return identifyFreeDecayRecords(pointersTo(records), options);
}

namespace {

/// Forced sweeps given by pointer (the single-record overload copies nothing).
Estimate identifyForcedRecords(const std::vector<const SweepRecord*>& records,
                               const IdentificationOptions& options) {
  throwIfInvalid(options);
  if (records.empty()) throw InputError("no sweep record given");
  const ResonatorModel model(options.model, ExperimentMode::kForced);
  if (model.estimatesMu())
    throw InputError(
        "model '" + model.spec() +
        "' estimates the control nonlinearity mu, which multiplies u~ bilinearly in (3.2): linear "
        "least squares cannot estimate it; use --method ceres (output-error fit), or drop 'mu' "
        "and give the known mu");
  SystemInfo info;
  info.mode = ExperimentMode::kForced;
  info.model = model.spec();
  info.names = model.parameterNames();
  info.max_lag_blocks = 0;
  info.resonator = &model;
  info.mu = options.mu;
  info.single_record = records.size() == 1;
  info.omega_rad_s = resolveOmega(options.omega_rad_s, records[0]->omega_rad_s, true,
                                  records[0]->source.empty() ? "sweep" : records[0]->source);
  for (const SweepRecord* r : records) {
    validateSweepRecord(*r);
    if (records.size() == 1) requireSufficientData(*r, model.numParameters());
    info.num_clusters += static_cast<long>(r->size());
  }
  info.notes.push_back(
      "stationary equations (3.4): y_j = ((omega0^2 - omega^2)/omega0) (p1, -q1, "
      "p2, -q2) (exact detuning rate, docs/paper.md item 7), omega = " +
      numberText(info.omega_rad_s, 6) + " rad/s, known mu = " + numberText(options.mu, 6));
  info.notes.push_back(
      "equation-error LS puts the noisy q inside D: biased ~ sigma_q^2 (docs/paper.md "
      "item 15); --method ceres removes it");
  const BlockStream stream = [&](const BlockSink& sink) {
    for (size_t r = 0; r < records.size(); ++r) {
      forEachValidatedForcedBlock(model, *records[r], info.omega_rad_s, options.mu,
                                  [&](const RegressionBlock& b) { sink(static_cast<int>(r), b); });
    }
  };
  return runEstimator(stream, info, options);
}

}  // namespace

Estimate identifyForced(const SweepRecord& record, const IdentificationOptions& options) {
  return identifyForcedRecords({&record}, options);
}

Estimate identifyForced(const std::vector<SweepRecord>& records,
                        const IdentificationOptions& options) {
  return identifyForcedRecords(pointersTo(records), options);
}

StackedSystem buildFreeDecaySystem(const std::vector<SlowRecord>& records,
                                   const IdentificationOptions& options) {
  throwIfInvalid(options);
  const ResonatorModel model(options.model, ExperimentMode::kFreeDecay);
  StackedSystem s;
  s.mode = ExperimentMode::kFreeDecay;
  s.model = model.spec();
  s.names = model.parameterNames();
  long blocks = 0;
  for (const auto& r : records) {
    validateFreeDecayRecord(r);
    blocks += static_cast<long>(r.size()) - 2;
    s.simpson = s.simpson && hasUniformTimes(r, options.uniform_time_tolerance);
  }
  s.d.resize(4 * blocks, model.numParameters());
  s.y.resize(4 * blocks);
  long i = 0;
  for (size_t r = 0; r < records.size(); ++r) {
    forEachFreeDecayBlock(model, records[r], options.uniform_time_tolerance,
                          [&](const RegressionBlock& b) {
                            s.d.middleRows(4 * i, 4) = *b.d;
                            s.y.segment<4>(4 * i) = b.y;
                            s.abscissa.push_back(b.abscissa);
                            s.amplitude.push_back(b.q.norm());
                            s.record_index.push_back(static_cast<int>(r));
                            ++i;
                          });
  }
  return s;
}

StackedSystem buildForcedSystem(const std::vector<SweepRecord>& records,
                                const IdentificationOptions& options) {
  throwIfInvalid(options);
  if (records.empty()) throw InputError("no sweep record given");
  const ResonatorModel model(options.model, ExperimentMode::kForced);
  const double omega = resolveOmega(options.omega_rad_s, records[0].omega_rad_s, true,
                                    records[0].source.empty() ? "sweep" : records[0].source);
  StackedSystem s;
  s.mode = ExperimentMode::kForced;
  s.model = model.spec();
  s.names = model.parameterNames();
  long blocks = 0;
  for (const auto& r : records) {
    validateSweepRecord(r);
    blocks += static_cast<long>(r.size());
  }
  s.d.resize(4 * blocks, model.numParameters());
  s.y.resize(4 * blocks);
  long i = 0;
  for (size_t r = 0; r < records.size(); ++r) {
    forEachForcedBlock(model, records[r], omega, options.mu, [&](const RegressionBlock& b) {
      s.d.middleRows(4 * i, 4) = *b.d;
      s.y.segment<4>(4 * i) = b.y;
      s.abscissa.push_back(b.abscissa);
      s.detuning_rad_s.push_back(b.abscissa - omega);
      s.amplitude.push_back(b.q.norm());
      s.record_index.push_back(static_cast<int>(r));
      ++i;
    });
  }
  return s;
}

Eigen::VectorXd equationResiduals(const StackedSystem& system, const Eigen::VectorXd& z) {
  if (z.size() != system.d.cols())
    throw InputError("residuals: " + std::to_string(z.size()) + " values for " +
                     std::to_string(system.d.cols()) + " columns");
  return system.y - system.d * z;
}

Estimate estimateFromSystem(const StackedSystem& system, const IdentificationOptions& options) {
  throwIfInvalid(options);
  const int k = static_cast<int>(system.names.size());
  if (system.d.cols() != k || system.d.rows() != system.y.size() || system.d.rows() % 4 != 0 ||
      system.d.rows() / 4 != system.numBlocks())
    throw InputError("stacked system: inconsistent sizes (rows must be 4 per block)");
  if (k < 1 || k > kMaxModelParameters) throw InputError("stacked system: bad number of columns");
  if (!system.d.allFinite() || !system.y.allFinite())
    throw InputError("stacked system: non-finite entries");
  SystemInfo info;
  info.mode = system.mode;
  info.model = system.model;
  info.names = system.names;
  info.max_lag_blocks = system.mode == ExperimentMode::kFreeDecay ? 2 : 0;
  info.num_clusters = system.numBlocks();
  info.omega_rad_s = options.omega_rad_s;
  IdentificationOptions opt = options;
  opt.method = "ls";
  return runEstimator(streamOf(system), info, opt);
}

}  // namespace cvg_bench

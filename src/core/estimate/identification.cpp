#include "cvg_bench/core/estimate/identification.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "cvg_bench/core/estimate/data_sufficiency.h"
#include "cvg_bench/core/estimate/derived_uncertainty.h"
#include "cvg_bench/core/estimate/forced_regression.h"
#include "cvg_bench/core/estimate/free_decay_noise_propagation.h"
#include "cvg_bench/core/estimate/free_decay_regression.h"
#include "cvg_bench/core/estimate/identifiability.h"
#include "cvg_bench/core/estimate/internal/block_gram_accumulator.h"
#include "cvg_bench/core/estimate/internal/regression_block_ops.h"
#include "cvg_bench/core/estimate/least_squares_solver.h"
#include "cvg_bench/core/estimate/recursive_least_squares.h"
#include "cvg_bench/core/estimate/student_t.h"
#include "cvg_bench/core/model/errors.h"

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

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

void throwIfInvalid(const IdentificationOptions& o) {
  const auto problems = o.validate();
  if (problems.empty()) return;
  std::string msg = "invalid identification options:";
  for (const auto& p : problems) msg += " " + p + ";";
  throw InputError(msg);
}

ParameterEstimate interval(double value, double variance, double s_p) {
  ParameterEstimate p;
  p.value = value;
  p.std_error = std::sqrt(std::max(0.0, variance));
  p.ci_low = value - s_p * p.std_error;
  p.ci_high = value + s_p * p.std_error;
  return p;
}

Estimate runEstimator(const BlockStream& stream, const SystemInfo& info,
                      const IdentificationOptions& opt) {
  const int k = static_cast<int>(info.names.size());
  const bool rls = opt.method == "rls";
  // ---- pass 1: QR of the whole system (and RLS over the same blocks)
  IncrementalQr qr(k);
  SquaredExcitation excitation;
  const int m_init = opt.rls_init_blocks > 0 ? opt.rls_init_blocks : std::max(2 * k, 8);
  IncrementalQr qr_init(k);
  BlockRecursiveLeastSquares filter(k, opt.rls_forgetting);
  long block_no = 0;
  bool rls_failed = false;
  stream([&](int, const RegressionBlock& b) {
    qr.addBlock(*b.d, b.y);
    excitation.add(b.q);
    if (rls && !rls_failed) {
      if (block_no < m_init) {
        qr_init.addBlock(*b.d, b.y);
      } else {
        if (!filter.initialized()) {
          try {
            filter.initialize(qr_init.rAug(), qr_init.numRows());
          } catch (const AnalysisError&) {
            rls_failed = true;
          }
        }
        if (!rls_failed) filter.update(*b.d, b.y);
      }
    }
    ++block_no;
  });
  const long n = qr.numRows();
  if (n <= k)
    throw InputError(std::to_string(n) + " equations for " + std::to_string(k) +
                     " parameters of model " + info.model + ": more data needed (n > k)");
  const LeastSquaresSolution ls = solveTriangular(qr.rAug(), n, opt.rank_tolerance);

  Estimate e;
  e.mode = info.mode;
  e.model = info.model;
  e.method = opt.method;
  e.omega_rad_s = info.omega_rad_s;
  e.n_equations = static_cast<int>(n);
  e.n_params = k;
  e.rank = ls.rank;
  e.dof = static_cast<int>(n - ls.rank);
  e.confidence = opt.confidence;
  e.names = info.names;
  e.rank_tolerance = opt.rank_tolerance;
  e.singular_values.assign(ls.singular_values.data(),
                           ls.singular_values.data() + ls.singular_values.size());
  e.notes = info.notes;
  e.values = ls.z;
  if (rls) {
    if (rls_failed || !filter.initialized() || ls.rank < k) {
      e.notes.push_back("RLS not run: the first " + std::to_string(m_init) +
                        " blocks (or the whole record) do not determine all parameters; "
                        "batch LS result reported");
      e.method = "ls";
    } else {
      e.values = filter.z();
      e.notes.push_back(
          "block RLS (2.12) with the corrected pairing y_{i+1} - D_{i+1} z_i "
          "(docs/paper.md item 9), initialised by QR on the first " +
          std::to_string(m_init) + " blocks, forgetting factor " + fmt(opt.rls_forgetting) +
          "; paper's prediction bound (sigma_e = sigma) " +
          fmt(filter.predictionSigmaBound(filter.sigma())));
    }
  }

  // ---- pass 2: residuals and the honest covariance
  const Eigen::VectorXd z = e.values;
  const Eigen::MatrixXd& c = ls.unscaled_covariance;
  const int dof_paper = static_cast<int>(n - ls.rank);
  double rss = 0.0;
  Eigen::MatrixXd honest;
  int dof_honest = dof_paper;
  if (info.mode == ExperimentMode::kFreeDecay && info.resonator != nullptr) {
    // Errors in variables (free_decay_noise_propagation.h): D' Omega D = sigma_q^2 sum_m W_m W_m',
    // sigma_q^2 = RSS / sum ||A_im||_F^2 x n / (n - k).
    FreeDecayNoisePropagation propagation(*info.resonator, z);
    double lag2 = 0.0;
    Eigen::Vector4d r_hist[2] = {Eigen::Vector4d::Zero(), Eigen::Vector4d::Zero()};
    long in_record = 0;
    stream([&](int, const RegressionBlock& b) {
      const Eigen::Vector4d r = blockResidual(*b.d, z, b.y);
      rss += r.squaredNorm();
      if (in_record >= 2) lag2 += r.dot(r_hist[1]);
      r_hist[1] = r_hist[0];
      r_hist[0] = r;
      propagation.add(b);
      in_record = b.last_in_record ? 0 : in_record + 1;
    });
    const double tr_a = propagation.noiseGain();
    const double sigma_q2 = tr_a > 0.0 ? rss / tr_a * static_cast<double>(n) / dof_paper : 0.0;
    honest = sigma_q2 * c * propagation.sensitivityGram() * c;
    e.interval_method =
        "errors-in-variables covariance of the differenced regression: sigma_q^2 C (sum_m W_m "
        "W_m') C, W_m = sum_i D-bar_i' de_i/dq_m (samples shared by neighbouring equations of "
        "(2.7), docs/paper.md item 10), white noise on q with sigma_q from the residuals";
    e.notes.push_back("noise on q implied by the residuals: sigma_q = " + fmt(std::sqrt(sigma_q2)) +
                      "; residual lag-2-block correlation " + fmt(rss > 0 ? lag2 / rss : 0.0) +
                      " (white noise on q predicts -0.5)");
  } else {
    // Sweep points are independent: per-point (cluster) sandwich from the residuals.
    // sum of sc sc' with sc = D_j' r_j: four points' scores are the rows of one Gram block.
    BlockGramAccumulator meat(k);
    RegressionBlockMatrix scores = RegressionBlockMatrix::Zero(4, k);
    int in_block = 0;
    stream([&](int, const RegressionBlock& b) {
      const Eigen::Vector4d r = blockResidual(*b.d, z, b.y);
      rss += r.squaredNorm();
      scores.row(in_block).noalias() = r.transpose() * (*b.d);
      if (++in_block == 4) {
        meat.add(scores);
        in_block = 0;
      }
    });
    if (in_block > 0) {
      scores.bottomRows(4 - in_block).setZero();
      meat.add(scores);
    }
    const double g = static_cast<double>(std::max(2L, info.num_clusters));
    const double factor = g / (g - 1.0) * static_cast<double>(n - 1) / dof_paper;
    honest = factor * c * meat.sum() * c;
    dof_honest = static_cast<int>(std::max(1L, info.num_clusters - 1));
    e.interval_method =
        "per-point (cluster) sandwich (D'D)^-1 D' Omega D (D'D)^-1, Omega block-diagonal from the "
        "residuals (noisy q enters y and D of a point), x G/(G-1) (n-1)/(n-k), t with G-1 dof";
    if (info.mode == ExperimentMode::kFreeDecay) {
      honest = Eigen::MatrixXd();
      e.interval_method = "paper (2.11) (a stacked system carries no sample structure)";
    }
  }
  e.sigma = std::sqrt(rss / dof_paper);
  e.covariance_paper = e.sigma * e.sigma * c;
  if (honest.size() == 0) honest = e.covariance_paper;
  honest = 0.5 * (honest + honest.transpose());
  bool honest_ok = true;
  for (int j = 0; j < k; ++j)
    if (!(honest(j, j) >= 0.0) || !std::isfinite(honest(j, j))) honest_ok = false;
  if (!honest_ok) {
    honest = e.covariance_paper;
    dof_honest = dof_paper;
    e.interval_method = "paper (2.11) (the sandwich was not positive; too few equations)";
  }
  e.covariance = honest;
  e.interval_dof = dof_honest;
  const double sp_paper = studentQuantile(opt.confidence, dof_paper);
  const double sp_honest = studentQuantile(opt.confidence, dof_honest);
  e.notes.push_back("\"parameters\" intervals: " + e.interval_method +
                    "; \"parameters_paper_2_11\": the paper's (2.11), sigma-hat^2 (D'D)^-1 with "
                    "Student-t at n-k dof, which assumes independent equation errors");

  // ---- identifiability
  const IdentifiabilityReport idr =
      analyzeIdentifiability(info.names, ls.null_space, ls.column_norms, excitation.summary());
  e.unidentifiable = idr.unidentifiable;
  e.identifiability_note = idr.note;
  for (int j = 0; j < k; ++j) {
    if (std::find(idr.unidentifiable.begin(), idr.unidentifiable.end(), info.names[j]) !=
        idr.unidentifiable.end())
      continue;
    e.parameters[info.names[j]] = interval(e.values[j], honest(j, j), sp_honest);
    e.parameters_paper[info.names[j]] = interval(e.values[j], e.covariance_paper(j, j), sp_paper);
  }
  for (const auto& comb : idr.combinations) {
    e.combinations[comb.name] =
        interval(comb.coefficients.dot(e.values), comb.coefficients.dot(honest * comb.coefficients),
                 sp_honest);
  }

  // ---- derived quantities (section 4) by the delta method
  if (opt.derive_quantities && ls.rank == k) {
    const double omega = info.omega_rad_s;
    if (omega > 0.0) {
      try {
        e.derived =
            deriveQuantitiesWithIntervals(uncertainParameters(e), omega, opt.angular_gain_k);
      } catch (const InputError& err) {
        e.notes.push_back(std::string("derived quantities not computed: ") + err.what());
      }
    } else {
      e.notes.push_back("derived quantities not computed: omega unknown (give --omega)");
    }
  }
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
    p.push_back("confidence must lie in (0, 1), got " + fmt(confidence));
  if (!(std::isfinite(omega_rad_s) && omega_rad_s >= 0.0 && omega_rad_s <= 1e10))
    p.push_back("omega must be in [0, 1e10] rad/s (0 = from the record), got " + fmt(omega_rad_s));
  if (!(std::isfinite(angular_gain_k) && angular_gain_k > 0.0))
    p.push_back("angular gain K must be finite and > 0, got " + fmt(angular_gain_k));
  if (!std::isfinite(mu)) p.push_back("mu must be finite");
  if (!(rank_tolerance > 0.0 && rank_tolerance < 1.0))
    p.push_back("rank tolerance must lie in (0, 1), got " + fmt(rank_tolerance));
  if (!(uniform_time_tolerance > 0.0 && uniform_time_tolerance < 1.0))
    p.push_back("uniform time tolerance must lie in (0, 1), got " + fmt(uniform_time_tolerance));
  if (rls_init_blocks < 0) p.push_back("RLS initial blocks must be >= 0 (0 = automatic)");
  if (!(rls_forgetting > 0.0 && rls_forgetting <= 1.0))
    p.push_back("RLS forgetting factor must lie in (0, 1], got " + fmt(rls_forgetting));
  return p;
}

namespace {

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
  }
  if (records.size() > 1)
    info.notes.push_back(std::to_string(records.size()) + " records stacked into one regression");
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
  const auto& ext = model.extensionNames();
  if (std::find(ext.begin(), ext.end(), "mu") != ext.end())
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
      fmt(info.omega_rad_s) + " rad/s, known mu = " + fmt(options.mu));
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

#include "cvg_bench/core/diagnose/nested_model_fitters.h"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/demod/demodulator_noise.h"
#include "cvg_bench/core/diagnose/candidate_extensions.h"
#include "cvg_bench/core/diagnose/sweep_noise_model.h"
#include "cvg_bench/core/estimate/free_decay_regression.h"
#include "cvg_bench/core/estimate/identify_pipeline.h"
#include "cvg_bench/core/estimate/least_squares_solver.h"
#include "cvg_bench/core/estimate/output_error_free_decay.h"
#include "cvg_bench/core/model/resonator_model.h"
#include "cvg_bench/core/model/stationary_solver.h"

namespace cvg_bench {

std::vector<std::string> NestedFitterOptions::validate() const {
  std::vector<std::string> p = identification.validate();
  for (const auto& c : ceres.validate()) p.push_back(c);
  if (!(holdout_fraction >= 0.1 && holdout_fraction <= 0.6))
    p.push_back("holdout_fraction must lie in [0.1, 0.6], got " + std::to_string(holdout_fraction));
  if (rk4_substeps < 1 || rk4_substeps > 1000)
    p.push_back("rk4_substeps must lie in 1..1000, got " + std::to_string(rk4_substeps));
  return p;
}

namespace {

NestedFit fitSystem(const StackedSystem& sys, const IdentificationOptions& o,
                    const std::vector<std::string>& extensions) {
  NestedFit f;
  f.extensions = extensions;
  f.estimate = estimateFromSystem(sys, o);
  f.model = f.estimate.model;
  f.residuals = equationResiduals(sys, f.estimate.values);
  f.rss = f.residuals.squaredNorm();
  f.n_equations = static_cast<long>(sys.y.size());
  f.sigma = f.estimate.sigma;
  return f;
}

/// LS residuals only (column-equilibrated pivoted QR, no covariance): the cheap fit that ranks
/// subsets by their residual sums.
NestedFit residualsOnly(const StackedSystem& sys, const std::vector<std::string>& extensions) {
  NestedFit f;
  f.extensions = extensions;
  f.model = sys.model;
  const Eigen::VectorXd norms = sys.d.colwise().norm().transpose().cwiseMax(1e-300);
  const Eigen::MatrixXd scaled = sys.d * norms.cwiseInverse().asDiagonal();
  const Eigen::VectorXd z = scaled.colPivHouseholderQr().solve(sys.y).cwiseQuotient(norms);
  f.residuals = sys.y - sys.d * z;
  f.rss = f.residuals.squaredNorm();
  f.n_equations = static_cast<long>(sys.y.size());
  const long dof = std::max<long>(1, f.n_equations - sys.d.cols());
  f.sigma = std::sqrt(f.rss / static_cast<double>(dof));
  f.estimate.model = sys.model;
  f.estimate.method = "ls";
  f.estimate.names = sys.names;
  f.estimate.values = z;
  f.estimate.n_params = static_cast<int>(sys.d.cols());
  f.estimate.sigma = f.sigma;
  return f;
}

/// Forced LS (per-point cluster sandwich intervals) plus the equation residuals.
NestedFit fitRecord(const SweepRecord& record, const IdentificationOptions& o,
                    const std::vector<std::string>& extensions) {
  const StackedSystem sys = buildForcedSystem({record}, o);
  NestedFit f = fitSystem(sys, o, extensions);
  PipelineOptions ls;
  ls.method = Method::kLs;
  ls.identification = o;
  f.estimate = identify(record, ls);
  f.residuals = equationResiduals(sys, f.estimate.values);
  f.rss = f.residuals.squaredNorm();
  f.sigma = f.estimate.sigma;
  return f;
}

/// The triangular factor [R c; 0 rho] of the stacked equation-error system [D | y] of (2.8) for a
/// model holding every extension of the subsets to rank, folded block by block (IncrementalQr,
/// ~10 kB). Every nested model's columns are columns of D (each term adds its own columns), so its
/// LS fit is the small problem min |c - R_S z|^2 + rho^2: the same solution and residual sum as
/// the stacked one, solved the same way (column-equilibrated pivoted QR; the column norms of R_S
/// are those of D_S).
class EquationErrorFactor {
 public:
  const std::vector<std::string>& extensions() const { return extensions_; }
  void clear() {
    extensions_.clear();
    names_.clear();
    r_aug_.resize(0, 0);
  }
  bool covers(const ResonatorModel& model) const {
    if (r_aug_.size() == 0) return false;
    for (const auto& n : model.parameterNames())
      if (std::find(names_.begin(), names_.end(), n) == names_.end()) return false;
    return true;
  }
  void build(const ResonatorModel& model, const SlowRecord& record, double tolerance) {
    clear();
    IncrementalQr qr(model.numParameters());
    forEachFreeDecayBlock(model, record, tolerance,
                          [&](const RegressionBlock& b) { qr.addBlock(*b.d, b.y); });
    rows_ = qr.numRows();
    if (rows_ <= model.numParameters()) return;
    r_aug_ = qr.rAug();
    extensions_ = model.extensionNames();
    names_ = model.parameterNames();
  }
  NestedFit solve(const ResonatorModel& model, const std::vector<std::string>& extensions) const {
    const int k_all = static_cast<int>(names_.size());
    const int k = model.numParameters();
    Eigen::MatrixXd a(k_all, k);
    for (int j = 0; j < k; ++j) {
      const auto it = std::find(names_.begin(), names_.end(), model.parameterNames()[j]);
      a.col(j) = r_aug_.col(it - names_.begin()).head(k_all);
    }
    const Eigen::VectorXd c = r_aug_.col(k_all).head(k_all);
    const Eigen::VectorXd norms = a.colwise().norm().transpose().cwiseMax(1e-300);
    const Eigen::MatrixXd scaled = a * norms.cwiseInverse().asDiagonal();
    const Eigen::VectorXd z = scaled.colPivHouseholderQr().solve(c).cwiseQuotient(norms);
    NestedFit f;
    f.extensions = extensions;
    f.model = model.spec();
    f.rss = (c - a * z).squaredNorm() + r_aug_(k_all, k_all) * r_aug_(k_all, k_all);
    f.n_equations = rows_;
    const long dof = std::max<long>(1, f.n_equations - k);
    f.sigma = std::sqrt(f.rss / static_cast<double>(dof));
    f.estimate.model = model.spec();
    f.estimate.method = "ls";
    f.estimate.names = model.parameterNames();
    f.estimate.values = z;
    f.estimate.n_params = k;
    f.estimate.sigma = f.sigma;
    return f;
  }

 private:
  std::vector<std::string> extensions_, names_;
  Eigen::MatrixXd r_aug_;
  long rows_ = 0;
};

class FreeDecayFitter : public NestedModelFitter {
 public:
  FreeDecayFitter(const SlowRecord& record, const NestedFitterOptions& options)
      : record_(record), options_(options) {
    throwIfInvalid("invalid explain fitting options", options.validate());
  }

  NestedFit fit(const std::vector<std::string>& extensions) const override {
    return fitOn(record_, extensions);
  }
  NestedFit fitNear(const std::vector<std::string>& extensions,
                    const NestedFit& near) const override {
    if (near.estimate.method != methodName(Method::kCeres)) return fit(extensions);
    std::map<std::string, double> start;
    for (size_t i = 0; i < near.estimate.names.size(); ++i)
      start[near.estimate.names[i]] = near.estimate.values[i];
    // The added terms start at zero, where the wider model is the nearer one at its optimum
    // (their LS values, biased by the noise in D(q), start far from it).
    const ResonatorModel wider(extensions, ExperimentMode::kFreeDecay);
    for (const auto& name : wider.parameterNames()) start.emplace(name, 0.0);
    return fitOn(record_, extensions, start, near.estimate.initial_slow_state);
  }

  /// Every subset is solved from the triangular factor of the widest system seen so far (one
  /// pass over the record per widening, see EquationErrorFactor); the per-equation residuals are
  /// made (one more pass) only for a fit that is not a strict subset of an earlier successful one:
  /// the subset search reads those of the linear model and of the widest fit, the rest need only
  /// the residual sum.
  NestedFit fitEquationError(const std::vector<std::string>& extensions) const override {
    const ResonatorModel model(extensions, ExperimentMode::kFreeDecay);
    NestedFit f;
    if (!factor_.covers(model)) {
      std::vector<std::string> wider = factor_.extensions();
      for (const auto& e : extensions)
        if (std::find(wider.begin(), wider.end(), e) == wider.end()) wider.push_back(e);
      try {
        factor_.build(ResonatorModel(wider, ExperimentMode::kFreeDecay), record_,
                      options_.identification.uniform_time_tolerance);
      } catch (const InputError&) {
        factor_.clear();
      }
    }
    bool need_residuals = true;
    for (const auto& done : fitted_cheap_)
      if (strictSubset(extensions, done)) need_residuals = false;
    if (factor_.covers(model)) {
      f = factor_.solve(model, extensions);
      if (need_residuals) {
        f.residuals = equationResidualsStreamed(model, f.estimate.values);
      }
    } else {
      IdentificationOptions o = options_.identification;
      o.model = model.spec();
      f = residualsOnly(buildFreeDecaySystem({record_}, o), extensions);
      if (!need_residuals) f.residuals.resize(0);
    }
    fitted_cheap_.push_back(extensions);
    return f;
  }
  bool refinesByOutputError() const override { return true; }
  std::vector<double> knownNoiseCorrelation() const override {
    return noiseCorrelationFromMetadata(record_.metadata);
  }

  double holdoutRms(const std::vector<std::string>& extensions) const override {
    const size_t n = record_.size();
    const size_t split = static_cast<size_t>(std::floor((1.0 - options_.holdout_fraction) * n));
    SlowRecord train = record_;
    train.t_s.assign(record_.t_s.begin(), record_.t_s.begin() + split);
    train.q.assign(record_.q.begin(), record_.q.begin() + split);
    const Estimate e = fitOn(train, extensions).estimate;  // values only: never finished
    const ResonatorModel model(extensions, ExperimentMode::kFreeDecay);
    ParameterValues values;
    for (size_t i = 0; i < e.names.size(); ++i) values[e.names[i]] = e.values[i];
    std::vector<Eigen::Vector4d> trajectory;
    if (!integrateSlowTrajectory(model, model.parameterVector(values), record_.q.front(),
                                 record_.t_s, options_.rk4_substeps, &trajectory) ||
        trajectory.size() != n)
      return std::numeric_limits<double>::infinity();
    double ss = 0.0;
    for (size_t i = split; i < n; ++i) ss += (trajectory[i] - record_.q[i]).squaredNorm();
    return std::sqrt(ss / (4.0 * (n - split)));
  }

  std::string holdoutDescription() const override {
    return "fit on the first " +
           std::to_string(static_cast<int>(std::lround(100 * (1 - options_.holdout_fraction)))) +
           " % of the record, integrate the averaged equations from the first sample, RMS of "
           "q_model - q_measured over the rest";
  }

  std::vector<BlockResidual> blocks(const NestedFit& fit) const override {
    // A cheap fit nested in an earlier one keeps no residual vector (fitCheap): recomputed here,
    // one pass over the record, when the selection asks for its blocks.
    if (fit.residuals.size() == 0 && fit.estimate.values.size() > 0) {
      NestedFit with = fit;
      with.residuals = equationResidualsStreamed(
          ResonatorModel(fit.model, ExperimentMode::kFreeDecay), fit.estimate.values);
      return blocks(with);
    }
    // Block i of (2.8) is centred on sample i + 1 (one record).
    const size_t nb = fit.residuals.size() / 4;
    std::vector<Eigen::Vector4d> q(nb);
    std::vector<double> t(nb);
    for (size_t i = 0; i < nb; ++i) {
      q[i] = record_.q[i + 1];
      t[i] = record_.t_s[i + 1] - record_.t_s.front();
    }
    return blockResiduals(fit.residuals, q, t, {});
  }

  std::vector<BlockResidual> adequacyResiduals(const NestedFit& fit) const override {
    const ResonatorModel model(fit.model, ExperimentMode::kFreeDecay);
    ParameterValues values;
    for (size_t i = 0; i < fit.estimate.names.size(); ++i)
      values[fit.estimate.names[i]] = fit.estimate.values[i];
    const Eigen::VectorXd z = model.parameterVector(values);
    const size_t n = record_.size();
    // The initial state q(t0) at the fitted z by Gauss-Newton (4 unknowns, Jacobian -dq/dq(t0)
    // by forward sensitivities, folded sample by sample into a 5 x 5 factor): the nuisance part
    // of the output-error fit, so that the residuals are the noise alone.
    // From the output-error fit's own q(t0) where it has one (a start at the noisy first sample
    // can make an undamped Gauss-Newton step leave the region where the trajectory exists).
    const Eigen::Vector4d start = fit.estimate.initial_slow_state.size() == 4
                                      ? Eigen::Vector4d(fit.estimate.initial_slow_state)
                                      : record_.q.front();
    Eigen::Vector4d q0 = start;
    for (int iter = 0; iter < 4; ++iter) {
      IncrementalQr qr(4);
      RegressionBlockMatrix minus_s(4, 4);
      const bool ok = integrateSlowInitialSensitivity(
          model, z, q0, record_.t_s, options_.rk4_substeps,
          [&](size_t i, const Eigen::Vector4d& q, const Eigen::Matrix4d& s) {
            minus_s = -s;
            qr.addBlock(minus_s, record_.q[i] - q);
          });
      if (!ok) break;
      const Eigen::MatrixXd& r_aug = qr.rAug();
      q0 -= r_aug.topLeftCorner(4, 4).colPivHouseholderQr().solve(r_aug.col(4).head(4));
    }
    Eigen::VectorXd r0 = Eigen::VectorXd::Zero(4 * n);
    std::vector<Eigen::Vector4d> traj;
    // A Gauss-Newton step that left the region where the trajectory exists falls back to the
    // start; a model whose trajectory cannot be integrated over the record even from there has no
    // output-error residuals: nothing (the caller says the adequacy cannot be shown), never zeros
    // that would pass every test.
    bool ok = integrateSlowTrajectory(model, z, q0, record_.t_s, options_.rk4_substeps, &traj) &&
              traj.size() == n;
    if (!ok)
      ok = integrateSlowTrajectory(model, z, start, record_.t_s, options_.rk4_substeps, &traj) &&
           traj.size() == n;
    if (!ok) return {};
    for (size_t i = 0; i < n; ++i) r0.segment<4>(4 * i) = record_.q[i] - traj[i];
    std::vector<double> t(n);
    for (size_t i = 0; i < n; ++i) t[i] = record_.t_s[i] - record_.t_s.front();
    // Radial and tangential parts along the MODEL's state: projected on the measured q, the
    // radial part e.q/|q| = (e.q_model + |e|^2)/|q| has the mean 3 sigma^2/|q|, a smooth trend as
    // the decay lowers |q| that the low-frequency test finds in long records.
    return blockResiduals(r0, traj, t, {});
  }

 private:
  /// LS start, then the output-error (trajectory) fit: the equation-error LS of (2.8) is biased
  /// by the noisy q inside D-bar (errors in variables) and its residuals are correlated
  /// (docs/paper.md items 10, 15), which makes clean data look like a significant xi; the
  /// output-error residuals are the measurement noise itself, so the Wald test on its covariance is
  /// honest. The equation residuals (for the signature) are those of (2.8) at the refined z; a
  /// refined fit does not keep them (4 doubles a sample each): blocks() makes them when asked.
  NestedFit fitOn(const SlowRecord& record, const std::vector<std::string>& extensions,
                  const std::map<std::string, double>& ceres_start = {},
                  const Eigen::VectorXd& ceres_start_state = Eigen::VectorXd()) const {
    PipelineOptions p;
    p.method = Method::kCeres;
    p.identification = options_.identification;
    p.identification.model = ResonatorModel(extensions, ExperimentMode::kFreeDecay).spec();
    p.ceres = options_.ceres;
    p.ceres.rk4_substeps = options_.rk4_substeps;
    // A failed refinement keeps the LS answer (honest sandwich intervals) and says why.
    p.on_ceres_failure = CeresFailure::kKeepStart;
    p.ceres_start = ceres_start;
    p.ceres_start_state = ceres_start_state;
    NestedFit f;
    f.extensions = extensions;
    // Covariance deferred: most refined fits are only ranked (NestedFit::finish).
    DeferredEstimate d = identifyDeferred(record, p);
    f.estimate = std::move(d.estimate);
    f.finish = std::move(d.finish);
    f.model = f.estimate.model;
    const ResonatorModel model(extensions, ExperimentMode::kFreeDecay);
    f.sigma = f.estimate.sigma;
    if (f.estimate.method != methodName(Method::kCeres)) {
      f.residuals = equationResidualsStreamed(model, f.estimate.values, record);
      f.n_equations = static_cast<long>(f.residuals.size());
      f.rss = f.residuals.squaredNorm();
      return f;
    }
    f.n_equations = f.estimate.n_equations;
    f.rss = f.sigma * f.sigma * std::max(1, f.estimate.dof);
    return f;
  }

  static bool strictSubset(const std::vector<std::string>& a, const std::vector<std::string>& b) {
    if (a.size() >= b.size()) return false;
    for (const auto& x : a)
      if (std::find(b.begin(), b.end(), x) == b.end()) return false;
    return true;
  }

  /// y - D-bar z of (2.8) block by block (the stacked D is never formed).
  Eigen::VectorXd equationResidualsStreamed(const ResonatorModel& model, const Eigen::VectorXd& z,
                                            const SlowRecord& record) const {
    Eigen::VectorXd r(4 * static_cast<Eigen::Index>(record.size() - 2));
    Eigen::Index i = 0;
    forEachFreeDecayBlock(
        model, record, options_.identification.uniform_time_tolerance,
        [&](const RegressionBlock& b) { r.segment<4>(4 * i++) = b.y - *b.d * z; });
    r.conservativeResize(4 * i);
    return r;
  }
  Eigen::VectorXd equationResidualsStreamed(const ResonatorModel& model,
                                            const Eigen::VectorXd& z) const {
    return equationResidualsStreamed(model, z, record_);
  }

  SlowRecord record_;
  NestedFitterOptions options_;
  mutable EquationErrorFactor factor_;
  mutable std::vector<std::vector<std::string>> fitted_cheap_;
};

class ForcedFitter : public NestedModelFitter {
 public:
  ForcedFitter(const SweepRecord& record, const NestedFitterOptions& options)
      : record_(record), options_(options) {
    throwIfInvalid("invalid explain fitting options", options.validate());
    omega_ = options.identification.omega_rad_s > 0 ? options.identification.omega_rad_s
                                                    : record.omega_rad_s;
    if (!(omega_ > 0.0))
      throw InputError("forced sweep" + (record.source.empty() ? "" : " " + record.source) +
                       ": natural frequency omega unknown (give --omega or '# omega:')");
    rho_ = noiseRhoAlongSweep();
  }

  NestedFit fit(const std::vector<std::string>& extensions) const override {
    return fitOn(record_, extensions);
  }

  double holdoutRms(const std::vector<std::string>& extensions) const override {
    double ss = 0.0;
    long count = 0;
    for (int fold = 0; fold < 2; ++fold) {
      const SweepRecord train = subset(fold), test = subset(1 - fold);
      const NestedFit f = fitEquationsOn(train, extensions);
      IdentificationOptions o = optionsFor(extensions, f);
      const StackedSystem sys = buildForcedSystem({test}, o);
      ss += equationResiduals(sys, linearPart(f)).squaredNorm();
      count += static_cast<long>(sys.y.size());
    }
    return std::sqrt(ss / std::max<long>(1, count));
  }

  std::string holdoutDescription() const override {
    return "two-fold interleaved hold-out: fit the even (odd) sweep points, RMS of the equation "
           "residuals (3.4) of the odd (even) ones";
  }

  std::vector<BlockResidual> blocks(const NestedFit& fit) const override {
    std::vector<double> lambda(record_.size());
    for (size_t j = 0; j < record_.size(); ++j) lambda[j] = record_.omega0_rad_s[j] - omega_;
    return blockResiduals(fit.residuals, record_.q, record_.omega0_rad_s, lambda);
  }

  /// Output-error residuals to first order, r_j = A_j^{-1} F(q_j) (sweep_noise_model.h): the
  /// equation residual's scale grows with the detuning; r is in amplitude units at every point.
  /// Points at a fold of the response (A_j singular) are left out. Radial and tangential parts are
  /// taken along the model's point q_j - r_j: along the measured q_j the radial part of the noise
  /// has the mean 3 sigma^2 / |q_j|, large on the quiet wings, and made sign runs there.
  std::vector<BlockResidual> adequacyResiduals(const NestedFit& fit) const override {
    return linearize(fit).blocks;
  }

 private:
  /// A_j = dF/dq (stationary_solver.h) and the linearized output error at the measured points.
  struct Linearized {
    std::vector<size_t> index;          ///< sweep point of each entry (folds left out)
    std::vector<Eigen::Matrix4d> a;     ///< A_j
    std::vector<BlockResidual> blocks;  ///< r_j = A_j^{-1} F(q_j) as residual blocks
  };

  double knownOrFittedMu(const NestedFit& fit) const {
    return ResonatorModel(fit.extensions, ExperimentMode::kForced).estimatesMu()
               ? fit.estimate.parameters.at(ResonatorModel::muName()).value
               : options_.identification.mu;
  }

  Linearized linearize(const NestedFit& fit) const {
    const ResonatorModel model =
        ResonatorModel(fit.extensions, ExperimentMode::kForced).linearPart();
    const Eigen::VectorXd z = fit.scored_values.size() ? fit.scored_values : linearPart(fit);
    const SlowContext ctx{0.0, knownOrFittedMu(fit)};
    Linearized out;
    Eigen::VectorXd r(4 * record_.size());
    std::vector<Eigen::Vector4d> q;
    std::vector<double> abscissa, lambda;
    long k = 0;
    for (size_t j = 0; j < record_.size(); ++j) {
      const double rate = detuningRate(omega_, record_.omega0_rad_s[j]);
      const Eigen::Matrix4d a = stationaryJacobian(model, record_.q[j], ctx, z, rate);
      const Eigen::JacobiSVD<Eigen::Matrix4d> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
      const auto& sv = svd.singularValues();
      if (!(sv(3) > 1e-9 * sv(0))) continue;  // a fold: no linearization
      const Eigen::Vector4d dq = svd.solve(stationaryResidual(model, record_.q[j], ctx, z, rate));
      if (!dq.allFinite()) continue;
      r.segment<4>(4 * k++) = dq;
      out.index.push_back(j);
      out.a.push_back(a);
      q.push_back(record_.q[j] - dq);  // the model's point q_j - r_j, see adequacyResiduals
      abscissa.push_back(record_.omega0_rad_s[j]);
      lambda.push_back(record_.omega0_rad_s[j] - omega_);
    }
    out.blocks = blockResiduals(r.head(4 * k), q, abscissa, lambda);
    return out;
  }

  /// The linear (in z) part's options: the base spec and the fitted mu when mu is estimated.
  IdentificationOptions optionsFor(const std::vector<std::string>& ext, const NestedFit& f) const {
    IdentificationOptions o = options_.identification;
    o.omega_rad_s = omega_;
    const ResonatorModel model(ext, ExperimentMode::kForced);
    o.model = model.linearPart().spec();
    if (model.estimatesMu()) o.mu = f.estimate.parameters.at(ResonatorModel::muName()).value;
    return o;
  }

  /// z of the linear part (without mu) in the base model's column order.
  static Eigen::VectorXd linearPart(const NestedFit& f) {
    Eigen::VectorXd z(f.estimate.values.size());
    int k = 0;
    for (size_t i = 0; i < f.estimate.names.size(); ++i)
      if (f.estimate.names[i] != ResonatorModel::muName()) z[k++] = f.estimate.values[i];
    return z.head(k);
  }

  /// The residual sum that ranks subsets, in output-error units: the feasible GLS of (3.4) with
  /// the block of point j weighted by W_j = A_j^-1 (A_j = dF/dq at the current fit), i.e.
  /// min_z sum_j |A_j^-1 F_j(z)|^2, the linearized output error of adequacyResiduals; two passes.
  /// The equation residuals' scale grows with the detuning, so their plain sum is ruled by the
  /// wings while the effects live near resonance; under white noise on q the weighted sum is
  /// the likelihood's. Singular values of A_j are floored at 1e-2 of the largest (folds).
  /// sigma, residuals and the estimate stay those of the equation-error fit.
  void scoreInOutputErrorUnits(const SweepRecord& record, const IdentificationOptions& o,
                               NestedFit* f) const {
    const StackedSystem sys = buildForcedSystem({record}, o);
    const ResonatorModel model(o.model, ExperimentMode::kForced);
    const SlowContext ctx{0.0, o.mu};
    Eigen::VectorXd z = linearPart(*f);
    Eigen::MatrixXd dw(sys.d.rows(), sys.d.cols());
    Eigen::VectorXd yw(sys.y.size());
    const auto weigh = [&]() {
      for (size_t j = 0; j < record.size(); ++j) {
        const double rate = detuningRate(omega_, record.omega0_rad_s[j]);
        const Eigen::Matrix4d a = stationaryJacobian(model, record.q[j], ctx, z, rate);
        const Eigen::JacobiSVD<Eigen::Matrix4d> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
        const Eigen::Vector4d sv = svd.singularValues().cwiseMax(1e-2 * svd.singularValues()(0));
        const Eigen::Matrix4d w =
            svd.matrixV() * sv.cwiseInverse().asDiagonal() * svd.matrixU().transpose();
        const long i = 4 * static_cast<long>(j);
        dw.middleRows(i, 4) = w * sys.d.middleRows(i, 4);
        yw.segment<4>(i) = w * sys.y.segment<4>(i);
      }
    };
    // AR(1) along the sweep (rho_): whiten the weighted rows, x_j - rho x_{j-1} (Prais-Winsten).
    const auto whiten = [&]() {
      if (!(rho_ > 0.0)) return;
      for (long j = static_cast<long>(record.size()) - 1; j >= 1; --j) {
        dw.middleRows(4 * j, 4) -= rho_ * dw.middleRows(4 * (j - 1), 4);
        yw.segment<4>(4 * j) -= rho_ * yw.segment<4>(4 * (j - 1));
      }
      dw.topRows(4) *= std::sqrt(1.0 - rho_ * rho_);
      yw.head<4>() *= std::sqrt(1.0 - rho_ * rho_);
    };
    for (int pass = 0; pass < 2; ++pass) {
      weigh();
      whiten();
      if (!dw.allFinite() || !yw.allFinite()) return;  // keep the equation-error sum
      const Eigen::VectorXd norms = dw.colwise().norm().transpose().cwiseMax(1e-300);
      const Eigen::MatrixXd scaled = dw * norms.cwiseInverse().asDiagonal();
      const Eigen::VectorXd next = scaled.colPivHouseholderQr().solve(yw).cwiseQuotient(norms);
      if (!next.allFinite()) return;
      z = next;
    }
    weigh();
    whiten();
    const Eigen::VectorXd r = yw - dw * z;
    const double rss = r.squaredNorm();
    if (std::isfinite(rss) && rss > 0.0) {
      f->rss = rss;
      f->n_equations = static_cast<long>(yw.size());
      f->scored_residuals = r;
      f->scored_values = z;
    }
  }

  NestedFit fitOn(const SweepRecord& record, const std::vector<std::string>& extensions) const {
    NestedFit f = fitEquationsOn(record, extensions);
    IdentificationOptions o = optionsFor(extensions, f);
    scoreInOutputErrorUnits(record, o, &f);
    return f;
  }

  NestedFit fitEquationsOn(const SweepRecord& record,
                           const std::vector<std::string>& extensions) const {
    const ResonatorModel model(extensions, ExperimentMode::kForced);
    IdentificationOptions o = options_.identification;
    o.omega_rad_s = omega_;
    o.model = model.linearPart().spec();
    if (!model.estimatesMu()) return fitRecord(record, o, extensions);
    // mu multiplies u~ bilinearly (3.2): the pipeline estimates it by output error, then z is
    // refitted by LS at that mu so that sigma and the residuals stay in equation units.
    PipelineOptions p;
    p.method = Method::kCeres;
    p.identification = o;
    p.identification.model = model.spec();
    p.ceres = options_.ceres;
    const Estimate ceres = identify(record, p);
    o.mu = ceres.parameters.at(ResonatorModel::muName()).value;
    NestedFit refit = fitRecord(record, o, extensions);
    refit.estimate = ceres;
    refit.model = model.spec();
    return refit;
  }

  SweepRecord subset(int parity) const {
    SweepRecord s;
    s.omega_rad_s = record_.omega_rad_s;
    s.metadata = record_.metadata;
    s.source = record_.source;
    for (size_t j = parity; j < record_.size(); j += 2) {
      s.omega0_rad_s.push_back(record_.omega0_rad_s[j]);
      s.q.push_back(record_.q[j]);
    }
    return s;
  }

  /// rho of the AR(1) along the sweep (sweep_noise_ar1.h) from the linearized output errors of
  /// the whole library's fit (least misfit; the linear model's if that fit fails): one noise
  /// model for every subset, so their criteria are comparable.
  double noiseRhoAlongSweep() const {
    std::vector<std::string> library;
    for (const auto& c : candidateExtensions(ExperimentMode::kForced)) library.push_back(c.name);
    for (const auto& ext : {library, std::vector<std::string>{}}) {
      try {
        return noiseModelAlongSweep(linearize(fitEquationsOn(record_, ext)).blocks).rho1;
      } catch (const std::exception&) {
        continue;  // the selection reports a failing fit itself
      }
    }
    return 0.0;
  }

  SweepRecord record_;
  NestedFitterOptions options_;
  double omega_ = 0.0;
  double rho_ = 0.0;
};

}  // namespace

std::unique_ptr<NestedModelFitter> makeFreeDecayFitter(const SlowRecord& record,
                                                       const NestedFitterOptions& options) {
  return std::make_unique<FreeDecayFitter>(record, options);
}

std::unique_ptr<NestedModelFitter> makeForcedFitter(const SweepRecord& record,
                                                    const NestedFitterOptions& options) {
  return std::make_unique<ForcedFitter>(record, options);
}

}  // namespace cvg_bench

// Streaming block RLS (see streaming_free_decay_rls.h).
#include "cvg_bench/ros/streaming_free_decay_rls.h"

#include <algorithm>
#include <cmath>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/free_decay_regression.h"
#include "cvg_bench/core/estimate/uncertainty/derived_uncertainty.h"
#include "cvg_bench/core/estimate/uncertainty/student_t.h"

namespace cvg_bench {

StreamingFreeDecayRls::StreamingFreeDecayRls(const IdentificationOptions& options)
    : options_(options),
      model_(options.model, ExperimentMode::kFreeDecay),
      qr_(model_.numParameters()),
      rls_(model_.numParameters(), options.rls_forgetting) {
  for (const auto& term : model_.terms())
    if (term->isTimeVarying())
      throw InputError("the recursive identifier cannot take " + term->name() +
                       " (a time-varying term); use ls");
  const int k = model_.numParameters();
  init_blocks_ = options.rls_init_blocks > 0 ? options.rls_init_blocks : std::max(2 * k, 8);
}

void StreamingFreeDecayRls::reset() {
  qr_ = IncrementalQr(model_.numParameters());
  rls_ = BlockRecursiveLeastSquares(model_.numParameters(), options_.rls_forgetting);
  last3_ = SlowRecord();
  blocks_ = 0;
}

void StreamingFreeDecayRls::add(double t_s, const Eigen::Vector4d& q) {
  if (!std::isfinite(t_s) || !q.allFinite()) throw InputError("non-finite slow state");
  if (!last3_.t_s.empty() && !(t_s > last3_.t_s.back()))
    throw InputError("slow states must arrive with increasing stamps");
  last3_.t_s.push_back(t_s);
  last3_.q.push_back(q);
  if (last3_.size() > 3) {
    last3_.t_s.erase(last3_.t_s.begin());
    last3_.q.erase(last3_.q.begin());
  }
  if (last3_.size() < 3) return;
  // The block of the centre sample; its time-varying context is unused (no cm_rate).
  const bool constant = last3_.q[0] == last3_.q[1] && last3_.q[1] == last3_.q[2];
  if (constant) return;
  forEachFreeDecayBlock(model_, last3_, options_.uniform_time_tolerance,
                        [&](const RegressionBlock& b) {
                          ++blocks_;
                          if (rls_.initialized()) {
                            rls_.update(*b.d, b.y);
                            return;
                          }
                          qr_.addBlock(*b.d, b.y);
                          if (blocks_ < init_blocks_) return;
                          try {
                            rls_.initialize(qr_.rAug(), qr_.numRows());
                          } catch (const AnalysisError&) {
                            // Not yet determined (e.g. a standing wave so far): keep accumulating.
                          }
                        });
}

Estimate StreamingFreeDecayRls::estimate(double omega_rad_s) const {
  if (!rls_.initialized())
    throw AnalysisError("the recursive estimate is not initialised yet (" +
                        std::to_string(blocks_) + " blocks; it needs " +
                        std::to_string(init_blocks_) + " that determine every parameter)");
  const int k = model_.numParameters();
  Estimate e;
  e.mode = ExperimentMode::kFreeDecay;
  e.model = model_.spec();
  e.method = "rls";
  e.omega_rad_s = omega_rad_s;
  e.n_equations = static_cast<int>(rls_.numEquations());
  e.n_params = k;
  e.rank = k;
  e.dof = e.n_equations - k;
  e.sigma = rls_.sigma();
  e.confidence = options_.confidence;
  e.names = model_.parameterNames();
  e.values = rls_.z();
  e.covariance = e.sigma * e.sigma * Eigen::MatrixXd(rls_.p());
  e.interval_method = "paper (2.11), recursive (2.12)";
  e.interval_dof = e.dof;
  const double s_p = studentQuantile(options_.confidence, std::max(e.dof, 1));
  for (int i = 0; i < k; ++i) {
    ParameterEstimate p;
    p.value = e.values[i];
    p.std_error = std::sqrt(std::max(e.covariance(i, i), 0.0));
    p.ci_low = p.value - s_p * p.std_error;
    p.ci_high = p.value + s_p * p.std_error;
    e.parameters[e.names[i]] = p;
  }
  e.covariance_paper = e.covariance;
  e.parameters_paper = e.parameters;
  if (omega_rad_s > 0.0 && options_.derive_quantities) {
    try {
      e.derived = deriveQuantitiesWithIntervals(uncertainParameters(e), omega_rad_s,
                                                options_.angular_gain_k);
    } catch (const InputError& err) {
      e.notes.push_back(std::string("derived quantities unavailable: ") + err.what());
    }
  }
  e.notes.push_back("block recursive least squares (2.12) over " + std::to_string(blocks_) +
                    " blocks");
  return e;
}

}  // namespace cvg_bench

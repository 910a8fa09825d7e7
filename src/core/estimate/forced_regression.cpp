#include "cvg_bench/core/estimate/forced_regression.h"

#include <cmath>
#include <string>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {

void validateSweepRecord(const SweepRecord& record) {
  const std::string src = record.source.empty() ? "sweep record" : record.source;
  if (record.q.size() != record.omega0_rad_s.size())
    throw InputError(src + ": " + std::to_string(record.omega0_rad_s.size()) +
                     " drive frequencies but " + std::to_string(record.q.size()) + " points");
  if (static_cast<int>(record.size()) < kMinSweepPoints)
    throw InputError(src + ": a forced sweep needs at least " + std::to_string(kMinSweepPoints) +
                     " stationary points (16 equations of (3.5)), got " +
                     std::to_string(record.size()));
  // The message is built only for the offending point (10^6-point sweeps are validated per call).
  for (size_t j = 0; j < record.size(); ++j) {
    if (!(std::isfinite(record.omega0_rad_s[j]) && record.omega0_rad_s[j] > 0.0))
      throw InputError(src + ": point " + std::to_string(j) + ": omega0 must be finite and > 0");
    if (!record.q[j].allFinite())
      throw InputError(src + ": point " + std::to_string(j) + ": q is not finite");
  }
}

void forEachForcedBlock(const ResonatorModel& model, const SweepRecord& record, double omega_rad_s,
                        double mu, const RegressionVisitor& visit) {
  validateSweepRecord(record);
  forEachValidatedForcedBlock(model, record, omega_rad_s, mu, visit);
}

void forEachValidatedForcedBlock(const ResonatorModel& model, const SweepRecord& record,
                                 double omega_rad_s, double mu, const RegressionVisitor& visit) {
  requirePositive(omega_rad_s, "omega (natural frequency)");
  requireFinite(mu, "mu");
  RegressionBlockMatrix d(4, model.numParameters());
  SlowContext ctx;
  ctx.mu = mu;
  RegressionBlock b;
  b.d = &d;
  for (size_t j = 0; j < record.size(); ++j) {
    model.regressor(record.q[j], ctx, d);
    b.y = detuningRate(omega_rad_s, record.omega0_rad_s[j]) * detuningDirection(record.q[j]);
    b.q = record.q[j];
    b.abscissa = record.omega0_rad_s[j];
    b.index = static_cast<long>(j);
    visit(b);
  }
}

}  // namespace cvg_bench

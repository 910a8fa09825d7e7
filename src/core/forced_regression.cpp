#include "cvg_bench/core/forced_regression.h"

#include <cmath>
#include <string>

#include "cvg_bench/core/errors.h"

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
  for (size_t j = 0; j < record.size(); ++j) {
    const std::string at = src + ": point " + std::to_string(j);
    if (!(std::isfinite(record.omega0_rad_s[j]) && record.omega0_rad_s[j] > 0.0))
      throw InputError(at + ": omega0 must be finite and > 0");
    if (!record.q[j].allFinite()) throw InputError(at + ": q is not finite");
  }
}

void forEachForcedBlock(const ResonatorModel& model, const SweepRecord& record, double omega_rad_s,
                        double mu, const RegressionVisitor& visit) {
  validateSweepRecord(record);
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

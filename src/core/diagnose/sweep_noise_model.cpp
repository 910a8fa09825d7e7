#include "cvg_bench/core/diagnose/sweep_noise_model.h"

namespace cvg_bench {

SweepNoiseOptions adequacySweepNoiseOptions() {
  SweepNoiseOptions o;
  o.upper_standard_errors = 1.0;
  return o;
}

ResidualNoiseModel noiseModelAlongSweep(const std::vector<BlockResidual>& blocks,
                                        const SweepNoiseOptions& options) {
  std::vector<Eigen::Vector4d> r;
  std::vector<double> amp2, abscissa;
  for (const auto& b : blocks) {
    r.push_back(b.e);
    amp2.push_back(b.amp2);
    abscissa.push_back(b.abscissa);
  }
  const SweepAr1 a = sweepNoiseAr1(r, amp2, abscissa, options);
  ResidualNoiseModel m;
  m.description = a.description;
  if (a.rho > 0.0) {
    m.ar = {a.rho};
    m.rho1 = a.rho;
  }
  return m;
}

}  // namespace cvg_bench

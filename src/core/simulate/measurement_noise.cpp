#include "cvg_bench/core/simulate/measurement_noise.h"

#include <cmath>
#include <string>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace {
void requireNoiseStd(double std) {
  if (!std::isfinite(std) || std < 0.0)
    throw InputError("noise standard deviation must be finite and >= 0, got " +
                     std::to_string(std));
}
}  // namespace

double MeasurementNoise::draw(double std) {
  requireNoiseStd(std);
  return std * normal_(engine_);
}

void MeasurementNoise::addTo(SlowRecord& record, double std) {
  requireNoiseStd(std);
  if (std == 0.0) return;
  for (auto& q : record.q)
    for (int i = 0; i < 4; ++i) q[i] += std * normal_(engine_);
}

void MeasurementNoise::addTo(SweepRecord& record, double std) {
  requireNoiseStd(std);
  if (std == 0.0) return;
  for (auto& q : record.q)
    for (int i = 0; i < 4; ++i) q[i] += std * normal_(engine_);
}

void MeasurementNoise::addTo(RawRecord& record, double std) {
  requireNoiseStd(std);
  if (std == 0.0) return;
  for (size_t k = 0; k < record.size(); ++k) {
    record.f[k] += std * normal_(engine_);
    record.g[k] += std * normal_(engine_);
  }
}

}  // namespace cvg_bench

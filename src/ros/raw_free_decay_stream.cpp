// Raw free decay piece by piece (see raw_free_decay_stream.h).
#include "cvg_bench/ros/raw_free_decay_stream.h"

#include <algorithm>
#include <cmath>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/simulate/experiment_runner.h"

namespace cvg_bench {

RawFreeDecayStream::RawFreeDecayStream(const ResonatorPreset& preset, double duration_s,
                                       std::uint64_t seed, const OrbitElements& start)
    : noise_(seed),
      noise_std_(preset.noise_fg_std),
      rate_hz_(preset.raw_sample_rate_hz),
      omega_rad_s_(preset.omega_rad_s) {
  if (!(std::isfinite(duration_s) && duration_s > 0.0))
    throw InputError("raw free decay: duration_s must be > 0");
  Eigen::Vector4d q0;
  if (start.r == 0.0) {
    q0 = ExperimentRunner(preset).freeDecayInitialState();
  } else {
    if (!(std::isfinite(start.r) && start.r > 0.0 && std::isfinite(start.k) &&
          std::abs(start.k) <= start.r && std::isfinite(start.theta) && std::isfinite(start.chi)))
      throw InputError("free-decay start: need r > 0, |k| <= r, finite theta and chi");
    q0 = slowFromOrbit(start);
  }
  model_.reset(new ResonatorModel(preset.truthModelSpec(ExperimentMode::kFreeDecay),
                                  ExperimentMode::kFreeDecay));
  FullEquationSimulatorOptions fo;
  fo.steps_per_period = preset.steps_per_period;
  sim_.reset(new FullEquationSimulator(*model_, preset.truthParameters(*model_), omega_rad_s_,
                                       omega_rad_s_, 0.0, {}, fo));
  sim_->reset(q0, 0.0);
  // Same sample count as ExperimentRunner::freeDecayRaw.
  total_ = static_cast<size_t>(std::floor(duration_s * rate_hz_)) + 1;
}

RawRecord RawFreeDecayStream::next(size_t max_samples) {
  RawRecord piece;
  piece.omega_rad_s = omega_rad_s_;
  const size_t n = std::min(max_samples, total_ - produced_);
  if (n == 0) return piece;
  sim_->sampleRaw(rate_hz_, n, piece);
  noise_.addTo(piece, noise_std_);
  produced_ += n;
  return piece;
}

}  // namespace cvg_bench

// A raw free-decay record produced piece by piece at bounded memory: the full equations
// (FullEquationSimulator, (2.3)) advanced only as far as the samples asked for, with the seeded
// measurement noise drawn in the same order as for the whole record (f then g per sample), so the
// pieces joined equal ExperimentRunner::freeDecayRaw + MeasurementNoise up to rounding of t.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "cvg_bench/core/io/records.h"
#include "cvg_bench/core/model/orbit_elements.h"
#include "cvg_bench/core/model/resonator_preset.h"
#include "cvg_bench/core/simulate/full_equation_simulator.h"
#include "cvg_bench/core/simulate/measurement_noise.h"

namespace cvg_bench {

class RawFreeDecayStream {
 public:
  /// duration_s > 0; start.r = 0: from the preset's drive
  /// (ExperimentRunner::freeDecayInitialState), else from these orbit elements (5.2). InputError on
  /// bad input.
  RawFreeDecayStream(const ResonatorPreset& preset, double duration_s, std::uint64_t seed,
                     const OrbitElements& start);
  /// The next at most max_samples samples (t_s from the experiment's start); empty at the end.
  RawRecord next(size_t max_samples);
  size_t total() const { return total_; }
  size_t produced() const { return produced_; }
  double sampleRateHz() const { return rate_hz_; }
  /// Simulated time of sample i [s].
  double timeOf(size_t i) const { return static_cast<double>(i) / rate_hz_; }

 private:
  std::unique_ptr<ResonatorModel> model_;
  std::unique_ptr<FullEquationSimulator> sim_;
  MeasurementNoise noise_;
  double noise_std_ = 0.0, rate_hz_ = 0.0, omega_rad_s_ = 0.0;
  size_t total_ = 0, produced_ = 0;
};

}  // namespace cvg_bench

// Seeded Gaussian measurement noise for simulated records: std::mt19937_64 +
// std::normal_distribution, so the same seed gives bit-identical records (with the same standard
// library). Noise is white and independent per sample and per channel: on q1, p1, q2, p2 of slow
// and sweep records, on f, g of raw records.
#pragma once

#include <cstdint>
#include <random>

#include "cvg_bench/core/io/records.h"

namespace cvg_bench {

class MeasurementNoise {
 public:
  explicit MeasurementNoise(std::uint64_t seed) : engine_(seed) {}
  /// Adds N(0, std^2) to every q component; std [amplitude units] >= 0 (0: unchanged).
  void addTo(SlowRecord& record, double std);
  void addTo(SweepRecord& record, double std);
  /// Adds N(0, std^2) to every f and g sample.
  void addTo(RawRecord& record, double std);
  /// One N(0, std^2) draw.
  double draw(double std);

 private:
  std::mt19937_64 engine_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace cvg_bench

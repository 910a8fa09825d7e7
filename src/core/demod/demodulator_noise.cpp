#include "cvg_bench/core/demod/demodulator_noise.h"

#include <cmath>
#include <sstream>
#include <string>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/demod/fir_lowpass.h"

namespace cvg_bench {

std::vector<double> outputNoiseCorrelation(const std::vector<FilterStage>& stages, double cutoff) {
  // Composite impulse response at the input rate.
  std::vector<double> h{1.0};
  long step = 1;  // decimation of the stages already folded in
  for (const FilterStage& s : stages) {
    const std::vector<double> taps = designKaiserLowpass(s.spec);
    std::vector<double> next(h.size() + (taps.size() - 1) * step, 0.0);
    for (size_t i = 0; i < h.size(); ++i)
      for (size_t k = 0; k < taps.size(); ++k) next[i + k * step] += h[i] * taps[k];
    h.swap(next);
    step *= s.decimation;
  }
  double energy = 0.0;
  for (double v : h) energy += v * v;
  std::vector<double> rho;
  if (!(energy > 0.0)) return rho;
  for (long lag = step; lag < static_cast<long>(h.size()); lag += step) {
    double sum = 0.0;
    for (size_t k = 0; k + lag < h.size(); ++k) sum += h[k] * h[k + lag];
    rho.push_back(sum / energy);
  }
  while (!rho.empty() && std::fabs(rho.back()) < cutoff) rho.pop_back();
  return rho;
}

std::vector<double> noiseCorrelationFromMetadata(const RecordMetadata& metadata) {
  std::vector<double> rho;
  const auto it = metadata.find(kNoiseCorrelationKey);
  if (it == metadata.end()) return rho;
  std::istringstream in(it->second);
  std::string word;
  while (in >> word) {
    double v = 0.0;
    try {
      size_t used = 0;
      v = std::stod(word, &used);
      if (used != word.size()) throw std::invalid_argument(word);
    } catch (const std::exception&) {
      throw InputError(std::string(kNoiseCorrelationKey) + ": '" + word + "' is not a number");
    }
    if (!(std::isfinite(v) && std::fabs(v) < 1.0))
      throw InputError(std::string(kNoiseCorrelationKey) + ": " + word +
                       " is not a correlation in (-1, 1)");
    rho.push_back(v);
  }
  return rho;
}

}  // namespace cvg_bench

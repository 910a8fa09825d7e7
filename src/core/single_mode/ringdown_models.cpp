#include "cvg_bench/core/single_mode/ringdown_models.h"

#include "cvg_bench/core/single_mode/ringdown_laws.h"

namespace cvg_bench {

std::vector<std::string> ringdownParameterNames(const std::string& model) {
  return ringdownLaw(model).parameters;
}

const std::vector<std::string>& ringdownExtensionNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const RingdownLaw& law : ringdownLaws())
      if (law.is_extension) out.push_back(law.name);
    return out;
  }();
  return names;
}

double ringdownLogAmplitude(const std::string& model, const Eigen::VectorXd& p, double t,
                            double floor_rel) {
  return ringdownLaw(model).logAmplitude(p, t, floor_rel);
}

}  // namespace cvg_bench

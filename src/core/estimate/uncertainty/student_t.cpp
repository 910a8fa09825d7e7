#include "cvg_bench/core/estimate/uncertainty/student_t.h"

#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <string>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {

double studentQuantile(double confidence, int dof) {
  if (!(confidence > 0.0 && confidence < 1.0))
    throw InputError("confidence P0 must lie in (0, 1), got " + std::to_string(confidence));
  const double p = 0.5 * (1.0 + confidence);
  if (dof <= 0) return boost::math::quantile(boost::math::normal_distribution<double>(), p);
  return boost::math::quantile(boost::math::students_t_distribution<double>(dof), p);
}

}  // namespace cvg_bench

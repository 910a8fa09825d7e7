// theta'(theta) measured from a whole-angle run (drift_measurement.h) against the truth of the
// simulated resonator: the measured intervals cover the true drift (issue #26).
#include "cvg_bench/core/diagnose/drift_measurement.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "cvg_bench/core/model/orbit_elements.h"
#include "cvg_bench/core/model/orbit_rates_chain_rule.h"
#include "cvg_bench/core/model/resonator_preset.h"
#include "cvg_bench/core/simulate/whole_angle_simulator.h"

namespace cvg_bench {
namespace {

struct Coverage {
  int inside = 0, bins = 0, one_pass = 0, one_pass_inside = 0;
};

/// Runs of the preset held at (0.5, k0), seeds 1..n, measured against the truth's prediction
/// (no covariance: the prediction is a line, so the measured interval alone must cover it).
Coverage coverageOver(const std::string& preset_name, double k0, int n) {
  const ResonatorPreset preset = loadShippedPreset(preset_name);
  UncertainParameters truth;
  truth.values = preset.parameters;
  Coverage c;
  // The validation's run (validate_drift.py): walked at 4x the largest true drift over 1.5
  // periods of theta, so about half the bins are passed once.
  const ResonatorModel model = freeOscillationModelOf(truth.values);
  double peak = 0.0;
  for (double th : thetaGrid(36))
    peak = std::max(
        peak,
        std::fabs(
            orbitRatesOfModel(model, truth.values, OrbitElements{0.5, k0, th, 0.0}).theta_dot));
  for (int seed = 1; seed <= n; ++seed) {
    WholeAngleOptions o;
    o.k0 = k0;
    o.walk_rad_s = 4.0 * peak;
    o.duration_s = 1.5 * (M_PI / 2) / o.walk_rad_s;
    o.seed = static_cast<std::uint64_t>(seed);
    const SlowRecord run = simulateWholeAngle(preset, o);
    const double walk = std::stod(run.metadata.at("whole_angle_walk_rad_s"));
    const DriftComparison d = measureDrift(run, walk, truth);
    EXPECT_GE(d.pass_scatter_ratio, 1.0);
    EXPECT_GT(d.noise_dof, 100);
    for (const DriftBin& b : d.bins) {
      if (!b.measured_ok) continue;
      const bool in =
          b.measured.ci_low <= b.predicted.value && b.predicted.value <= b.measured.ci_high;
      c.bins += 1;
      c.inside += in;
      if (b.passes != 1) continue;
      c.one_pass += 1;
      c.one_pass_inside += in;
    }
  }
  return c;
}

// The run the drift validation found too confident (docs/validation_drift.md, k0 = 0.2 r0): a
// bin passed once had only its pass's own HAC interval (~10 samples), which covered the true
// drift in 76 of these 112 one-pass bins. The noise pooled over all passes covers it like the
// rest.
TEST(DriftMeasurement, IntervalsCoverTheTrueDriftAtQuadrature) {
  const Coverage c = coverageOver("quartz_cylinder", 0.1, 8);
  ASSERT_GT(c.one_pass, 20);
  EXPECT_GE(c.inside, static_cast<int>(0.88 * c.bins)) << c.inside << " of " << c.bins;
  EXPECT_GE(c.one_pass_inside, static_cast<int>(0.85 * c.one_pass))
      << c.one_pass_inside << " of " << c.one_pass;
}

TEST(DriftMeasurement, IntervalsCoverTheTrueDriftHeldAtZeroQuadrature) {
  const Coverage c = coverageOver("quartz_cylinder", 0.0, 8);
  ASSERT_GT(c.one_pass, 20);
  EXPECT_GE(c.inside, static_cast<int>(0.88 * c.bins)) << c.inside << " of " << c.bins;
}

}  // namespace
}  // namespace cvg_bench

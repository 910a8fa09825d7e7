#include "cvg_bench/core/simulate/whole_angle_simulator.h"

#include <array>
#include <cmath>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/number_text.h"
#include "cvg_bench/core/model/orbit_rates_chain_rule.h"
#include "cvg_bench/core/simulate/measurement_noise.h"

namespace cvg_bench {
namespace {

/// The default walk: 1.5 periods of theta over the run, and at least 4x the largest drift the
/// resonator has at (r0, k0) over theta: a slower walk lets the pattern lock where the drift
/// cancels it (the MEMS ring drifts ~35 deg/s, more than 1.5 periods over its 4 s default run).
double defaultWalk(const ResonatorModel& model, const ResonatorPreset& preset,
                   const WholeAngleOptions& o, double duration) {
  double peak = 0.0;
  for (int i = 0; i < 36; ++i) {
    const OrbitElements x{o.r0, o.k0, -M_PI / 4 + (M_PI / 2) * i / 36.0, 0.0};
    peak = std::max(peak, std::abs(orbitRatesOfModel(model, preset.parameters, x, 0.0).theta_dot));
  }
  return std::max(1.5 * (M_PI / 2.0) / duration, 4.0 * peak);
}

}  // namespace

namespace {}  // namespace

SlowRecord simulateWholeAngle(const ResonatorPreset& preset, const WholeAngleOptions& o) {
  requirePositive(o.r0, "whole-angle amplitude r0");
  requireFinite(o.k0, "whole-angle quadrature k0");
  if (!(std::abs(o.k0) < o.r0)) throw InputError("whole-angle run: |k0| must be below r0");
  const ResonatorModel model = freeOscillationModelOf(preset.parameters);
  // Ideal loops (g = 0) hold r and k exactly; a finite gain g leaves the model's r', k' acting
  // against g (r0 - r), g (k0 - k).
  const bool ideal = !(o.loop_rate_1_s > 0.0);
  const double g = ideal ? 0.0 : o.loop_rate_1_s;
  const double duration = o.duration_s > 0.0 ? o.duration_s : 20.0 * preset.decay_duration_s;
  const double rate = o.sample_rate_hz > 0.0 ? o.sample_rate_hz : preset.decay_sample_rate_hz;
  requirePositive(duration, "whole-angle duration");
  requirePositive(rate, "whole-angle sample rate");
  const double walk = o.walk_rad_s != 0.0 ? o.walk_rad_s : defaultWalk(model, preset, o, duration);
  requireFinite(walk, "whole-angle walk");
  const long n = static_cast<long>(std::floor(duration * rate)) + 1;
  if (n < 10 || n > 20000000)
    throw InputError("whole-angle run: 10 .. 2e7 samples, got " + std::to_string(n));
  const int sub = 4;  // RK4 steps per sample
  const double h = 1.0 / (rate * sub);
  // The run starts with r, k at the loops' set points.
  OrbitElements e{o.r0, o.k0, -M_PI / 4 + 1e-3, 0.0};
  auto deriv = [&](const OrbitElements& x, double t) {
    const OrbitRates m = orbitRatesOfModel(model, preset.parameters, x, t);
    if (ideal) return std::array<double, 4>{0.0, 0.0, m.theta_dot + walk, m.chi_dot};
    return std::array<double, 4>{m.r_dot + g * (o.r0 - x.r), m.k_dot + g * (o.k0 - x.k),
                                 m.theta_dot + walk, m.chi_dot};
  };
  auto add = [](const OrbitElements& x, const std::array<double, 4>& d, double s) {
    return OrbitElements{x.r + s * d[0], x.k + s * d[1], x.theta + s * d[2], x.chi + s * d[3]};
  };
  SlowRecord rec;
  rec.omega_rad_s = preset.omega_rad_s;
  double t = 0.0;
  for (long i = 0; i < n; ++i) {
    rec.t_s.push_back(t);
    rec.q.push_back(slowFromOrbit(e));
    for (int s = 0; s < sub; ++s) {
      const auto k1 = deriv(e, t), k2 = deriv(add(e, k1, h / 2), t + h / 2),
                 k3 = deriv(add(e, k2, h / 2), t + h / 2), k4 = deriv(add(e, k3, h), t + h);
      for (int c = 0; c < 4; ++c) {
        const double d = (k1[c] + 2 * k2[c] + 2 * k3[c] + k4[c]) / 6.0;
        if (c == 0) e.r += h * d;
        if (c == 1) e.k += h * d;
        if (c == 2) e.theta += h * d;
        if (c == 3) e.chi += h * d;
      }
      t += h;
    }
  }
  MeasurementNoise noise(o.seed);
  noise.addTo(rec, o.noise_std >= 0.0 ? o.noise_std : preset.noise_q_std);
  rec.metadata["omega"] = numberText(preset.omega_rad_s, 17);
  rec.metadata["mode"] = "free_decay";
  rec.metadata["experiment"] = "whole_angle";
  rec.metadata["whole_angle_r0"] = numberText(o.r0, 17);
  rec.metadata["whole_angle_k0"] = numberText(o.k0, 17);
  rec.metadata["whole_angle_loops"] =
      ideal ? "ideal (r and k held exactly)" : "proportional, gain " + numberText(g, 17) + " 1/s";
  rec.metadata["whole_angle_walk_rad_s"] = numberText(walk, 17);
  rec.metadata["preset"] = preset.name;
  rec.metadata["seed"] = std::to_string(o.seed);
  rec.metadata["truth_model"] = model.spec();
  for (const auto& kv : preset.parameters)
    rec.metadata["truth_" + kv.first] = numberText(kv.second, 17);
  return rec;
}

}  // namespace cvg_bench

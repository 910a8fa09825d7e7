// One-mode lock-in sweeps by time integration (response_simulator.h).
#include "cvg_bench/core/simulate/response_simulator.h"

#include <cmath>
#include <random>
#include <sstream>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {

ResponseRecord simulateResponse(const ResponseSimulatorOptions& o) {
  requirePositive(o.f0_hz, "f0_hz");
  requirePositive(o.q, "q");
  requirePositive(o.max_amplitude, "max_amplitude");
  if (o.levels < 1 || o.levels > 50) throw InputError("levels: 1 to 50");
  if (o.points_per_sweep < 8 || o.points_per_sweep > 5000)
    throw InputError("points per sweep: 8 to 5000");
  if (o.sweeps_per_level < 1 || o.sweeps_per_level > 20)
    throw InputError("sweeps per level: 1 to 20");
  if (!(o.correlation >= 0 && o.correlation < 1)) throw InputError("correlation: [0, 1)");
  const double two_pi = 2.0 * M_PI;
  const double w0 = o.f0_hz / o.q;
  const double k3 = o.backbone_hz_per_amp2 * 8.0 / 3.0 * two_pi * two_pi * o.f0_hz;
  const double c2 = 4.0 * o.width_growth_hz_per_amp2;
  const double tau = 1.0 / (M_PI * w0);
  const double u_max = o.max_amplitude * o.max_amplitude;
  const double shift = o.backbone_hz_per_amp2 * u_max;
  const double half = 0.5 * o.span_widths * w0 + 0.5 * std::abs(shift);
  const double centre = o.f0_hz + 0.5 * shift;
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);

  ResponseRecord rec;
  rec.has_time = true;
  std::ostringstream truth;
  truth.precision(12);
  truth << " generator: cvg_ident simulate --mode response (time integration + lock-in)\n";
  rec.comments = {" f0_hz: " + std::to_string(o.f0_hz), " width_hz: " + std::to_string(w0),
                  " Q: " + std::to_string(o.q)};
  {
    std::ostringstream a, b;
    a.precision(12);
    b.precision(12);
    a << " backbone_hz_per_amp2: " << o.backbone_hz_per_amp2;
    b << " width_growth_hz_per_amp2: " << o.width_growth_hz_per_amp2;
    rec.comments.push_back(a.str());
    rec.comments.push_back(b.str());
  }
  rec.comments.push_back(" response: " + responseKindName(o.kind) +
                         (o.conjugate ? " (y written with the other sign)" : ""));

  double x = 0.0, v = 0.0, phi = 0.0, t = 0.0;
  std::complex<double> noise_state(0.0, 0.0);
  const double innovation = o.noise * std::sqrt(1.0 - o.correlation * o.correlation);
  for (int level = 0; level < o.levels; ++level) {
    const double frac =
        o.levels == 1 ? 1.0
                      : std::pow(8.0, -static_cast<double>(o.levels - 1 - level) / (o.levels - 1));
    const double force_nominal = frac * o.max_amplitude * two_pi * two_pi * o.f0_hz * w0;
    double force = force_nominal;
    if (o.saturation_amplitude > 0) {
      const double fs = o.saturation_amplitude * two_pi * two_pi * o.f0_hz * w0;
      force = fs * std::tanh(force_nominal / fs);
    }
    for (int s = 0; s < o.sweeps_per_level; ++s) {
      const double f0 = o.f0_hz + o.f0_drift_hz * gauss(rng);
      const double om0 = two_pi * f0;
      const bool up = s % 2 == 0;
      for (int k = 0; k < o.points_per_sweep; ++k) {
        const double a =
            static_cast<double>(up ? k : o.points_per_sweep - 1 - k) / (o.points_per_sweep - 1);
        const double f = centre - half + 2.0 * half * a;
        const double dwell = o.dwell_time_constants * tau * (k == 0 ? 3.0 : 1.0);
        const int cycles = std::max(4, static_cast<int>(std::ceil(dwell * f)));
        const int avg_cycles =
            std::max(2, static_cast<int>(std::floor(std::min(tau, dwell / 2) * f)));
        const int steps_per_cycle = 64;  // RK4's numerical damping: Q_num ~ 2e7
        const double dt = 1.0 / (f * steps_per_cycle);
        auto accel = [&](double xx, double vv, double ph) {
          return force * std::cos(ph) - two_pi * (w0 + c2 * xx * xx) * vv - om0 * om0 * xx -
                 k3 * xx * xx * xx;
        };
        std::complex<double> acc(0.0, 0.0);
        const int n_steps = cycles * steps_per_cycle;
        const int avg_from = n_steps - avg_cycles * steps_per_cycle;
        const double dphi = two_pi * f * dt;
        for (int i = 0; i < n_steps; ++i) {
          const double k1x = v, k1v = accel(x, v, phi);
          const double k2x = v + 0.5 * dt * k1v,
                       k2v = accel(x + 0.5 * dt * k1x, k2x, phi + 0.5 * dphi);
          const double k3x = v + 0.5 * dt * k2v,
                       k3v = accel(x + 0.5 * dt * k2x, k3x, phi + 0.5 * dphi);
          const double k4x = v + dt * k3v, k4v = accel(x + dt * k3x, k4x, phi + dphi);
          x += dt / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
          v += dt / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
          phi += dphi;
          if (phi > two_pi) phi -= two_pi;
          if (i >= avg_from) {
            const double sig = o.kind == ResponseKind::kVelocity ? v / (two_pi * o.f0_hz) : x;
            acc += sig * std::exp(std::complex<double>(0.0, -phi));
          }
        }
        if (!std::isfinite(x) || !std::isfinite(v))
          throw AnalysisError(
              "the simulated oscillator diverged (a negative width at the "
              "amplitudes reached: w0 + g A^2 < 0)");
        t += n_steps * dt;
        std::complex<double> z = acc * (2.0 / (avg_cycles * steps_per_cycle));
        z += force_nominal / (o.max_amplitude * two_pi * two_pi * o.f0_hz * w0) *
             (o.background + o.background_slope_per_hz * (f - o.f0_hz));
        noise_state =
            o.correlation * noise_state + innovation * std::complex<double>(gauss(rng), gauss(rng));
        z += noise_state;
        if (o.conjugate) z = std::conj(z);
        rec.t_s.push_back(o.point_interval_s > 0 ? rec.size() * o.point_interval_s : t);
        rec.frequency_hz.push_back(f);
        rec.x.push_back(z.real());
        rec.y.push_back(z.imag());
        rec.drive.push_back(force_nominal / (two_pi * two_pi * o.f0_hz * w0 * o.max_amplitude));
      }
    }
  }
  return rec;
}

}  // namespace cvg_bench

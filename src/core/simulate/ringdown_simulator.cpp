#include "cvg_bench/core/simulate/ringdown_simulator.h"

#include <cmath>
#include <complex>
#include <random>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/io/ringdown_record.h"

namespace cvg_bench {

std::vector<std::string> RingdownSimulationOptions::validate() const {
  std::vector<std::string> p;
  if (!(frequency_hz > 0.0)) p.push_back("frequency_hz must be > 0");
  if (!(q > 0.0)) p.push_back("q must be > 0");
  if (!(amplitude > 0.0)) p.push_back("amplitude must be > 0");
  if (n_samples < 50) p.push_back("n_samples must be >= 50");
  if (!(noise_db >= 0.0)) p.push_back("noise_db must be >= 0 dB");
  if (!(noise_correlation >= 0.0 && noise_correlation <= 0.99))
    p.push_back("noise_correlation must be in [0, 0.99]");
  if (second_amplitude < 0.0 || two_stage_ratio < 0.0) p.push_back("amplitude ratios must be >= 0");
  if (q2 < 0.0 || q_fast < 0.0) p.push_back("q2 and q_fast must be >= 0");
  if (dropouts < 0) p.push_back("dropouts must be >= 0");
  if (!(detection_loss_db >= 0.0)) p.push_back("detection_loss_db must be >= 0 dB");
  if (!(duration_s >= 0.0)) p.push_back("duration_s must be >= 0 s");
  return p;
}

RingdownRecord simulateRingdown(const RingdownSimulationOptions& o) {
  const auto problems = o.validate();
  if (!problems.empty()) {
    std::string m = "ring-down simulation:";
    for (const auto& s : problems) m += " " + s + ";";
    throw InputError(m);
  }
  const double g0 = M_PI * o.frequency_hz / o.q;  // amplitude decay rate [1/s]
  const double tau = 1.0 / g0;
  const double floor_amp =
      o.floor_db > -300.0 ? o.amplitude * std::pow(10.0, o.floor_db / 20.0) : 0.0;
  double duration = o.duration_s;
  if (!(duration > 0.0)) {
    const double decay = floor_amp > 0.0 ? tau * std::log(o.amplitude / floor_amp) : 8.0 * tau;
    duration = decay * 1.3 / 0.9;
  }
  const double plateau = o.plateau_s >= 0.0 ? o.plateau_s : 0.1 * duration;
  const int n = o.n_samples;
  const double dt = duration / (n - 1);
  const double g2 = M_PI * o.frequency_hz / (o.q2 > 0.0 ? o.q2 : o.q);
  const double gf = M_PI * o.frequency_hz / (o.q_fast > 0.0 ? o.q_fast : o.q / 5.0);
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> N01(0.0, 1.0);
  const double rho = o.noise_correlation, innov = std::sqrt(1.0 - rho * rho);
  const double sd_m = o.noise_db / (kDbPerNeper);
  double em = sd_m * N01(rng);
  std::complex<double> na(floor_amp / std::sqrt(2.0) * N01(rng),
                          floor_amp / std::sqrt(2.0) * N01(rng));
  RingdownRecord rec;
  rec.frequency_hz = o.frequency_hz;
  rec.kind = o.output_db ? RingdownValueKind::kPowerDb : RingdownValueKind::kAmplitude;
  std::ostringstream truth;
  truth << "simulated ring-down: Q " << o.q << ", gamma_nl " << o.gamma_nl << ", gamma_a "
        << o.gamma_a << ", split_hz " << o.split_hz << ", seed " << o.seed;
  rec.comments.push_back(truth.str());
  double a1 = o.amplitude;
  auto rate = [&](double a) { return -(g0 + o.gamma_nl * a * a + o.gamma_a * a) * a; };
  const double t_loss = plateau + 0.45 * (duration - plateau) * 0.9 / 1.3;
  std::vector<double> ys(n);
  for (int i = 0; i < n; ++i) {
    const double t = i * dt;
    const double td = std::max(0.0, t - plateau);
    if (i > 0 && t > plateau) {  // RK4 from the previous sample (or from the switch-off)
      const double h = std::min(dt, t - plateau);
      const int sub = 8;
      const double hs = h / sub;
      for (int k = 0; k < sub; ++k) {
        const double k1 = rate(a1), k2 = rate(a1 + 0.5 * hs * k1), k3 = rate(a1 + 0.5 * hs * k2),
                     k4 = rate(a1 + hs * k3);
        a1 += hs / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
      }
    }
    std::complex<double> z(a1, 0.0);
    if (o.second_amplitude > 0.0)
      z += o.second_amplitude * o.amplitude * std::exp(-g2 * td) *
           std::polar(1.0, 2.0 * M_PI * o.split_hz * td);
    double amp = std::abs(z);
    if (o.two_stage_ratio > 0.0) {
      const double af = o.two_stage_ratio * o.amplitude * std::exp(-gf * td);
      amp = std::sqrt(amp * amp + af * af);
    }
    if (o.detection_loss_db > 0.0) {
      const double w = 0.06 * (duration - plateau);
      const double s = 1.0 / (1.0 + std::exp(-(t - t_loss) / w));
      amp *= std::pow(10.0, -o.detection_loss_db * s / 20.0);
    }
    if (i > 0) {
      em = rho * em + innov * sd_m * N01(rng);
      na = rho * na + innov * std::complex<double>(floor_amp / std::sqrt(2.0) * N01(rng),
                                                   floor_amp / std::sqrt(2.0) * N01(rng));
    }
    ys[i] = std::abs(amp * std::exp(em) + na);
    rec.t_s.push_back(t);
  }
  std::uniform_int_distribution<int> pick(static_cast<int>(plateau / dt) + 1, n - 1);
  for (int k = 0; k < o.dropouts; ++k) ys[pick(rng)] *= 1e-3;
  for (int i = 0; i < n; ++i)
    rec.value.push_back(o.output_db ? 20.0 * std::log10(ys[i]) + o.db_offset : ys[i]);
  rec.value_column = o.output_db ? "power_db" : "amplitude";
  rec.source = "simulated";
  return rec;
}

}  // namespace cvg_bench

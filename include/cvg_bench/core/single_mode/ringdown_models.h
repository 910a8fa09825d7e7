// Envelope models of a single-channel ring-down, in normalized units: time t' = (t - t_start) / T
// over the fitted span of length T, amplitude A' = A / A_ref (A_ref the span's first level), so the
// fit is scale-free (an amplitude of 3e-4 and of 1 give the same answer). Each returns the mean of
// ln A'(t') as detected over a known noise floor of rms F' (additive circular Gaussian noise, a
// Rice magnitude): ln A' + E1(A'^2 / F'^2) / 2, which is ln A' to 4e-6 at 10 dB above the floor.
// Damping conventions (amplitude decay rate g [1/T]; Q = omega tau / 2 = pi f T / g, tau = T / g
// the amplitude time constant):
//   linear     dA/dt = -g A                              ln A = a - g t
//   gamma_nl   dA/dt = -(g0 + g2 A^2) A  (gas, thermoelastic at large amplitude; the slow-variable
//              form of the extension gamma_nl of docs/paper.md: -gamma_nl (f^2+g^2) f')
//              A^2 = e^{2a} e^{-2 g0 t} / (1 + g2 e^{2a} (1 - e^{-2 g0 t}) / g0)  (1/A^2 is linear
//              in e^{2 g0 t})
//   gamma_a    dA/dt = -(g0 + g1 A) A    (clamping / friction-like loss)
//              A = e^{a} e^{-g0 t} / (1 + g1 e^{a} (1 - e^{-g0 t}) / g0)
//   beat       two close modes in one channel: A^2 = |e^{a1 - d1 t} + e^{a2 - d2 t} e^{i(w t +
//   phi)}|^2
//              (w = 2 pi split frequency x T; d1, d2 the two modes' rates)
//   two_stage  two decays without beating (modes far apart): A^2 = e^{2(a1 - d1 t)} + e^{2(a2 - d2
//   t)}
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace cvg_bench {

/// Parameter names of a ring-down model (normalized units) in vector order; InputError for an
/// unknown model. Names: linear {a, g}; gamma_nl {a, g0, g2}; gamma_a {a, g0, g1};
/// beat {a1, d1, a2, d2, w, phi}; two_stage {a1, d1, a2, d2}.
std::vector<std::string> ringdownParameterNames(const std::string& model);

/// ln A'(t') of the model plus the floor F' (>= 0) in power. Returns NaN where the parameters
/// give no finite positive amplitude (e.g. a negative g2 blowing up within the span).
double ringdownLogAmplitude(const std::string& model, const Eigen::VectorXd& p, double t,
                            double floor_rel);

/// The models the explain stage knows, extension names of interfaces.md.
const std::vector<std::string>& ringdownExtensionNames();

}  // namespace cvg_bench

// Envelope models of a single-channel ring-down by name: the ring-down laws of ringdown_laws.h
// (their equations, normalized units and the floor's Rice mean are stated there), as thin
// wrappers over its registry for callers that hold a law's name.
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

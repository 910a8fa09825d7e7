// Registry of the ring-down laws: the envelope models a single-channel ring-down is fitted with
// (ringdown_fit.h), one record per law holding everything specific to it. The by-name functions of
// ringdown_models.h are thin wrappers over it; a fit resolves its law once (ringdownLaw) and calls
// the record's function pointers, so nothing dispatches on the name per sample.
//
// Envelope models in normalized units: time t' = (t - t_start) / T over the fitted span of length
// T, amplitude A' = A / A_ref (A_ref the span's first level), so the fit is scale-free (an
// amplitude of 3e-4 and of 1 give the same answer). Each returns the mean of ln A'(t') as detected
// over a known noise floor of rms F' (additive circular Gaussian noise, a Rice magnitude):
// ln A' + E1(A'^2 / F'^2) / 2, which is ln A' to 4e-6 at 10 dB above the floor.
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
//
// How to add a ring-down law: in ringdown_laws.cpp, write its pieces in one block like the others:
// ln A'(t') without the floor (false outside its domain), its starting points from the fitted
// linear baseline, its canonical parameter order (keepOrder when it has none), its physical readout
// (rates in 1/s, Q, tau_s, flags, through RingdownReadout), its physical check (the explain
// stage's sign check), the sentence the explanation prints when it is selected, and a function
// returning its RingdownLaw record with its kind and flags; add that to the table in
// ringdownLaws(). is_extension = true makes it a candidate of the explain stage
// (ringdownExtensionNames, in table order; the default RingdownExplainOptions::candidates). State
// its equation above and its parameter names in ringdown_models.h, its outputs in
// docs/interfaces.md. The unknown-name message lists the table. Neither the fit nor the explain
// stage nor the CLI dispatches on a law's name: they read the record's fields
// (test/core/single_mode/ringdown_laws_test.cpp checks every law has them).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "cvg_bench/core/single_mode/ringdown_fit.h"

namespace cvg_bench {

struct RingdownLaw;

/// What a law's physical readout works from (fitRingdown, after the intervals): the fit with its
/// normalized parameters and covariances; it writes fit.parameters, fit.derived and fit.flags.
struct RingdownReadout {
  const RingdownLaw& law;
  RingdownFit& fit;
  double z;        ///< quantile of the intervals (Student, the covariance's degrees of freedom)
  double T;        ///< time scale [s]: rates in 1/T -> 1/s divide by T
  double qc;       ///< Q = qc / rate (rate in 1/T); pi f T
  double a_ref;    ///< A_ref [file's unit]
  double t_first;  ///< normalized time of the first fitted sample
  double t_last;   ///< normalized time of the last fitted sample

  /// Normalized parameter k with its standard error and interval.
  RingdownValue param(int k) const;
  /// A function of the parameters by the delta method.
  RingdownValue value(const std::function<double(const Eigen::VectorXd&)>& fn) const;
  /// fit.parameters[name] = the rate in 1/s.
  void putRate(const std::string& name, const RingdownValue& rate) const;
  /// fit.derived[name] = Q of the rate, when the frequency is known.
  void putQ(const std::string& name, const RingdownValue& rate) const;
};

/// How the explain stage treats a law (ringdown_causes.h).
enum class RingdownLawKind {
  /// The single exponential every other law is compared with (not a candidate).
  kBaseline,
  /// Damping that depends on the amplitude: rate g0 + g A^amplitude_power, parameters {a, g0, g}
  /// (g at index 2). Q0 at zero amplitude differs from the line's Q by design; a negative g that
  /// wins means the decay accelerates ("unexplained"); the two such laws are compared once more
  /// through the detector filter.
  kAmplitudeLaw,
  /// Another shape of the decay (two modes): it must beat every physical amplitude law by
  /// law_margin and predict held-out blocks by the larger hold-out margin.
  kShapeAlternative,
};

/// Thresholds of the laws' physical checks (RingdownLaw::physical_check; the explain stage's
/// RingdownExplainOptions::plausibility).
struct RingdownPlausibilityOptions {
  /// beat: smallest split w [rad per span] a beat is taken for: 4 pi, two beat periods in the
  /// span (fewer: a step is not a beat). Set by hand with "beat needs 2 periods" (commit 2cc791c),
  /// no recorded evidence for 2.
  double beat_min_split_w = 4.0 * M_PI;
  /// beat: smallest amplitude ratio A2/A1 of the second mode at the span's start [1] (0.5 %).
  /// Set by hand (commit 3dbfdf5), no recorded evidence.
  double beat_min_amplitude_ratio = 0.005;
  /// two_stage: the fast stage's rate at least this times the slow one's [1]. Set by hand
  /// (commit 3dbfdf5), no recorded evidence.
  double two_stage_min_rate_ratio = 1.5;
};

/// One ring-down law (see the file comment for the equations and how to add one).
struct RingdownLaw {
  /// Name (--model, the extension names of docs/interfaces.md).
  const char* name = nullptr;
  /// Normalized parameter names in vector order.
  std::vector<std::string> parameters;
  /// A candidate of the explain stage (every law but the linear baseline).
  bool is_extension = false;
  /// ln A'(t') without the floor into log_a; false where the parameters give no finite positive
  /// amplitude (log_a then unset).
  bool (*log_amplitude)(const Eigen::VectorXd& p, double t, double& log_a) = nullptr;
  /// Starting points from a fitted linear baseline.
  std::vector<Eigen::VectorXd> (*starts)(const RingdownFit& linear) = nullptr;
  /// Puts fitted parameters in canonical order, in place (two-component laws: which is mode 1).
  void (*canonical_order)(Eigen::VectorXd& p) = nullptr;
  /// Physical values, derived values and flags of a fit with details.
  void (*readout)(const RingdownReadout& r) = nullptr;

  // ---- what the explain stage (ringdown_causes.cpp) and the CLI read ----
  /// How the explain stage treats it.
  RingdownLawKind kind = RingdownLawKind::kBaseline;
  /// kAmplitudeLaw: the power of A in its amplitude-dependent rate (2: A^2, 1: A), which names the
  /// generator's coefficient it is simulated with (cvg_ident simulate --effect); 0 otherwise.
  int amplitude_power = 0;
  /// Its split frequency is searched (a periodogram over the span): its information criterion
  /// pays for the search beyond its parameters (RingdownExplainOptions::split_search_penalty).
  bool searched_frequency = false;
  /// An accepted fit must have its Q within RingdownExplainOptions::q_factor of the single
  /// exponential's over the same span (else it describes something else than the decay).
  bool q_checked_against_baseline = false;
  /// Sign check of fitted normalized parameters: "" when physical, else why not.
  std::string (*physical_check)(const Eigen::VectorXd& p,
                                const RingdownPlausibilityOptions& o) = nullptr;
  /// The sentence of the explanation when it is selected, a template: {KEY} prints the final
  /// fit's derived value KEY with its interval ("n/a (no frequency)" when absent), {KEY.value} its
  /// value alone. Ends with a space. Empty for the baseline.
  const char* cause_text = "";

  /// ln A'(t') plus the floor F' (>= 0) in power (Rice mean); NaN where log_amplitude is false.
  double logAmplitude(const Eigen::VectorXd& p, double t, double floor_rel) const;
};

/// The laws, linear first, then the extensions in the explain stage's order.
const std::vector<RingdownLaw>& ringdownLaws();

/// The law of that name; InputError for an unknown name (the message lists the known ones).
const RingdownLaw& ringdownLaw(const std::string& name);

/// The law of that name, nullptr for an unknown name.
const RingdownLaw* findRingdownLaw(const std::string& name);

/// Q = c / rate. The interval is the delta method on ln Q = ln c - ln rate (sd of ln Q = the
/// rate's relative sd), with the rate's own quantile: positive and of nonzero width for every
/// decaying fit, where mapping the rate's symmetric interval opened above as soon as it reached 0
/// (a 35 dB decay with strongly correlated residuals and few effective samples printed
/// [1.4e6, inf]). A rate that is not positive has no Q interval (-inf, inf).
RingdownValue ringdownQFromRate(const RingdownValue& rate, double c);

/// v times s (std and crb_std times |s|, the interval reordered for s < 0).
RingdownValue ringdownScaled(RingdownValue v, double s);

}  // namespace cvg_bench

// One driven mode's stationary response (docs/response.md): the one source of the equation that
// the fit, the generator's truth conversion and the report evaluate.
//
//   Z = d (b0 + b1 (f - f_ref)) + d a S(f) / D(u),   u = |d a / D(u)|^2
//   D(u) = f0^2 - f^2 + 2 f0 xi u + i f (w0 + g u)
//
// f drive frequency [Hz], d drive level (input units), a complex gain, b0, b1 complex background
// per unit drive (the drive's crosstalk into the detector), S = 1 (displacement) or f / f0
// (velocity: the i of i omega x is absorbed in a's phase). u is the squared amplitude of the
// displacement in the input's x, y unit (for a velocity response: the velocity reading scaled by
// f0 / f, which the Duffing terms act on). f0 and w0 are the zero-amplitude frequency and full
// width at half power [Hz]; xi the backbone (frequency shift per amplitude^2, Duffing: the
// first-harmonic balance of a cubic stiffness gives f0(u)^2 = f0^2 + 2 f0 xi u exactly) and g the
// width growth per amplitude^2 (either sign). Q = f0 / w0.
//
// u solves the cubic u |D(u)|^2 = |d a|^2. Where it has three positive roots the middle one is
// unstable (the slope of u |D|^2 in u is negative there); along a sweep, in time order, the
// response stays on the stable root nearest the previous point's (that is what makes jumps and
// up/down hysteresis), and jumps where its branch ends.
#pragma once

#include <complex>
#include <string>
#include <vector>

#include "cvg_bench/core/io/response_record.h"

namespace cvg_bench {

/// Which terms a one-mode model has: backbone (xi), width growth (gamma_nl), background slope. The
/// terms' names, keys and texts are in the registry response_laws.h.
struct ResponseTerms {
  bool backbone = false;
  bool width_growth = false;
  bool background_slope = false;
  /// `linear`, or the terms' names joined by '+' in the registry's order (xi+gamma_nl).
  std::string name() const;
};
/// `linear`, or term names of the registry (response_laws.h) joined by '+' in any order; InputError
/// on other names.
ResponseTerms parseResponseTerms(const std::string& model);

struct ResponseParams {
  double f0_hz = 0.0;
  double width_hz = 0.0;
  double backbone_hz_per_amp2 = 0.0;      ///< xi
  double width_growth_hz_per_amp2 = 0.0;  ///< g (gamma_nl)
  std::complex<double> gain, bg0, bg1;
  double f_ref_hz = 0.0;  ///< frequency of the background's constant term
};

/// The points of a response record in time order (the conjugate of the file's x + iy when the
/// lock-in's phase runs the other way; the fit decides).
struct ResponseData {
  std::vector<double> frequency_hz, drive;
  std::vector<std::complex<double>> z;
  std::vector<int> sweep;  ///< sweep index per point (splitSweeps)
  /// Optional factor on the drive of the resonant part only (not the background) per point; empty
  /// = 1. The adequacy check fits one per drive level.
  std::vector<double> resonant_drive_factor;
  ResponseKind kind = ResponseKind::kDisplacement;
  size_t size() const { return z.size(); }
};

/// Stable squared amplitudes u >= 0 of u |D(u)|^2 = p, ascending (one or two).
std::vector<double> stableSquaredAmplitudes(const ResponseParams& p, double f_hz, double power);

/// How the stable root is chosen where there are two.
enum class BranchChoice {
  kFollow,       ///< the one nearest the previous point's, in time order (the physics)
  kNearestData,  ///< the one nearest the data's own |Z - background|^2 (a smooth cost for the
                 ///< first stage of a fit; no hysteresis of its own)
};

/// The model response at every point (see above). `u_out` (optional) receives u per point and
/// `jumps` the number of branch changes.
std::vector<std::complex<double>> stationaryResponse(const ResponseParams& p,
                                                     const ResponseData& data,
                                                     std::vector<double>* u_out = nullptr,
                                                     int* jumps = nullptr,
                                                     BranchChoice choice = BranchChoice::kFollow);

}  // namespace cvg_bench

// Simulated single-channel ring-downs (what a lock-in or a zero-span spectrum analyser records):
// a driven plateau, the drive switched off, the decay, a noise floor and drop-outs. The mode's
// amplitude obeys dA/dt = -(g0 + gamma_nl A^2 + gamma_a A) A (g0 = pi f / Q; gamma_nl is the
// slow-variable form of the extension of docs/paper.md), integrated by RK4; a second close mode
// (split_hz) adds coherently (a beat), a second far mode incoherently (two-stage decay). The
// detector sees |z e^{e_m} + n_a| x gain(t): e_m relative noise (noise_db), n_a complex additive
// noise of rms `floor` (the noise floor), both AR(1) with coefficient noise_correlation; gain(t)
// is 1 unless detection_loss_db > 0 (a smooth step down mid-decay: the mode drifting out of the
// detection band, so the observed decay rate rises and falls).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cvg_bench/core/io/ringdown_record.h"

namespace cvg_bench {

struct RingdownSimulationOptions {
  double frequency_hz = 1.0e4;     ///< mode frequency [Hz], > 0
  double q = 1.0e5;                ///< zero-amplitude Q of the mode, > 0
  double amplitude = 1.0;          ///< amplitude at switch-off [any unit], > 0
  double plateau_s = -1.0;         ///< plateau length [s]; < 0: 10 % of the record
  double duration_s = 0.0;         ///< record length [s]; 0: plateau + decay to the floor + 30 %
  int n_samples = 2000;            ///< samples in the record, >= 50
  double gamma_nl = 0.0;           ///< A^2 damping [1/(s unit^2)]
  double gamma_a = 0.0;            ///< A-linear damping [1/(s unit)]
  double split_hz = 0.0;           ///< second close mode's offset [Hz] (0: none)
  double second_amplitude = 0.0;   ///< its amplitude / the first's at switch-off
  double q2 = 0.0;                 ///< its Q (0: = q)
  double two_stage_ratio = 0.0;    ///< incoherent fast component / the mode at switch-off (0: none)
  double q_fast = 0.0;             ///< its Q (0: q / 5)
  double noise_db = 0.05;          ///< relative (log-scale) noise sd [dB], >= 0
  double floor_db = -60.0;         ///< additive noise rms re the amplitude [dB] (<= -300: none)
  double noise_correlation = 0.0;  ///< AR(1) coefficient of both noises per sample, [0, 0.99]
  int dropouts = 0;                ///< samples after switch-off blanked to -60 dB
  double detection_loss_db = 0.0;  ///< depth of the detection-gain step [dB], >= 0
  bool output_db = false;          ///< write power_db (20 log10 A + db_offset) instead of amplitude
  double db_offset = 0.0;          ///< dB offset (e.g. dBm re the unit)
  uint32_t seed = 1;
  std::vector<std::string> validate() const;
};

/// The record (t from 0, frequency_hz set, a comment naming the truth).
RingdownRecord simulateRingdown(const RingdownSimulationOptions& options);

}  // namespace cvg_bench

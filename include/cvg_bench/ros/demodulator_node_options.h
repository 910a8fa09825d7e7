// Settings of demodulator_node (config/demodulator.yaml documents each key).
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/demod/demodulator.h"
#include "cvg_bench/ros/param_reader.h"

namespace cvg_bench {

struct DemodulatorNodeOptions {
  /// Reference frequency W [rad/s], >= 0; 0 = from each batch (its drive_frequency_rad_s when a
  /// drive is on, else its omega_rad_s).
  double omega_rad_s = 0.0;
  /// Nominal input sample rate [Hz], >= 0; 0 = the batches' sample_rate_hz.
  double sample_rate_hz = 0.0;
  /// The core demodulator's filter settings (output_rate_hz, passband_hz, stopband_hz,
  /// attenuation_db, interval_tolerance, gap_periods, anchor_interval); omega and sample rate come
  /// from the two fields above or the data.
  DemodulatorOptions filter;
  /// Minimum interval between two warnings about dropped samples [s], > 0.
  double warn_throttle_s = 5.0;
  /// A stamp earlier than the previous batch's end by more than this resets the demodulator
  /// (bag loop, clock reset) [s], >= 0.
  double backward_jump_s = 0.0;
  /// Subscriber and publisher queue lengths, >= 1.
  int queue_size = 1000;
  /// Queue length of the raw subscription [batches], >= 1: a short queue bounds the memory when
  /// the input outruns the node (the oldest batches are dropped and counted).
  int raw_queue_size = 100;

  std::vector<std::string> validate() const;
  void load(ParamReader& reader);
};

}  // namespace cvg_bench

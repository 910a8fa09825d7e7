#include "cvg_bench/ros/demodulator_node_options.h"

#include <algorithm>
#include <cmath>

namespace cvg_bench {

std::vector<std::string> DemodulatorNodeOptions::validate() const {
  std::vector<std::string> p;
  if (!(omega_rad_s >= 0.0)) p.push_back("omega_rad_s: must be >= 0");
  if (!(sample_rate_hz >= 0.0)) p.push_back("sample_rate_hz: must be >= 0");
  if (!(warn_throttle_s > 0.0)) p.push_back("warn_throttle_s: must be > 0");
  if (!(backward_jump_s >= 0.0)) p.push_back("backward_jump_s: must be >= 0");
  if (queue_size < 1) p.push_back("queue_size: must be >= 1");
  if (raw_queue_size < 1) p.push_back("raw_queue_size: must be >= 1");
  // The core filter's own checks need W and the rate. Where the data will supply them, check the
  // other settings with placeholders that pass the W / rate checks (rate 10x W, W well above the
  // output rate); the real values are checked again when the first batch arrives.
  DemodulatorOptions f = filter;
  const double out_hz = filter.output_rate_hz > 0.0 ? filter.output_rate_hz : 1.0;
  const double w_hz = omega_rad_s > 0.0 ? omega_rad_s / (2.0 * M_PI) : 0.0;
  f.sample_rate_hz = sample_rate_hz > 0.0 ? sample_rate_hz : std::max(1000.0 * out_hz, 10.0 * w_hz);
  f.omega_rad_s = omega_rad_s > 0.0 ? omega_rad_s : 2.0 * M_PI * f.sample_rate_hz / 10.0;
  for (const auto& s : f.validate()) p.push_back("filter: " + s);
  return p;
}

void DemodulatorNodeOptions::load(ParamReader& r) {
  r.get("omega_rad_s", omega_rad_s);
  r.get("sample_rate_hz", sample_rate_hz);
  r.get("output_rate_hz", filter.output_rate_hz);
  r.get("passband_hz", filter.passband_hz);
  r.get("stopband_hz", filter.stopband_hz);
  r.get("attenuation_db", filter.attenuation_db);
  r.get("interval_tolerance", filter.interval_tolerance);
  r.get("gap_periods", filter.gap_periods);
  r.get("anchor_interval", filter.anchor_interval);
  r.get("warn_throttle_s", warn_throttle_s);
  r.get("backward_jump_s", backward_jump_s);
  r.get("queue_size", queue_size);
  r.get("raw_queue_size", raw_queue_size);
}

}  // namespace cvg_bench

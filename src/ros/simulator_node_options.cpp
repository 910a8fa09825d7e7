#include "cvg_bench/ros/simulator_node_options.h"

namespace cvg_bench {

std::vector<std::string> SimulatorNodeOptions::validate() const {
  std::vector<std::string> p;
  if (preset.empty() && config.empty()) p.push_back("preset or config: one must be set");
  if (autostart != "free_decay" && autostart != "forced" && autostart != "none")
    p.push_back("autostart: must be free_decay, forced or none, got '" + autostart + "'");
  if (!(duration_s >= 0.0)) p.push_back("duration_s: must be >= 0");
  if (!(max_duration_s > 0.0)) p.push_back("max_duration_s: must be > 0");
  if (duration_s > max_duration_s) p.push_back("duration_s: must not exceed max_duration_s");
  if (max_batch_samples < 1000) p.push_back("max_batch_samples: must be >= 1000");
  if (!(realtime_factor > 0.0 && realtime_factor <= 1000.0))
    p.push_back("realtime_factor: must be in (0, 1000]");
  if (!(publish_rate_hz >= 1.0 && publish_rate_hz <= 1000.0))
    p.push_back("publish_rate_hz: must be in [1, 1000]");
  if (!(start_delay_s >= 0.0 && start_delay_s <= 60.0))
    p.push_back("start_delay_s: must be in [0, 60]");
  if (!(sweep_point_interval_s >= 0.0 && sweep_point_interval_s <= 10.0))
    p.push_back("sweep_point_interval_s: must be in [0, 10]");
  if (seed < 0) p.push_back("seed: must be >= 0");
  if (!(noise_scale >= 0.0)) p.push_back("noise_scale: must be >= 0");
  if (!publish_raw && !publish_slow)
    p.push_back("publish_raw, publish_slow: at least one must be true");
  return p;
}

void SimulatorNodeOptions::load(ParamReader& r) {
  r.get("preset", preset);
  r.get("config", config);
  r.get("autostart", autostart);
  r.get("publish_raw", publish_raw);
  r.get("publish_slow", publish_slow);
  r.get("duration_s", duration_s);
  r.get("realtime_factor", realtime_factor);
  r.get("publish_rate_hz", publish_rate_hz);
  r.get("start_delay_s", start_delay_s);
  r.get("sweep_point_interval_s", sweep_point_interval_s);
  r.get("seed", seed);
  r.get("noise_scale", noise_scale);
  r.get("max_duration_s", max_duration_s);
  r.get("max_batch_samples", max_batch_samples);
  r.get("frame_id", frame_id);
}

}  // namespace cvg_bench

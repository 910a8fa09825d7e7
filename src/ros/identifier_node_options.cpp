#include "cvg_bench/ros/identifier_node_options.h"

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {

std::vector<std::string> IdentifierNodeOptions::validate() const {
  std::vector<std::string> p;
  ExperimentMode m = ExperimentMode::kFreeDecay;
  try {
    m = parseExperimentMode(mode);
  } catch (const InputError& e) {
    p.push_back(std::string("mode: ") + e.what());
  }
  try {
    ResonatorModel model(identification.model, m);
  } catch (const InputError& e) {
    p.push_back(std::string("model: ") + e.what());
  }
  for (const auto& s : identification.validate()) p.push_back(s);
  if (identification.method == "rls" && m == ExperimentMode::kForced)
    p.push_back("method: rls (recursive) applies to free decay only; use ls for a sweep");
  if (!(window_s >= 0.0)) p.push_back("window_s: must be >= 0");
  if (max_samples < 10) p.push_back("max_samples: must be >= 10");
  if (min_samples < 4) p.push_back("min_samples: must be >= 4");
  if (min_samples > max_samples) p.push_back("min_samples: must not exceed max_samples");
  if (!(identify_period_s >= 0.0)) p.push_back("identify_period_s: must be >= 0");
  if (!(idle_identify_s >= 0.0)) p.push_back("idle_identify_s: must be >= 0");
  if (!(rls_publish_period_s >= 0.0)) p.push_back("rls_publish_period_s: must be >= 0");
  if (frame_id.empty()) p.push_back("frame_id: must not be empty");
  if (queue_size < 1) p.push_back("queue_size: must be >= 1");
  if (history_size < 1) p.push_back("history_size: must be >= 1");
  return p;
}

void IdentifierNodeOptions::load(ParamReader& r) {
  r.get("mode", mode);
  r.get("model", identification.model);
  r.get("method", identification.method);
  r.get("confidence", identification.confidence);
  r.get("omega_rad_s", identification.omega_rad_s);
  r.get("angular_gain", identification.angular_gain_k);
  r.get("mu", identification.mu);
  r.get("rank_tolerance", identification.rank_tolerance);
  r.get("rls_forgetting", identification.rls_forgetting);
  r.get("window_s", window_s);
  r.get("max_samples", max_samples);
  r.get("min_samples", min_samples);
  r.get("identify_period_s", identify_period_s);
  r.get("idle_identify_s", idle_identify_s);
  r.get("rls_publish_period_s", rls_publish_period_s);
  r.get("frame_id", frame_id);
  r.get("child_frame_prefix", child_frame_prefix);
  r.get("queue_size", queue_size);
  r.get("history_size", history_size);
}

}  // namespace cvg_bench

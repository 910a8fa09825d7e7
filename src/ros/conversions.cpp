// ROS message <-> core conversions (see conversions.h).
#include "cvg_bench/ros/conversions.h"

#include <cmath>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/io/input_checks.h"
#include "cvg_bench/core/model/resonator_model.h"

namespace cvg_bench {
namespace {

std::string sizeMismatch(const std::string& what, size_t got, size_t want) {
  std::ostringstream s;
  s << what << " has " << got << " elements, expected " << want;
  return s.str();
}

}  // namespace

double secondsSince(const ros::Time& t, const ros::Time& origin) {
  const int64_t ns = static_cast<int64_t>(t.toNSec()) - static_cast<int64_t>(origin.toNSec());
  return static_cast<double>(ns) * 1e-9;
}

ros::Time timeAfter(const ros::Time& origin, double seconds) {
  requireFinite(seconds, "time offset [s]");
  if (std::fabs(seconds) > 4.0e9) throw InputError("time offset puts the stamp outside ros::Time");
  const int64_t ns = static_cast<int64_t>(origin.toNSec()) + std::llround(seconds * 1e9);
  if (ns < 0 || ns >= (int64_t{1} << 32) * int64_t{1000000000})
    throw InputError("time offset puts the stamp outside ros::Time");
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(ns));
  return t;
}

RawSamples rawSamplesFromMsg(const RawSampleBatch& msg, const ros::Time& origin) {
  const size_t n = msg.f.size();
  if (msg.g.size() != n) throw InputError(sizeMismatch("RawSampleBatch.g", msg.g.size(), n));
  const bool irregular = !msg.time_offsets_s.empty();
  if (irregular && msg.time_offsets_s.size() != n)
    throw InputError(sizeMismatch("RawSampleBatch.time_offsets_s", msg.time_offsets_s.size(), n));
  if (!irregular && n > 0 && !(std::isfinite(msg.sample_rate_hz) && msg.sample_rate_hz > 0.0))
    throw InputError("RawSampleBatch has neither a positive sample_rate_hz nor time_offsets_s");
  RawSamples out;
  out.f = msg.f;
  out.g = msg.g;
  out.t_s.resize(n);
  const double t0 = secondsSince(msg.header.stamp, origin);
  if (irregular) {
    for (size_t i = 0; i < n; ++i) out.t_s[i] = t0 + msg.time_offsets_s[i];
    return out;
  }
  // A stamp is a whole nanosecond: a uniform batch whose first sample lies within 1 ns of the
  // sample grid counted from the origin is put on that grid, sample k at k / rate, so the times
  // do not depend on where a publisher cut its batches (issue #27: two live runs, one record).
  const double rate = msg.sample_rate_hz;
  const double k0 = std::round(t0 * rate);
  const bool on_grid = rate < 1e8 && std::fabs(t0 - k0 / rate) <= 1e-9 && std::fabs(k0) < 1e15;
  for (size_t i = 0; i < n; ++i)
    out.t_s[i] =
        on_grid ? (k0 + static_cast<double>(i)) / rate : t0 + static_cast<double>(i) / rate;
  return out;
}

RawSampleBatch rawBatchToMsg(const RawRecord& record, size_t begin, size_t end,
                             const ros::Time& origin, double sample_rate_hz) {
  if (begin > end || end > record.size() || record.f.size() != record.size() ||
      record.g.size() != record.size())
    throw InputError("rawBatchToMsg: sample range outside the record or inconsistent record");
  RawSampleBatch msg;
  if (begin == end) {
    msg.header.stamp = origin;
  } else {
    msg.header.stamp = timeAfter(origin, record.t_s[begin]);
  }
  msg.sample_rate_hz = sample_rate_hz > 0.0 ? sample_rate_hz : 0.0;
  msg.f.assign(record.f.begin() + begin, record.f.begin() + end);
  msg.g.assign(record.g.begin() + begin, record.g.begin() + end);
  if (sample_rate_hz <= 0.0) {
    msg.time_offsets_s.reserve(end - begin);
    for (size_t i = begin; i < end; ++i)
      msg.time_offsets_s.push_back(record.t_s[i] - record.t_s[begin]);
  }
  msg.omega_rad_s = record.omega_rad_s;
  msg.phase_epoch = origin;
  return msg;
}

Eigen::Vector4d slowFromMsg(const SlowState& msg) {
  const Eigen::Vector4d q(msg.q1, msg.p1, msg.q2, msg.p2);
  if (!q.allFinite()) throw InputError("SlowState has a non-finite q1, p1, q2 or p2");
  if (q.cwiseAbs().maxCoeff() > kMaxStateMagnitude)
    throw InputError("SlowState q1, p1, q2 or p2 beyond 1e30 [amplitude units] (corrupted)");
  return q;
}

SlowState slowStateToMsg(const Eigen::Vector4d& q, const ros::Time& stamp,
                         const ros::Time& phase_epoch, double reference_frequency_rad_s,
                         double detuning_rad_s) {
  SlowState msg;
  msg.header.stamp = stamp;
  msg.phase_epoch = phase_epoch;
  msg.q1 = q[0];
  msg.p1 = q[1];
  msg.q2 = q[2];
  msg.p2 = q[3];
  msg.reference_frequency_rad_s = reference_frequency_rad_s;
  msg.detuning_rad_s = detuning_rad_s;
  return msg;
}

SweepPoint sweepPointToMsg(const SweepRecord& record, size_t i, const ros::Time& stamp) {
  if (i >= record.size() || record.q.size() != record.size())
    throw InputError("sweepPointToMsg: point index outside the record");
  SweepPoint msg;
  msg.header.stamp = stamp;
  msg.omega0_rad_s = record.omega0_rad_s[i];
  msg.omega_rad_s = record.omega_rad_s;
  msg.q1 = record.q[i][0];
  msg.p1 = record.q[i][1];
  msg.q2 = record.q[i][2];
  msg.p2 = record.q[i][3];
  msg.settled = true;
  msg.jump = i < record.jump.size() && record.jump[i] != 0;
  msg.direction = i < record.direction.size() ? static_cast<int8_t>(record.direction[i]) : 0;
  return msg;
}

void appendSweepPoint(const SweepPoint& msg, SweepRecord* record) {
  const Eigen::Vector4d q(msg.q1, msg.p1, msg.q2, msg.p2);
  if (!q.allFinite()) throw InputError("SweepPoint has a non-finite q1, p1, q2 or p2");
  if (q.cwiseAbs().maxCoeff() > kMaxStateMagnitude)
    throw InputError("SweepPoint q1, p1, q2 or p2 beyond 1e30 [amplitude units] (corrupted)");
  if (!(std::isfinite(msg.omega0_rad_s) && msg.omega0_rad_s > 0.0))
    throw InputError("SweepPoint has omega0_rad_s <= 0 or not finite");
  if (record->omega_rad_s <= 0.0 && std::isfinite(msg.omega_rad_s) && msg.omega_rad_s > 0.0)
    record->omega_rad_s = msg.omega_rad_s;
  // Keep the optional flag columns aligned with the points: either all points have them or none.
  const bool flags = msg.direction != 0 || msg.jump || !record->direction.empty();
  if (flags && record->direction.size() < record->size()) {
    record->direction.resize(record->size(), 0);
    record->jump.resize(record->size(), 0);
  }
  record->omega0_rad_s.push_back(msg.omega0_rad_s);
  record->q.push_back(q);
  if (flags) {
    record->direction.push_back(msg.direction);
    record->jump.push_back(msg.jump ? 1 : 0);
  }
}

ModelEstimate estimateToMsg(const Estimate& e, const ros::Time& window_start,
                            const ros::Time& window_end, uint32_t n_samples) {
  ModelEstimate msg;
  msg.header.stamp = window_end;
  msg.mode = experimentModeName(e.mode);
  msg.model = e.model;
  msg.method = e.method;
  msg.omega_rad_s = e.omega_rad_s;
  msg.window_start = window_start;
  msg.window_end = window_end;
  msg.n_samples = n_samples;
  msg.names = e.names;
  const size_t n = e.names.size();
  msg.values.resize(n, 0.0);
  msg.std_errors.resize(n, 0.0);
  msg.ci_low.resize(n, 0.0);
  msg.ci_high.resize(n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    const auto it = e.parameters.find(e.names[i]);
    msg.values[i] = static_cast<Eigen::Index>(i) < e.values.size()
                        ? e.values[i]
                        : (it != e.parameters.end() ? it->second.value : 0.0);
    if (it != e.parameters.end()) {
      msg.std_errors[i] = it->second.std_error;
      msg.ci_low[i] = it->second.ci_low;
      msg.ci_high[i] = it->second.ci_high;
    }
  }
  if (e.covariance.rows() == static_cast<Eigen::Index>(n) &&
      e.covariance.cols() == static_cast<Eigen::Index>(n)) {
    msg.covariance.resize(n * n);
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j) msg.covariance[i * n + j] = e.covariance(i, j);
  }
  msg.interval_method = e.interval_method;
  msg.interval_dof = e.interval_dof;
  msg.sigma = e.sigma;
  msg.n_equations = e.n_equations;
  msg.n_params = e.n_params;
  msg.rank = e.rank;
  msg.dof = e.dof;
  msg.confidence = e.confidence;
  msg.unidentifiable = e.unidentifiable;
  msg.identifiability_note = e.identifiability_note;
  msg.notes = e.notes;
  return msg;
}

Estimate estimateFromMsg(const ModelEstimate& msg) {
  const size_t n = msg.names.size();
  if (msg.values.size() != n)
    throw InputError(sizeMismatch("ModelEstimate.values", msg.values.size(), n));
  if (msg.std_errors.size() != n || msg.ci_low.size() != n || msg.ci_high.size() != n)
    throw InputError("ModelEstimate: std_errors, ci_low, ci_high must be parallel to names");
  if (!msg.covariance.empty() && msg.covariance.size() != n * n)
    throw InputError(sizeMismatch("ModelEstimate.covariance", msg.covariance.size(), n * n));
  Estimate e;
  e.mode = parseExperimentMode(msg.mode);
  e.model = msg.model;
  e.method = msg.method;
  e.omega_rad_s = msg.omega_rad_s;
  e.names = msg.names;
  e.values = Eigen::Map<const Eigen::VectorXd>(msg.values.data(), static_cast<Eigen::Index>(n));
  for (size_t i = 0; i < n; ++i) {
    ParameterEstimate p;
    p.value = msg.values[i];
    p.std_error = msg.std_errors[i];
    p.ci_low = msg.ci_low[i];
    p.ci_high = msg.ci_high[i];
    e.parameters[msg.names[i]] = p;
  }
  if (!msg.covariance.empty()) {
    e.covariance.resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j) e.covariance(i, j) = msg.covariance[i * n + j];
  }
  e.interval_method = msg.interval_method;
  e.interval_dof = msg.interval_dof;
  e.sigma = msg.sigma;
  e.n_equations = msg.n_equations;
  e.n_params = msg.n_params;
  e.rank = msg.rank;
  e.dof = msg.dof;
  e.confidence = msg.confidence;
  e.unidentifiable = msg.unidentifiable;
  e.identifiability_note = msg.identifiability_note;
  e.notes = msg.notes;
  return e;
}

DerivedQuantitiesStamped derivedToMsg(const std::map<std::string, ParameterEstimate>& derived,
                                      const ros::Time& stamp, double confidence,
                                      double angular_gain) {
  DerivedQuantitiesStamped msg;
  msg.header.stamp = stamp;
  msg.confidence = confidence;
  msg.angular_gain = angular_gain;
  const auto set = [&](const char* key, double& v, double& lo, double& hi) {
    const auto it = derived.find(key);
    if (it == derived.end()) return;
    v = it->second.value;
    lo = it->second.ci_low;
    hi = it->second.ci_high;
  };
  set("Q", msg.Q, msg.Q_ci_low, msg.Q_ci_high);
  set("zero_rate_rad_s", msg.zero_rate_rad_s, msg.zero_rate_rad_s_ci_low,
      msg.zero_rate_rad_s_ci_high);
  set("frequency_error_rad_s", msg.frequency_error_rad_s, msg.frequency_error_rad_s_ci_low,
      msg.frequency_error_rad_s_ci_high);
  set("frequency_error_hz", msg.frequency_error_hz, msg.frequency_error_hz_ci_low,
      msg.frequency_error_hz_ci_high);
  set("frequency_split_rad_s", msg.frequency_split_rad_s, msg.frequency_split_rad_s_ci_low,
      msg.frequency_split_rad_s_ci_high);
  set("frequency_split_hz", msg.frequency_split_hz, msg.frequency_split_hz_ci_low,
      msg.frequency_split_hz_ci_high);
  set("damping_anisotropy_1_s", msg.damping_anisotropy_1_s, msg.damping_anisotropy_1_s_ci_low,
      msg.damping_anisotropy_1_s_ci_high);
  set("alpha_rad", msg.alpha_rad, msg.alpha_rad_ci_low, msg.alpha_rad_ci_high);
  set("beta_rad", msg.beta_rad, msg.beta_rad_ci_low, msg.beta_rad_ci_high);
  return msg;
}

DriftRate driftRateToMsg(double r, double k, double theta_rad, const ParameterEstimate& rate,
                         double confidence, const ros::Time& stamp) {
  DriftRate msg;
  msg.header.stamp = stamp;
  msg.r = r;
  msg.k = k;
  msg.theta_rad = theta_rad;
  msg.drift_rate_rad_s = rate.value;
  msg.std_error_rad_s = rate.std_error;
  msg.ci_low_rad_s = rate.ci_low;
  msg.ci_high_rad_s = rate.ci_high;
  msg.drift_rate_deg_h = rate.value * 180.0 / M_PI * 3600.0;
  msg.confidence = confidence;
  return msg;
}

DriftMeasured driftComparisonToMsg(const DriftComparison& c, double confidence,
                                   const ros::Time& stamp) {
  constexpr double kDegH = 180.0 / M_PI * 3600.0;
  const double nan = std::nan("");
  DriftMeasured msg;
  msg.header.stamp = stamp;
  msg.model = c.model;
  msg.r = c.r;
  msg.k = c.k;
  msg.walk_deg_h = c.walk_rad_s * kDegH;
  msg.confidence = confidence;
  for (const DriftBin& b : c.bins) {
    msg.theta_deg.push_back(b.theta_rad * 180.0 / M_PI);
    msg.measured_ok.push_back(b.measured_ok);
    msg.measured_deg_h.push_back(b.measured_ok ? b.measured.value * kDegH : nan);
    msg.measured_ci_low_deg_h.push_back(b.measured_ok ? b.measured.ci_low * kDegH : nan);
    msg.measured_ci_high_deg_h.push_back(b.measured_ok ? b.measured.ci_high * kDegH : nan);
    msg.predicted_deg_h.push_back(b.predicted.value * kDegH);
    msg.predicted_ci_low_deg_h.push_back(b.predicted.ci_low * kDegH);
    msg.predicted_ci_high_deg_h.push_back(b.predicted.ci_high * kDegH);
    msg.passes.push_back(static_cast<uint32_t>(b.passes));
  }
  msg.rms_measured_deg_h = c.rms_measured_rad_s * kDegH;
  msg.rms_difference_deg_h = c.rms_difference_rad_s * kDegH;
  msg.compensation_gain =
      c.rms_difference_rad_s > 0.0 ? c.rms_measured_rad_s / c.rms_difference_rad_s : nan;
  msg.bins_measured = static_cast<uint32_t>(c.bins_measured);
  msg.summary = c.summary;
  return msg;
}

SimulationTruth truthToMsg(const std::string& preset, const std::string& mode,
                           const std::string& model, double omega_rad_s, double mu,
                           const std::vector<std::string>& names,
                           const std::map<std::string, double>& values, const ros::Time& stamp) {
  SimulationTruth msg;
  msg.header.stamp = stamp;
  msg.preset = preset;
  msg.mode = mode;
  msg.model = model;
  msg.omega_rad_s = omega_rad_s;
  msg.mu = mu;
  if (!names.empty()) {
    for (const auto& name : names) {
      const auto it = values.find(name);
      msg.names.push_back(name);
      msg.values.push_back(it == values.end() ? 0.0 : it->second);
    }
  } else {
    for (const auto& kv : values) {
      msg.names.push_back(kv.first);
      msg.values.push_back(kv.second);
    }
  }
  return msg;
}

std::map<std::string, double> truthValuesFromMsg(const SimulationTruth& msg) {
  if (msg.names.size() != msg.values.size())
    throw InputError(sizeMismatch("SimulationTruth.values", msg.values.size(), msg.names.size()));
  std::map<std::string, double> out;
  for (size_t i = 0; i < msg.names.size(); ++i) out[msg.names[i]] = msg.values[i];
  return out;
}

}  // namespace cvg_bench

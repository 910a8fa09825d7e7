// Conversions between ROS messages and core types (no roscore): exact round trips, the time origin
// arithmetic, and clear errors for malformed messages.
#include "cvg_bench/ros/conversions.h"

#include <gtest/gtest.h>

#include <cmath>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace {

TEST(Conversions, TimeArithmeticIsExactAtAbsoluteStamps) {
  const ros::Time origin(1700000000, 123456789);
  const ros::Time t = timeAfter(origin, 12.5e-6);
  // 12.5 us after a 1.7e9 s stamp: a double holding the absolute time would be off by ~0.1 us.
  EXPECT_EQ(t.toNSec() - origin.toNSec(), 12500u);
  EXPECT_DOUBLE_EQ(secondsSince(t, origin), 12.5e-6);
  EXPECT_DOUBLE_EQ(secondsSince(origin, t), -12.5e-6);
  EXPECT_THROW(timeAfter(origin, std::nan("")), InputError);
  EXPECT_THROW(timeAfter(ros::Time(1, 0), -5.0), InputError);
}

TEST(Conversions, UniformRawBatchRoundTrip) {
  RawRecord rec;
  rec.omega_rad_s = 31415.9;
  const double rate = 20000.0;
  for (int i = 0; i < 50; ++i) {
    rec.t_s.push_back(i / rate);
    rec.f.push_back(std::sin(0.3 * i));
    rec.g.push_back(std::cos(0.7 * i));
  }
  const ros::Time origin(1700000000, 0);
  const RawSampleBatch msg = rawBatchToMsg(rec, 10, 30, origin, rate);
  ASSERT_EQ(msg.f.size(), 20u);
  EXPECT_TRUE(msg.time_offsets_s.empty());
  EXPECT_EQ(msg.phase_epoch, origin);
  EXPECT_DOUBLE_EQ(msg.omega_rad_s, rec.omega_rad_s);
  const RawSamples s = rawSamplesFromMsg(msg, origin);
  ASSERT_EQ(s.t_s.size(), 20u);
  for (size_t i = 0; i < 20; ++i) {
    EXPECT_NEAR(s.t_s[i], rec.t_s[i + 10], 1e-9);  // stamps carry whole nanoseconds
    EXPECT_EQ(s.f[i], rec.f[i + 10]);
    EXPECT_EQ(s.g[i], rec.g[i + 10]);
  }
}

TEST(Conversions, UniformBatchTimesDoNotDependOnWhereBatchesAreCut) {
  // Issue #27: a stamp holds whole nanoseconds; a batch cut at another sample must give the very
  // same sample times (k / rate from the origin), not the rounded stamp plus i / rate.
  const double rate = 48000.0;
  RawRecord rec;
  for (int i = 0; i < 100000; ++i) {
    rec.t_s.push_back(i / rate);
    rec.f.push_back(0.0);
    rec.g.push_back(0.0);
  }
  const ros::Time origin(1700000000, 123456789);
  for (size_t begin : {1u, 7u, 3001u, 77777u}) {
    const RawSamples s =
        rawSamplesFromMsg(rawBatchToMsg(rec, begin, begin + 50, origin, rate), origin);
    for (size_t i = 0; i < 50; ++i) EXPECT_EQ(s.t_s[i], rec.t_s[begin + i]) << begin << " " << i;
  }
  // A stamp off the sample grid by more than its rounding (a real publisher's jitter) is kept.
  RawSampleBatch msg = rawBatchToMsg(rec, 10, 12, origin, rate);
  msg.header.stamp += ros::Duration(0, 3000);
  const RawSamples s = rawSamplesFromMsg(msg, origin);
  EXPECT_NEAR(s.t_s[0], rec.t_s[10] + 3e-6, 1e-9);  // the stamp's own rounding
  EXPECT_NEAR(s.t_s[1] - s.t_s[0], 1.0 / rate, 1e-15);
}

TEST(Conversions, IrregularRawBatchKeepsOffsets) {
  RawRecord rec;
  rec.t_s = {0.0, 0.001, 0.0035, 0.004};
  rec.f = {1, 2, 3, 4};
  rec.g = {5, 6, 7, 8};
  const ros::Time origin(100, 0);
  const RawSampleBatch msg = rawBatchToMsg(rec, 1, 4, origin, 0.0);
  ASSERT_EQ(msg.time_offsets_s.size(), 3u);
  EXPECT_DOUBLE_EQ(msg.sample_rate_hz, 0.0);
  const RawSamples s = rawSamplesFromMsg(msg, origin);
  for (size_t i = 0; i < 3; ++i) EXPECT_NEAR(s.t_s[i], rec.t_s[i + 1], 1e-9);
}

TEST(Conversions, MalformedRawBatchesAreInputErrors) {
  RawSampleBatch msg;
  msg.header.stamp = ros::Time(10, 0);
  msg.f = {1, 2, 3};
  msg.g = {1, 2};
  msg.sample_rate_hz = 100;
  EXPECT_THROW(rawSamplesFromMsg(msg, msg.header.stamp), InputError);
  msg.g = {1, 2, 3};
  msg.sample_rate_hz = 0;  // neither a rate nor offsets
  EXPECT_THROW(rawSamplesFromMsg(msg, msg.header.stamp), InputError);
  msg.time_offsets_s = {0.0, 0.1};
  EXPECT_THROW(rawSamplesFromMsg(msg, msg.header.stamp), InputError);
  msg.time_offsets_s = {0.0, 0.1, 0.2};
  EXPECT_NO_THROW(rawSamplesFromMsg(msg, msg.header.stamp));
}

TEST(Conversions, SlowStateRoundTripAndNonFinite) {
  const Eigen::Vector4d q(0.1, -0.2, 0.3, -0.4);
  SlowState msg = slowStateToMsg(q, ros::Time(5, 0), ros::Time(1, 0), 5000.0, 2.0);
  EXPECT_EQ(slowFromMsg(msg), q);
  EXPECT_DOUBLE_EQ(msg.reference_frequency_rad_s, 5000.0);
  EXPECT_DOUBLE_EQ(msg.detuning_rad_s, 2.0);
  msg.p2 = std::numeric_limits<double>::infinity();
  EXPECT_THROW(slowFromMsg(msg), InputError);
}

TEST(Conversions, SweepPointsRebuildTheRecordWithFlags) {
  SweepRecord rec;
  rec.omega_rad_s = 85732.0;
  for (int j = 0; j < 4; ++j) {
    rec.omega0_rad_s.push_back(85700.0 + 10 * j);
    rec.q.push_back(Eigen::Vector4d(j, -j, 0.5 * j, 0.25));
    rec.direction.push_back(j < 2 ? 1 : -1);
    rec.jump.push_back(j == 2 ? 1 : 0);
  }
  SweepRecord back;
  for (size_t j = 0; j < rec.size(); ++j)
    appendSweepPoint(sweepPointToMsg(rec, j, ros::Time(1 + j, 0)), &back);
  ASSERT_EQ(back.size(), 4u);
  EXPECT_DOUBLE_EQ(back.omega_rad_s, 85732.0);
  EXPECT_EQ(back.omega0_rad_s, rec.omega0_rad_s);
  EXPECT_EQ(back.direction, rec.direction);
  EXPECT_EQ(back.jump, rec.jump);
  for (size_t j = 0; j < 4; ++j) EXPECT_EQ(back.q[j], rec.q[j]);

  SweepPoint bad = sweepPointToMsg(rec, 0, ros::Time(1, 0));
  bad.omega0_rad_s = -1.0;
  EXPECT_THROW(appendSweepPoint(bad, &back), InputError);
  bad.omega0_rad_s = 1.0;
  bad.q1 = std::nan("");
  EXPECT_THROW(appendSweepPoint(bad, &back), InputError);
  EXPECT_EQ(back.size(), 4u);
}

Estimate sampleEstimate() {
  Estimate e;
  e.mode = ExperimentMode::kForced;
  e.model = "linear+xi";
  e.method = "ls";
  e.omega_rad_s = 85732.0;
  e.names = {"gamma", "nu", "xi"};
  e.values = Eigen::Vector3d(43.0, 2.0, 32.0);
  e.covariance = Eigen::Matrix3d::Identity();
  e.covariance(0, 1) = 0.25;  // not symmetric on purpose: proves the row-major order
  e.covariance(1, 0) = -0.5;
  e.covariance(2, 0) = 0.125;
  for (int i = 0; i < 3; ++i) {
    ParameterEstimate p;
    p.value = e.values[i];
    p.std_error = 0.1 * (i + 1);
    p.ci_low = p.value - 2 * p.std_error;
    p.ci_high = p.value + 2 * p.std_error;
    e.parameters[e.names[i]] = p;
  }
  e.sigma = 0.0926;
  e.n_equations = 244;
  e.n_params = 3;
  e.rank = 3;
  e.dof = 241;
  e.confidence = 0.9;
  e.interval_method = "paper (2.11)";
  e.interval_dof = 241;
  e.unidentifiable = {"h_c+c_m"};
  e.identifiability_note = "standing wave";
  e.notes = {"from a test"};
  return e;
}

TEST(Conversions, EstimateRoundTripKeepsCovarianceOrder) {
  const Estimate e = sampleEstimate();
  const ModelEstimate msg = estimateToMsg(e, ros::Time(10, 0), ros::Time(20, 0), 61);
  EXPECT_EQ(msg.mode, "forced");
  EXPECT_EQ(msg.header.stamp, ros::Time(20, 0));
  EXPECT_EQ(msg.n_samples, 61u);
  ASSERT_EQ(msg.covariance.size(), 9u);
  EXPECT_DOUBLE_EQ(msg.covariance[0 * 3 + 1], 0.25);   // (gamma, nu)
  EXPECT_DOUBLE_EQ(msg.covariance[1 * 3 + 0], -0.5);   // (nu, gamma)
  EXPECT_DOUBLE_EQ(msg.covariance[2 * 3 + 0], 0.125);  // (xi, gamma)
  const Estimate back = estimateFromMsg(msg);
  EXPECT_EQ(back.mode, e.mode);
  EXPECT_EQ(back.model, e.model);
  EXPECT_EQ(back.names, e.names);
  EXPECT_EQ(back.values, e.values);
  EXPECT_EQ(back.covariance, e.covariance);
  EXPECT_EQ(back.unidentifiable, e.unidentifiable);
  EXPECT_EQ(back.interval_method, e.interval_method);
  EXPECT_EQ(back.interval_dof, e.interval_dof);
  EXPECT_DOUBLE_EQ(back.parameters.at("nu").ci_high, e.parameters.at("nu").ci_high);
  EXPECT_DOUBLE_EQ(back.sigma, e.sigma);
  EXPECT_EQ(back.dof, 241);
}

TEST(Conversions, MalformedEstimateMessageIsInputError) {
  ModelEstimate msg = estimateToMsg(sampleEstimate(), ros::Time(1, 0), ros::Time(2, 0), 3);
  msg.covariance.pop_back();
  EXPECT_THROW(estimateFromMsg(msg), InputError);
  msg = estimateToMsg(sampleEstimate(), ros::Time(1, 0), ros::Time(2, 0), 3);
  msg.ci_low.pop_back();
  EXPECT_THROW(estimateFromMsg(msg), InputError);
  msg = estimateToMsg(sampleEstimate(), ros::Time(1, 0), ros::Time(2, 0), 3);
  msg.mode = "sideways";
  EXPECT_THROW(estimateFromMsg(msg), InputError);
}

TEST(Conversions, DerivedAndDriftFields) {
  std::map<std::string, ParameterEstimate> derived;
  derived["Q"] = {1992.4, 10.0, 1972.0, 2012.0};
  derived["alpha_rad"] = {0.601, 0.01, 0.58, 0.62};
  const DerivedQuantitiesStamped d = derivedToMsg(derived, ros::Time(3, 0), 0.95, 0.4);
  EXPECT_DOUBLE_EQ(d.Q, 1992.4);
  EXPECT_DOUBLE_EQ(d.Q_ci_low, 1972.0);
  EXPECT_DOUBLE_EQ(d.alpha_rad_ci_high, 0.62);
  EXPECT_DOUBLE_EQ(d.beta_rad, 0.0);  // absent: left 0
  EXPECT_DOUBLE_EQ(d.angular_gain, 0.4);

  const DriftRate r =
      driftRateToMsg(1.0, 0.05, 0.3, {1e-3, 1e-4, 8e-4, 1.2e-3}, 0.95, ros::Time(4, 0));
  EXPECT_DOUBLE_EQ(r.drift_rate_rad_s, 1e-3);
  EXPECT_NEAR(r.drift_rate_deg_h, 1e-3 * 180.0 / M_PI * 3600.0, 1e-12);
  EXPECT_DOUBLE_EQ(r.ci_low_rad_s, 8e-4);
}

TEST(Conversions, TruthKeepsModelOrder) {
  const SimulationTruth msg =
      truthToMsg("mems_ring", "forced", "linear", 85732.0, 0.0, {"gamma", "nu"},
                 {{"nu", 2.0}, {"gamma", 43.0}}, ros::Time(1, 0));
  ASSERT_EQ(msg.names.size(), 2u);
  EXPECT_EQ(msg.names[0], "gamma");
  EXPECT_DOUBLE_EQ(msg.values[0], 43.0);
  EXPECT_DOUBLE_EQ(truthValuesFromMsg(msg).at("nu"), 2.0);
}

// The measured-against-predicted drift in deg/h per bin; a bin with no usable pass has NaN
// measured fields (never a 0 that would read as "no drift").
TEST(Conversions, DriftComparisonInDegreesPerHourWithUnmeasuredBinsNaN) {
  DriftComparison c;
  c.bins.resize(2);
  c.bins[0].theta_rad = -M_PI / 4;
  c.bins[0].measured_ok = true;
  c.bins[0].measured.value = 1e-4;
  c.bins[0].measured.ci_low = 0.5e-4;
  c.bins[0].measured.ci_high = 1.5e-4;
  c.bins[0].predicted.value = 2e-4;
  c.bins[0].passes = 3;
  c.bins[1].theta_rad = 0.0;
  c.rms_measured_rad_s = 4e-4;
  c.rms_difference_rad_s = 1e-4;
  c.bins_measured = 1;
  const DriftMeasured m = driftComparisonToMsg(c, 0.95, ros::Time(5.0));
  const double dh = 180.0 / M_PI * 3600.0;
  ASSERT_EQ(m.theta_deg.size(), 2u);
  EXPECT_DOUBLE_EQ(m.theta_deg[0], -45.0);
  EXPECT_DOUBLE_EQ(m.measured_deg_h[0], 1e-4 * dh);
  EXPECT_DOUBLE_EQ(m.measured_ci_high_deg_h[0], 1.5e-4 * dh);
  EXPECT_DOUBLE_EQ(m.predicted_deg_h[0], 2e-4 * dh);
  EXPECT_EQ(m.passes[0], 3u);
  EXPECT_FALSE(m.measured_ok[1]);
  EXPECT_TRUE(std::isnan(m.measured_deg_h[1]));
  EXPECT_DOUBLE_EQ(m.compensation_gain, 4.0);
  EXPECT_EQ(m.bins_measured, 1u);
}

}  // namespace
}  // namespace cvg_bench

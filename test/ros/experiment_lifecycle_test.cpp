// Experiment lifecycle pieces without roscore: experiment boundaries (ExperimentTracker), the
// physical sanity checks of an estimate, and the raw free decay produced piece by piece.
#include <gtest/gtest.h>

#include <cmath>

#include "cvg_bench/core/simulate/experiment_runner.h"
#include "cvg_bench/core/simulate/measurement_noise.h"
#include "cvg_bench/ros/bench_markers.h"
#include "cvg_bench/ros/estimate_sanity.h"
#include "cvg_bench/ros/experiment_tracker.h"
#include "cvg_bench/ros/raw_free_decay_stream.h"

namespace cvg_bench {
namespace {

using B = ExperimentTracker::Boundary;

TEST(ExperimentTracker, NewEpochJumpBackAndStartEventEachStartAFreshExperiment) {
  ExperimentTracker t;
  const ros::Time e1(100, 0), e2(200, 0);
  EXPECT_EQ(t.onSample(e1, ros::Time(100, 5)), B::kFirst);
  EXPECT_EQ(t.id(), 1u);
  EXPECT_EQ(t.onSample(e1, ros::Time(100, 6)), B::kNone);
  EXPECT_EQ(t.onSample(e2, ros::Time(200, 1)), B::kNewEpoch);  // rerun: new phase epoch
  EXPECT_EQ(t.id(), 2u);
  EXPECT_EQ(t.start(), ros::Time(200, 1));
  EXPECT_EQ(t.onSample(e2, ros::Time(200, 0)), B::kJumpBack);  // looped bag
  EXPECT_EQ(t.jumpsBack(), 1u);
  EXPECT_EQ(t.id(), 3u);
  // Sweep points carry no epoch: the simulator's start event decides.
  t.onStartEvent(ros::Time(300, 0));
  EXPECT_EQ(t.onSample(ros::Time(), ros::Time(299, 0)), B::kNone);  // old sweep's last point
  EXPECT_EQ(t.onSample(ros::Time(), ros::Time(300, 0)), B::kStartEvent);
  EXPECT_EQ(t.id(), 4u);
  // A (latched) start event of the running experiment starts nothing.
  t.onStartEvent(ros::Time(300, 0));
  EXPECT_EQ(t.onSample(ros::Time(), ros::Time(301, 0)), B::kNone);
  EXPECT_EQ(t.id(), 4u);
}

Estimate estimateWith(double gamma, double gamma_se, double bc, double q, double q_lo) {
  Estimate e;
  e.names = {"gamma", "b_c", "b_s"};
  e.values = Eigen::Vector3d(gamma, bc, 0.0);
  e.parameters["gamma"] = {gamma, gamma_se, gamma - 2 * gamma_se, gamma + 2 * gamma_se};
  e.parameters["b_c"] = {bc, 0.01, bc - 0.02, bc + 0.02};
  e.parameters["b_s"] = {0.0, 0.01, -0.02, 0.02};
  e.derived["Q"] = {q, 1.0, q_lo, 2 * q - q_lo};
  e.derived["alpha_rad"] = {0.1, 0.01, 0.08, 0.12};
  return e;
}

TEST(EstimateSanity, PlausibleEstimatePasses) {
  EXPECT_TRUE(sanityProblems(estimateWith(43.0, 0.5, 1.3, 1993.0, 1970.0)).empty());
}

TEST(EstimateSanity, NegativeDampingAndQAreFlagged) {
  // The mixed-rerun estimate of the issue: gamma -0.25 +/- 0.02, Q -3.5e5.
  const auto p = sanityProblems(estimateWith(-0.25, 0.01, 0.0, -3.5e5, -3.6e5));
  ASSERT_EQ(p.size(), 2u);
  EXPECT_NE(p[0].find("damping gamma = -0.25 1/s is not positive"), std::string::npos) << p[0];
  EXPECT_NE(p[1].find("Q = -3.5e+05 is not positive"), std::string::npos) << p[1];
}

TEST(EstimateSanity, IntervalsWiderThanPhysicalAndNegativePrincipalDampingAreFlagged) {
  Estimate e = estimateWith(0.5, 0.4, 0.6, 100.0, -20.0);
  e.derived["beta_rad"] = {0.0, 1.0, -1.0, 1.0};  // 2 rad > pi/2
  const auto p = sanityProblems(e);
  ASSERT_EQ(p.size(), 4u);
  EXPECT_NE(p[0].find("gamma interval [-0.3, 1.3] 1/s reaches below 0"), std::string::npos) << p[0];
  EXPECT_NE(p[1].find("principal damping gamma - sqrt(b_c^2 + b_s^2) = -0.1 1/s"),
            std::string::npos)
      << p[1];
  EXPECT_NE(p[2].find("Q interval [-20, 220] reaches below 0"), std::string::npos) << p[2];
  EXPECT_NE(p[3].find("beta_rad interval is 2 rad wide"), std::string::npos) << p[3];
}

TEST(RawFreeDecayStream, PiecesJoinedEqualTheWholeRecord) {
  ResonatorPreset preset = loadShippedPreset("mems_ring");
  const double duration_s = 0.01;
  const std::uint64_t seed = 5;
  RawRecord whole = ExperimentRunner(preset).freeDecayRaw(duration_s);
  MeasurementNoise noise(seed);
  noise.addTo(whole, preset.noise_fg_std);
  RawFreeDecayStream stream(preset, duration_s, seed, OrbitElements());
  ASSERT_EQ(stream.total(), whole.size());  // 3001 samples at 300 kHz
  size_t i = 0;
  for (size_t piece_size : {1000u, 7u, 1500u, 100000u}) {
    const RawRecord piece = stream.next(piece_size);
    for (size_t k = 0; k < piece.size(); ++k, ++i) {
      EXPECT_NEAR(piece.t_s[k], whole.t_s[i], 1e-12);
      EXPECT_NEAR(piece.f[k], whole.f[i], 1e-9 * std::fabs(whole.f[i]) + 1e-12);
      EXPECT_NEAR(piece.g[k], whole.g[i], 1e-9 * std::fabs(whole.g[i]) + 1e-12);
    }
  }
  EXPECT_EQ(i, whole.size());
  EXPECT_EQ(stream.produced(), stream.total());
  EXPECT_EQ(stream.next(10).size(), 0u);
}

TEST(BenchMarkers, StandingWaveTurnsWithThePatternAngle) {
  BenchView v;
  v.have_state = true;
  v.r = 1.0;
  v.r_ref = 1.0;
  v.theta_rad = 0.3;
  const auto markers = benchMarkers(v).markers;
  const visualization_msgs::Marker* wave = nullptr;
  for (const auto& m : markers)
    if (m.ns == "standing_wave") wave = &m;
  ASSERT_NE(wave, nullptr);
  // Largest radius 1 + 0.3 at phi = theta (and theta + pi), smallest 0.7 at theta + pi/2.
  double best = 0.0, best_phi = 0.0;
  for (const auto& p : wave->points) {
    const double rad = std::hypot(p.x, p.y);
    if (rad > best) best = rad, best_phi = std::atan2(p.y, p.x);
  }
  EXPECT_NEAR(best, 1.3, 1e-3);
  EXPECT_NEAR(std::remainder(best_phi - 0.3, M_PI), 0.0, 2 * M_PI / 180 + 1e-9);
}

}  // namespace
}  // namespace cvg_bench

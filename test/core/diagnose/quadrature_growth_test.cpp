// The named cause of a growing ellipse (quadrature_growth.h): the model's k' split into the shares
// of its parameter groups, against (5.8) k' = (-gamma k + n r + h_m r sin 4(theta - alpha)
// + b_m k cos 4(theta - beta)) / 2 (test/core/model/paper_orbit_rates.h), and groups the
// covariance cannot tell apart reported as their sum.
#include "cvg_bench/core/diagnose/quadrature_growth.h"

#include <gtest/gtest.h>

#include <cmath>

#include "model/paper_orbit_rates.h"

namespace cvg_bench {
namespace {

UncertainParameters linearModel(double gamma, double n, double h_c, double sd) {
  UncertainParameters p;
  p.values = {{"gamma", gamma}, {"nu", 0.0}, {"b_c", 0.0}, {"b_s", 0.0},
              {"c_m", 0.0},     {"n", n},    {"h_c", h_c}, {"h_s", 0.0}};
  for (const auto& kv : p.values) p.cov_names.push_back(kv.first);
  p.covariance = Eigen::MatrixXd::Identity(8, 8) * sd * sd;
  p.dof = 100;
  return p;
}

const QuadratureShare* shareOf(const QuadratureGrowth& g, const std::string& meaning) {
  for (const QuadratureShare& s : g.shares)
    if (s.meaning == meaning) return &s;
  return nullptr;
}

TEST(QuadratureGrowth, AFrequencySplitWidensTheEllipseAndIsNamed) {
  // r = 1, k = 0.05, theta = pi/16: the split's share h_c r sin(pi/4) / 2 = 3.54e-3 amplitude/s
  // dominates the damping's -gamma k / 2 = -2.5e-5.
  const UncertainParameters p = linearModel(1e-3, 0.0, 0.01, 1e-5);
  const double theta = M_PI / 16;
  const ParameterEstimate measured{3.5e-3, 1e-4, 3.3e-3, 3.7e-3};
  const QuadratureGrowth g = explainQuadratureGrowth(p, 1.0, 0.05, theta, measured);
  ASSERT_TRUE(g.valid) << g.why_not;
  EXPECT_NEAR(g.predicted_widening.value,
              orbitRates(OrbitElements{1.0, 0.05, theta, 0.0}, p.values).k_dot, 1e-10);
  const QuadratureShare* split = shareOf(g, "frequency split");
  ASSERT_NE(split, nullptr);
  EXPECT_NEAR(split->widening.value, 0.5 * 0.01 * std::sin(M_PI / 4), 1e-9);
  EXPECT_TRUE(split->determined);
  const QuadratureShare* damping = shareOf(g, "damping");
  ASSERT_NE(damping, nullptr);
  EXPECT_NEAR(damping->widening.value, -0.5 * 1e-3 * 0.05, 1e-10);
  ASSERT_FALSE(g.named.empty());
  EXPECT_EQ(g.named.front(), "frequency split");
  // nu and c_m do not enter k' (5.8): no share.
  EXPECT_EQ(shareOf(g, "rotation term"), nullptr);
  EXPECT_EQ(shareOf(g, "mean frequency offset"), nullptr);
}

TEST(QuadratureGrowth, ANegativeKWidensWhenKFalls) {
  // k < 0: |k| grows when k' < 0; with the split at theta = -pi/16 the share flips sign with k'.
  const UncertainParameters p = linearModel(1e-3, 0.0, 0.01, 1e-5);
  const ParameterEstimate measured{-3.5e-3, 1e-4, -3.7e-3, -3.3e-3};
  const QuadratureGrowth g = explainQuadratureGrowth(p, 1.0, -0.05, -M_PI / 16, measured);
  ASSERT_TRUE(g.valid);
  EXPECT_GT(g.measured_widening.value, 0.0);
  EXPECT_NEAR(g.measured_widening.ci_low, 3.3e-3, 1e-15);
  EXPECT_GT(g.predicted_widening.value, 0.0);
  ASSERT_FALSE(g.named.empty());
  EXPECT_EQ(g.named.front(), "frequency split");
}

TEST(QuadratureGrowth, GroupsTheRecordCannotTellApartAreReportedAsTheirSum) {
  // n and h_c nearly collinear (correlation -0.99999, as one swing at one azimuth gives): their
  // shares alone are not determined, their sum is, and it is one share.
  UncertainParameters p = linearModel(1e-3, 0.004, 0.006, 1e-5);
  // cov_names is the map's order: b_c b_s c_m gamma h_c h_s n nu.
  ASSERT_EQ(p.cov_names[4], "h_c");
  ASSERT_EQ(p.cov_names[6], "n");
  p.covariance(4, 4) = p.covariance(6, 6) = 1e-2 * 1e-2;
  p.covariance(4, 6) = p.covariance(6, 4) = -0.99999 * 1e-2 * 1e-2;
  const ParameterEstimate measured{5e-3, 1e-4, 4.8e-3, 5.2e-3};
  const QuadratureGrowth g = explainQuadratureGrowth(p, 1.0, 0.05, M_PI / 8, measured);
  ASSERT_TRUE(g.valid);
  const QuadratureShare* both = shareOf(g, "position (circulatory) forces + frequency split");
  ASSERT_NE(both, nullptr) << g.summary;
  EXPECT_EQ(both->parameters.size(), 3u);  // n, h_c, h_s
  EXPECT_EQ(shareOf(g, "frequency split"), nullptr);
  // At theta = pi/8, sin 4 theta = 1: the sum's share (n + h_c) r / 2 = 5e-3, determined.
  EXPECT_NEAR(both->widening.value, 0.5 * (0.004 + 0.006), 1e-9);
  EXPECT_TRUE(both->determined);
  ASSERT_FALSE(g.named.empty());
  EXPECT_EQ(g.named.front(), "position (circulatory) forces + frequency split");
}

TEST(QuadratureGrowth, WithoutACovarianceOrAtATravellingWaveItSaysWhyNot) {
  UncertainParameters p = linearModel(1e-3, 0.0, 0.01, 1e-5);
  EXPECT_FALSE(explainQuadratureGrowth(p, 1.0, 1.0, 0.0, {}).valid);
  p.cov_names.clear();
  const QuadratureGrowth g = explainQuadratureGrowth(p, 1.0, 0.05, 0.0, {});
  EXPECT_FALSE(g.valid);
  EXPECT_FALSE(g.why_not.empty());
}

}  // namespace
}  // namespace cvg_bench

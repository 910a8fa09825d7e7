// Delta-method intervals of derived quantities and of the drift rate (5.9).
#include "cvg_bench/core/estimate/uncertainty/derived_uncertainty.h"

#include <gtest/gtest.h>

#include <cmath>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/estimate/uncertainty/student_t.h"
#include "cvg_bench/core/model/orbit_elements.h"
#include "model/paper_orbit_rates.h"

namespace cvg_bench {
namespace {

UncertainParameters example() {
  UncertainParameters p;
  p.values = {{"gamma", 43.029}, {"nu", 2.029},   {"b_c", 1.332},
              {"b_s", -1.389},   {"c_m", 24.358}, {"n", 1.173},
              {"h_c", -12.797},  {"h_s", 11.588}, {"xi", 18.217}};
  for (const auto& kv : p.values) p.cov_names.push_back(kv.first);
  const int n = static_cast<int>(p.cov_names.size());
  p.covariance = Eigen::MatrixXd::Identity(n, n) * 0.01;
  p.covariance(0, 1) = p.covariance(1, 0) = 0.004;  // b_c, b_s (alphabetical order of the map)
  p.dof = 50;
  return p;
}

TEST(DerivedUncertainty, LinearAndSimpleQuantitiesHaveTheirExactErrors) {
  const UncertainParameters p = example();
  const auto d = deriveQuantitiesWithIntervals(p, 85732.0, 0.4);
  // Omega = nu / (4K): se = 0.1 / 1.6; Q = omega / gamma: se = omega / gamma^2 * 0.1.
  EXPECT_NEAR(d.at("zero_rate_rad_s").std_error, 0.1 / 1.6, 1e-9);
  EXPECT_NEAR(d.at("Q").std_error, 85732.0 / (43.029 * 43.029) * 0.1, 1e-6);
  const double s = studentQuantile(0.95, 50);
  EXPECT_NEAR(d.at("Q").ci_high - d.at("Q").value, s * d.at("Q").std_error, 1e-9);
  // Damping anisotropy 2 sqrt(b_c^2 + b_s^2): gradient 2 (b_c, b_s) / b_m.
  const double bm = std::hypot(1.332, -1.389);
  const Eigen::Vector2d g(2 * 1.332 / bm, 2 * -1.389 / bm);
  Eigen::Matrix2d c;
  c << 0.01, 0.004, 0.004, 0.01;
  EXPECT_NEAR(d.at("damping_anisotropy_1_s").std_error, std::sqrt(g.dot(c * g)), 1e-8);
}

TEST(DerivedUncertainty, DriftRateIntervalFollowsNu) {
  UncertainParameters p = example();
  // Only nu uncertain: d theta' / d nu = -1/4 exactly.
  p.covariance.setZero();
  int idx = -1;
  for (int j = 0; j < static_cast<int>(p.cov_names.size()); ++j)
    if (p.cov_names[j] == "nu") idx = j;
  ASSERT_GE(idx, 0);
  p.covariance(idx, idx) = 0.04;
  const ParameterEstimate r = driftRateWithInterval(1.0, 0.05, 0.3, p);
  EXPECT_NEAR(r.value, driftRate(1.0, 0.05, 0.3, p.values), 1e-15);
  EXPECT_NEAR(r.std_error, 0.25 * 0.2, 1e-9);
}

TEST(DerivedUncertainty, WindowMeanDriftIsTheMeanWithTheMeansInterval) {
  const UncertainParameters p = example();
  const std::vector<OrbitElements> states{{1.0, 0.05, 0.3, 0.0}, {0.6, 0.02, -0.5, 0.0}};
  const ParameterEstimate a = driftRateWithInterval(1.0, 0.05, 0.3, p);
  const ParameterEstimate b = driftRateWithInterval(0.6, 0.02, -0.5, p);
  const ParameterEstimate m = meanDriftRateWithInterval(states, p);
  EXPECT_NEAR(m.value, 0.5 * (a.value + b.value), 1e-15);
  // Correlated through the shared parameters: the mean's error lies between |a - b| / 2 and the
  // mean of the two (equality at the ends of perfect correlation); nu alone shifts both by -nu/4.
  EXPECT_LE(m.std_error, 0.5 * (a.std_error + b.std_error) + 1e-12);
  EXPECT_GE(m.std_error, 0.5 * std::fabs(a.std_error - b.std_error) - 1e-12);
  // The drift of one state is its own mean.
  const ParameterEstimate one = meanDriftRateWithInterval({states[0]}, p);
  EXPECT_NEAR(one.value, a.value, 1e-15);
  EXPECT_NEAR(one.std_error, a.std_error, 1e-12);
  EXPECT_THROW(meanDriftRateWithInterval({}, p), InputError);
}

Estimate estimateOf(const UncertainParameters& p) {
  Estimate e;
  e.names = p.cov_names;
  e.values.resize(static_cast<Eigen::Index>(e.names.size()));
  for (size_t j = 0; j < e.names.size(); ++j) e.values[j] = p.values.at(e.names[j]);
  e.covariance = p.covariance;
  e.n_params = e.rank = static_cast<int>(e.names.size());
  e.confidence = 0.95;
  e.interval_dof = p.dof;
  return e;
}

// Issue #25: a figure derived from a parameter the record does not identify is not printed as a
// number; the figures that do not need it stay, with the same values.
TEST(DerivedUncertainty, FiguresOfAParameterNotIdentifiedAreNotReported) {
  Estimate e = estimateOf(example());
  deriveFromIdentified(&e, 85732.0, 0.4);
  const auto all = e.derived;
  ASSERT_TRUE(all.count("frequency_split_hz") && all.count("zero_rate_rad_s"));
  e.not_identified = {"h_c"};
  deriveFromIdentified(&e, 85732.0, 0.4);
  deriveFromIdentified(&e, 85732.0, 0.4);  // said once
  for (const char* k : {"frequency_split_hz", "frequency_split_rad_s", "alpha_rad"})
    EXPECT_EQ(e.derived.count(k), 0u) << k;
  for (const char* k :
       {"zero_rate_rad_s", "frequency_error_hz", "damping_anisotropy_1_s", "beta_rad", "Q"}) {
    ASSERT_EQ(e.derived.count(k), 1u) << k;
    EXPECT_DOUBLE_EQ(e.derived.at(k).value, all.at(k).value) << k;
  }
  int notes = 0;
  for (const auto& n : e.notes)
    notes += n ==
             "frequency_split_hz not reported: it depends on h_c, which this record does "
             "not identify";
  EXPECT_EQ(notes, 1);
}

}  // namespace
}  // namespace cvg_bench

// The one-mode stationary response (response_model.h): the linear case is the Lorentzian in closed
// form; the cubic's stable roots satisfy u |D(u)|^2 = |d a|^2 with the middle root dropped; along a
// sweep the branch is followed in time order, so a softening resonance swept down stays on the
// upper branch where the up sweep is on the lower one, and each sweep through the fold jumps once.
#include "cvg_bench/core/single_mode/response_model.h"

#include <gtest/gtest.h>

#include <cmath>

namespace cvg_bench {
namespace {

using cd = std::complex<double>;

ResponseParams params(double xi, double g) {
  ResponseParams p;
  p.f0_hz = 100.0;
  p.width_hz = 1.0;
  p.gain = cd(100.0, 0.0);  // peak amplitude |a| / (f0 w) = 1 at unit drive
  p.backbone_hz_per_amp2 = xi;
  p.width_growth_hz_per_amp2 = g;
  p.f_ref_hz = 100.0;
  return p;
}

ResponseData sweep(double f_lo, double f_hi, int n, bool up_then_down) {
  ResponseData d;
  for (int k = 0; k < n; ++k) {
    d.frequency_hz.push_back(f_lo + (f_hi - f_lo) * k / (n - 1));
    d.sweep.push_back(0);
  }
  if (up_then_down)
    for (int k = n - 1; k >= 0; --k) {
      d.frequency_hz.push_back(f_lo + (f_hi - f_lo) * k / (n - 1));
      d.sweep.push_back(1);
    }
  d.drive.assign(d.frequency_hz.size(), 1.0);
  d.z.assign(d.frequency_hz.size(), cd(0.0, 0.0));
  return d;
}

TEST(ResponseModel, LinearIsTheLorentzianWithBackground) {
  ResponseParams p = params(0.0, 0.0);
  p.bg0 = cd(0.1, -0.2);
  p.bg1 = cd(0.01, 0.0);
  ResponseData d = sweep(95.0, 105.0, 21, false);
  d.drive.assign(d.size(), 2.0);
  const std::vector<cd> z = stationaryResponse(p, d);
  for (size_t i = 0; i < d.size(); ++i) {
    const double f = d.frequency_hz[i];
    const cd want = 2.0 * (p.bg0 + p.bg1 * (f - 100.0)) + 2.0 * p.gain / cd(1e4 - f * f, f);
    EXPECT_NEAR(std::abs(z[i] - want), 0.0, 1e-12);
  }
  // Velocity: the resonant part carries f / f0.
  d.kind = ResponseKind::kVelocity;
  const std::vector<cd> v = stationaryResponse(p, d);
  const double f = d.frequency_hz[3];
  EXPECT_NEAR(std::abs(v[3] - (2.0 * (p.bg0 + p.bg1 * (f - 100.0)) +
                               2.0 * p.gain * (f / 100.0) / cd(1e4 - f * f, f))),
              0.0, 1e-12);
}

TEST(ResponseModel, StableRootsSolveTheCubicAndSkipTheMiddleOne) {
  const ResponseParams p = params(-3.0, 0.0);  // shift of 3 widths at unit amplitude
  const double power = 1e4;                    // |d a|^2 at unit drive
  // Inside the bistable band of a softening resonance (below f0): two stable roots.
  const std::vector<double> two = stableSquaredAmplitudes(p, 98.0, power);
  ASSERT_EQ(two.size(), 2u);
  for (double u : two) {
    const cd D(1e4 - 98.0 * 98.0 + 2 * 100.0 * -3.0 * u, 98.0 * 1.0);
    EXPECT_NEAR(u * std::norm(D) / power, 1.0, 1e-9);
    // Stable: u |D|^2 rises with u there.
    const double du = 1e-6;
    const cd D2(1e4 - 98.0 * 98.0 + 2 * 100.0 * -3.0 * (u + du), 98.0);
    EXPECT_GT((u + du) * std::norm(D2), u * std::norm(D));
  }
  EXPECT_LT(two[0], 0.2);
  EXPECT_GT(two[1], 0.5);
  // Far from resonance: one root, the linear one to first order.
  const std::vector<double> one = stableSquaredAmplitudes(p, 110.0, power);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_NEAR(one[0], power / std::norm(cd(1e4 - 110.0 * 110.0, 110.0)), 2e-3 * one[0]);
}

TEST(ResponseModel, BranchFollowingMakesHysteresisAndOneJumpPerSweep) {
  const ResponseParams p = params(-3.0, 0.0);
  const ResponseData d = sweep(94.0, 102.0, 161, true);
  std::vector<double> u;
  int jumps = 0;
  stationaryResponse(p, d, &u, &jumps);
  EXPECT_EQ(jumps, 2);  // up: lower -> upper branch; down: upper -> lower
  // At 98 Hz: the up sweep (k = 80) is on the lower branch, the down sweep on the upper one.
  const size_t up = 80, down = 2 * 161 - 1 - 80;
  ASSERT_NEAR(d.frequency_hz[up], 98.0, 1e-9);
  ASSERT_NEAR(d.frequency_hz[down], 98.0, 1e-9);
  EXPECT_LT(u[up], 0.2);
  EXPECT_GT(u[down], 0.5);
  // The peak of the down sweep lies on the backbone f0 + xi u (within one frequency step).
  size_t imax = 161;
  for (size_t i = 161; i < d.size(); ++i)
    if (u[i] > u[imax]) imax = i;
  EXPECT_NEAR(d.frequency_hz[imax], 100.0 - 3.0 * u[imax], 0.06);
  // The peak amplitude is |a| / (f w) at the shifted peak frequency f.
  EXPECT_NEAR(u[imax], std::pow(100.0 / d.frequency_hz[imax], 2), 0.01);
}

TEST(ResponseModel, WidthGrowthLowersAndWidensThePeak) {
  const ResponseData d = sweep(95.0, 105.0, 201, false);
  std::vector<double> u_lin, u_nl;
  stationaryResponse(params(0.0, 0.0), d, &u_lin);
  stationaryResponse(params(0.0, 1.0), d, &u_nl);  // width 1 -> 1 + u
  // At f0 the amplitude solves u (1 + u)^2 = 1 (f0 = f = 100, width (1 + u) f): u = 0.4656.
  EXPECT_NEAR(u_lin[100], 1.0, 1e-9);
  EXPECT_NEAR(u_nl[100], 0.465571, 1e-5);
  // Far out on the wings the amplitude law does not matter.
  EXPECT_NEAR(u_nl[0] / u_lin[0], 1.0, 0.03);
}

TEST(ResponseModel, TermNames) {
  EXPECT_EQ(parseResponseTerms("linear").name(), "linear");
  EXPECT_EQ(parseResponseTerms("gamma_nl+xi").name(), "xi+gamma_nl");
  EXPECT_THROW(parseResponseTerms("xi_diff"), std::exception);
  EXPECT_THROW(parseResponseTerms("mu"), std::exception);
}

}  // namespace
}  // namespace cvg_bench

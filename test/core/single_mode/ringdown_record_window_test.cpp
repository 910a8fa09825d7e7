// Known-answer tests of the real-export window (ringdown_record_window.h) on envelopes shaped like
// the development set's records: floor before the drive, switch-off steps, out-of-band drops.
#include "cvg_bench/core/single_mode/ringdown_record_window.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace cvg_bench {
namespace {

constexpr double kNeperPerDb = 2.302585092994046 / 20.0;

/// A record in dB sampled at 1 s: level(t) piecewise, plus 0.3 dB white noise; returned as ln A.
struct Rec {
  std::vector<double> t, y;
};
template <class F>
Rec make(int n, F level, unsigned seed = 1) {
  std::mt19937 g(seed);
  std::normal_distribution<double> e(0.0, 0.3);
  Rec r;
  for (int i = 0; i < n; ++i) {
    r.t.push_back(i);
    r.y.push_back((level(double(i)) + e(g)) * kNeperPerDb);
  }
  return r;
}

TEST(RingdownWindow, APlainRecordIsKeptWhole) {
  const Rec r =
      make(600, [](double t) { return t < 100 ? 0.0 : std::max(-0.3 * (t - 100), -80.0); });
  const RingdownWindow w = findRingdownWindow(r.t, r.y);
  EXPECT_EQ(w.first, 0u);
  EXPECT_EQ(w.last, 600u);
  EXPECT_TRUE(w.why.empty());
}

TEST(RingdownWindow, ARecordStartingAtTheFloorStartsAtTheDriveLevel) {
  // floor -80 dB until 100 s, ramp to 0 dB by 150 s, plateau to 200 s, decay 0.3 dB/s to -80.
  const Rec r = make(800, [](double t) {
    if (t < 100) return -80.0;
    if (t < 150) return -80.0 + 80.0 * (t - 100) / 50;
    if (t < 200) return 0.0;
    return std::max(-0.3 * (t - 200), -80.0);
  });
  const RingdownWindow w = findRingdownWindow(r.t, r.y);
  EXPECT_GE(w.first, 146u);  // last rise through -3 dB at 148 s
  EXPECT_LE(w.first, 150u);
  EXPECT_EQ(w.last, 800u);
  EXPECT_NE(w.why.find("under the drive level"), std::string::npos);
}

TEST(RingdownWindow, ASwitchOffStepIsSkippedAndAnOutOfBandDropEndsTheWindow) {
  // plateau 0 dB to 100 s, a 15 dB step at switch-off, decay 0.2 dB/s, at 250 s a 50 dB drop.
  const Rec r = make(500, [](double t) {
    if (t < 100) return 0.0;
    if (t < 250) return -15.0 - 0.2 * (t - 100);
    return -95.0;
  });
  const RingdownWindow w = findRingdownWindow(r.t, r.y);
  // The first sample after the step, to within the medians' half-width of 3 samples.
  EXPECT_GE(w.first, 100u);
  EXPECT_LE(w.first, 102u);
  EXPECT_GE(w.last, 240u);
  EXPECT_LE(w.last, 250u);
  EXPECT_NE(w.why.find("switch-off"), std::string::npos);
  EXPECT_NE(w.why.find("leaves the detector"), std::string::npos);
}

TEST(RingdownWindow, ASmoothGainStepOfTheGeneratorIsNoStep) {
  // The generator's detection loss: 10 dB over ~20 samples, mid-decay.
  const Rec r = make(600, [](double t) {
    const double base = t < 50 ? 0.0 : -0.2 * (t - 50);
    return base - 10.0 / (1.0 + std::exp(-(t - 300) / 5.0));
  });
  const RingdownWindow w = findRingdownWindow(r.t, r.y);
  EXPECT_EQ(w.first, 0u);
  EXPECT_EQ(w.last, 600u);
}

TEST(RingdownWindow, ADrivePulseAfterTheDecayLeavesTheDecayBeforeIt) {
  // D154/D167 of the development set: plateau 0 dB to 50 s, decay 0.3 dB/s to a -60 dB floor,
  // the drive on again 400-430 s (1 dB higher: the peak lies in the pulse), then a step out of
  // the band to -70 dB falling 0.02 dB/s: a 5 dB stub of "decay" after the pulse.
  const Rec r = make(700, [](double t) {
    if (t < 50) return 0.0;
    if (t < 400) return std::max(-0.3 * (t - 50), -60.0);
    if (t < 430) return 1.0;
    return -70.0 - 0.02 * (t - 430);
  });
  const RingdownWindow w = findRingdownWindow(r.t, r.y);
  EXPECT_EQ(w.first, 0u);
  EXPECT_GE(w.last, 394u);  // up to the pulse, less the medians' half-width
  EXPECT_LE(w.last, 400u);
  EXPECT_NE(w.why.find("before the drive came on again"), std::string::npos) << w.why;
}

TEST(RingdownWindow, ARerunWithAFullDecayIsReadLast) {
  // Two full ring-downs: the last is read (the earlier one falls no further).
  const Rec r = make(800, [](double t) {
    if (t < 50) return 0.0;
    if (t < 350) return std::max(-0.3 * (t - 50), -60.0);
    if (t < 400) return 0.0;
    return std::max(-0.3 * (t - 400), -60.0);
  });
  const RingdownWindow w = findRingdownWindow(r.t, r.y);
  EXPECT_GE(w.first, 348u);
  EXPECT_LE(w.first, 352u);
  EXPECT_EQ(w.last, 800u);
  EXPECT_NE(w.why.find("the last ring-down is read"), std::string::npos) << w.why;
}

TEST(RingdownWindow, ADriveToggledOnThroughARampIsAReexcitation) {
  // D197 of the development set: the drive toggles between 0 dB and a -60 dB decay, each change
  // a 24-sample ramp through the detector's filter (a 3-sample comparison reads it as a slope);
  // after the last toggle a 0.1 dB/s decay. The window starts at the last rise, not before the
  // toggles (where the earlier plateaus and ramps sit inside the "decay").
  auto ramp = [](double t, double t0, double from, double to) {
    const double u = std::min(1.0, std::max(0.0, (t - t0) / 24.0));
    return from + (to - from) * u;
  };
  const Rec r = make(1400, [&](double t) {
    if (t < 100) return 0.0;
    if (t < 250) return ramp(t, 100, 0.0, -60.0);
    if (t < 400) return ramp(t, 250, -60.0, 0.0);
    if (t < 550) return ramp(t, 400, 0.0, -60.0);
    if (t < 700) return ramp(t, 550, -60.0, 0.0);
    return ramp(t, 700, 0.0, -60.0) - 0.1 * std::max(0.0, t - 724);
  });
  const RingdownWindow w = findRingdownWindow(r.t, r.y);
  EXPECT_GE(w.first, 550u) << w.why;  // after the last rise's first sample ...
  EXPECT_LE(w.first, 700u) << w.why;  // ... and before the last switch-off
  EXPECT_EQ(w.last, 1400u);
  EXPECT_NE(w.why.find("the drive comes on again at 57"), std::string::npos) << w.why;
  // Without the ramp reading the last rise is not seen (what the tool did before 29 Nov).
  RingdownWindowOptions sharp_only;
  sharp_only.ramp_scale = 1;
  EXPECT_EQ(findRingdownWindow(r.t, r.y, sharp_only).why.find("comes on again at 57"),
            std::string::npos);
}

TEST(RingdownWindow, AFastFallIsNotARamp) {
  // A decay whose first 40 dB fall at 2 dB/sample (a fast first stage) then 0.05 dB/s: no step,
  // the window is the whole record (D201, D204 of the development set).
  const Rec r = make(1000, [](double t) {
    if (t < 100) return 0.0;
    if (t < 120) return -2.0 * (t - 100);
    return -40.0 - 0.05 * (t - 120);
  });
  const RingdownWindow w = findRingdownWindow(r.t, r.y);
  EXPECT_EQ(w.first, 0u) << w.why;
  EXPECT_EQ(w.last, 1000u) << w.why;
}

}  // namespace
}  // namespace cvg_bench

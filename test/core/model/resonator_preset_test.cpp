// Every shipped preset loads and validates; mems_ring is the paper's section-4 estimate; bad preset
// files list every problem at once; effects set the truth model.
#include "cvg_bench/core/model/resonator_preset.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace {

TEST(ResonatorPreset, EveryShippedPresetLoadsAndValidates) {
  const auto names = shippedPresetNames();
  for (const char* required : {"mems_ring", "hrg_hemispherical", "quartz_cylinder"})
    EXPECT_NE(std::find(names.begin(), names.end(), required), names.end()) << required;
  for (const auto& name : names) {
    const ResonatorPreset p = loadShippedPreset(name);
    EXPECT_EQ(p.name, name);
    EXPECT_TRUE(p.validate().empty());
    EXPECT_NO_THROW(
        ResonatorModel(p.truthModelSpec(ExperimentMode::kForced), ExperimentMode::kForced));
    EXPECT_NO_THROW(
        ResonatorModel(p.truthModelSpec(ExperimentMode::kFreeDecay), ExperimentMode::kFreeDecay));
  }
}

TEST(ResonatorPreset, MemsRingIsThePapersSectionFourEstimate) {
  const ResonatorPreset p = loadShippedPreset("mems_ring");
  EXPECT_EQ(p.omega_rad_s, 85732.0);
  const ParameterValues expected = {{"gamma", 43.029}, {"nu", 2.029},   {"b_c", 1.332},
                                    {"b_s", -1.389},   {"c_m", 24.358}, {"n", 1.173},
                                    {"h_c", -12.797},  {"h_s", 11.588}, {"xi", 18.217}};
  for (const auto& kv : expected) EXPECT_EQ(p.parameters.at(kv.first), kv.second) << kv.first;
  EXPECT_EQ(p.drive_u_tilde, Eigen::Vector4d(32.159, 30.597, 1.415, -0.605));
  EXPECT_EQ(p.sweep_points, 61);
  EXPECT_EQ(p.truthModelSpec(ExperimentMode::kForced), "linear+xi");
}

TEST(ResonatorPreset, BadFileListsEveryProblem) {
  const std::string path = ::testing::TempDir() + "bad_preset.yaml";
  {
    std::ofstream out(path);
    out << "omega_rad_s: -5\nparameters:\n  gamma: .nan\n  zeta: 1\ncolour: red\n"
           "forced:\n  points: many\n";
  }
  try {
    loadResonatorPresetFile(path);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("omega_rad_s must be > 0"), std::string::npos) << m;
    EXPECT_NE(m.find("unknown key 'zeta' in parameters"), std::string::npos) << m;
    EXPECT_NE(m.find("unknown key 'colour'"), std::string::npos) << m;
    EXPECT_NE(m.find("parameters.gamma is not finite"), std::string::npos) << m;
    EXPECT_NE(m.find(":7:11: forced.points must be an integer"), std::string::npos) << m;
    EXPECT_NE(m.find("free_decay.duration_s must be > 0"), std::string::npos) << m;
  }
  {
    std::ofstream out(path);
    out << "parameters: [1, 2\n";
  }
  EXPECT_THROW(loadResonatorPresetFile(path), InputError);
  EXPECT_THROW(loadShippedPreset("no_such_preset"), InputError);
}

TEST(ResonatorPreset, EffectsSetTheTruthModel) {
  ResonatorPreset p = loadShippedPreset("hrg_hemispherical");
  p.applyEffect("gamma_nl=1e-4");
  p.applyEffect("cm_rate", 1e-5);
  p.applyEffect("mu=0.1");
  p.applyEffect("u3=0.002");
  EXPECT_EQ(p.truthModelSpec(ExperimentMode::kFreeDecay), "linear+xi+gamma_nl+cm_rate");
  EXPECT_THROW(p.truthModelSpec(ExperimentMode::kForced), InputError);  // cm_rate: free decay only
  EXPECT_EQ(p.mu, 0.1);
  EXPECT_EQ(p.drive_u_tilde[2], 0.002);
  EXPECT_THROW(p.applyEffect("zeta=1"), InputError);
  EXPECT_THROW(p.applyEffect("xi=abc"), InputError);
  EXPECT_THROW(p.applyEffect("xi"), InputError);
  EXPECT_THROW(p.applyEffect("eta=-1"), InputError);
  const auto names = effectNames();
  for (const char* n : {"gamma_nl", "cm_rate", "xi_diff", "xi", "kappa", "mu", "eta", "u4"})
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
}

}  // namespace
}  // namespace cvg_bench

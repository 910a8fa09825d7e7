// Node settings: every shipped config/*.yaml loads and validates; a bad file is refused with ALL
// its problems listed (wrong types, unknown keys, out-of-range values) in one InputError.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/ros/demodulator_node_options.h"
#include "cvg_bench/ros/identifier_node_options.h"
#include "cvg_bench/ros/simulator_node_options.h"

namespace cvg_bench {
namespace {

std::string configPath(const std::string& name) {
  return std::string(CVG_BENCH_SOURCE_DIR) + "/config/" + name;
}

template <class T>
T loadFile(const std::string& path) {
  ParamReader reader = ParamReader::fromYamlFile(path);
  return loadOptions<T>(reader);
}

std::string writeTemp(const std::string& text) {
  const std::string path = testing::TempDir() + "cvg_options_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(path) << text;
  return path;
}

TEST(NodeOptions, ShippedConfigsLoad) {
  const SimulatorNodeOptions sim = loadFile<SimulatorNodeOptions>(configPath("simulator.yaml"));
  EXPECT_EQ(sim.preset, "mems_ring");
  const DemodulatorNodeOptions demod =
      loadFile<DemodulatorNodeOptions>(configPath("demodulator.yaml"));
  EXPECT_DOUBLE_EQ(demod.filter.output_rate_hz, 2000.0);
  const IdentifierNodeOptions ident =
      loadFile<IdentifierNodeOptions>(configPath("identifier.yaml"));
  EXPECT_EQ(ident.identification.model, "linear");
  EXPECT_DOUBLE_EQ(ident.identification.confidence, 0.95);
}

TEST(NodeOptions, DefaultsAreValid) {
  EXPECT_TRUE(SimulatorNodeOptions().validate().empty());
  EXPECT_TRUE(DemodulatorNodeOptions().validate().empty());
  EXPECT_TRUE(IdentifierNodeOptions().validate().empty());
}

TEST(NodeOptions, AllProblemsListedAtOnce) {
  const std::string path = writeTemp(
      "mode: sideways\n"
      "model: linear+warp\n"
      "confidence: 1.5\n"
      "min_samples: two\n"
      "window_s: -1\n"
      "windw_s: 3\n");
  try {
    loadFile<IdentifierNodeOptions>(path);
    FAIL() << "bad identifier settings accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    for (const char* expected :
         {"min_samples", "windw_s", "mode", "model", "confidence", "window_s"})
      EXPECT_NE(msg.find(expected), std::string::npos) << "missing '" << expected << "' in:\n"
                                                       << msg;
    EXPECT_NE(msg.find(path + ":4"), std::string::npos) << msg;  // the wrong type's line
  }
}

TEST(NodeOptions, SimulatorAndDemodulatorRanges) {
  SimulatorNodeOptions sim;
  sim.realtime_factor = 0.0;
  sim.autostart = "maybe";
  sim.publish_raw = sim.publish_slow = false;
  EXPECT_EQ(sim.validate().size(), 3u);

  DemodulatorNodeOptions demod;
  demod.omega_rad_s = 2 * M_PI * 5000.0;
  demod.sample_rate_hz = 8000.0;  // below the Nyquist rate of 5 kHz
  demod.queue_size = 0;
  const auto problems = demod.validate();
  EXPECT_GE(problems.size(), 2u);
  bool filter_problem = false;
  for (const auto& p : problems) filter_problem = filter_problem || p.rfind("filter: ", 0) == 0;
  EXPECT_TRUE(filter_problem);
}

TEST(NodeOptions, YamlSyntaxErrorNamesTheLine) {
  const std::string path = writeTemp("mode: free_decay\nmodel: [unclosed\n");
  try {
    loadFile<IdentifierNodeOptions>(path);
    FAIL() << "broken YAML accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace cvg_bench

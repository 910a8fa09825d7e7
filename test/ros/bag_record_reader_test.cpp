// Bag input of the offline tool: bags written here with the rosbag API are read back into records;
// every malformed case is an InputError that says what is wrong.
#include "cvg_bench/ros/bag_record_reader.h"

#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <std_msgs/Float64.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/ros/conversions.h"

namespace cvg_bench {
namespace {

std::string tempBag(const std::string& name) {
  return testing::TempDir() + "cvg_bag_reader_" + std::to_string(getpid()) + "_" + name + ".bag";
}

const ros::Time kStart(1700000000, 500000000);

Eigen::Vector4d slowAt(int i) {
  return Eigen::Vector4d(1.0 - 0.01 * i, 0.02 * i, 0.1, -0.05 * i);
}

void writeSlow(rosbag::Bag& bag, const std::string& topic, int n) {
  for (int i = 0; i < n; ++i) {
    const ros::Time stamp = timeAfter(kStart, 0.01 * i);
    bag.write(topic, stamp, slowStateToMsg(slowAt(i), stamp, kStart, 5000.0));
  }
}

std::string expectInputError(const std::string& path, const BagReadOptions& options = {}) {
  try {
    readRecordBag(path, options);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError for " << path;
  return "";
}

TEST(BagRecordReader, SlowStatesBecomeAFreeDecayRecord) {
  const std::string path = tempBag("slow");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    writeSlow(bag, "/cvg/slow", 25);
    std_msgs::Float64 other;
    bag.write("/unrelated", kStart, other);
  }
  const AnyRecord rec = readRecordBag(path);
  ASSERT_EQ(rec.kind, RecordKind::kFreeDecay);
  ASSERT_EQ(rec.slow.size(), 25u);
  EXPECT_DOUBLE_EQ(rec.slow.omega_rad_s, 5000.0);
  EXPECT_EQ(rec.slow.metadata.at("topic"), "/cvg/slow");
  EXPECT_EQ(rec.slow.metadata.at("stamp_origin"), "1700000000.500000000");
  for (int i = 0; i < 25; ++i) {
    EXPECT_NEAR(rec.slow.t_s[i], 0.01 * i, 1e-9);
    EXPECT_EQ(rec.slow.q[i], slowAt(i));
  }
  std::remove(path.c_str());
}

TEST(BagRecordReader, RawBatchesAreConcatenatedFromThePhaseEpoch) {
  const std::string path = tempBag("raw");
  RawRecord raw;
  raw.omega_rad_s = 31416.0;
  const double rate = 10000.0;
  for (int i = 0; i < 300; ++i) {
    raw.t_s.push_back(0.25 + i / rate);  // the experiment started 0.25 s before the first sample
    raw.f.push_back(std::sin(0.1 * i));
    raw.g.push_back(std::cos(0.2 * i));
  }
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    for (size_t b = 0; b < 300; b += 100) {
      const RawSampleBatch msg = rawBatchToMsg(raw, b, b + 100, kStart, rate);
      bag.write("/cvg/raw", msg.header.stamp, msg);
    }
  }
  BagReadOptions options;
  options.kinds = {RecordKind::kRaw};
  const AnyRecord rec = readRecordBag(path, options);
  ASSERT_EQ(rec.kind, RecordKind::kRaw);
  ASSERT_EQ(rec.raw.size(), 300u);
  EXPECT_DOUBLE_EQ(rec.raw.omega_rad_s, 31416.0);
  for (size_t i = 0; i < 300; ++i) {
    EXPECT_NEAR(rec.raw.t_s[i], raw.t_s[i], 1e-9);
    EXPECT_EQ(rec.raw.f[i], raw.f[i]);
  }
  EXPECT_EQ(rec.raw.extra.count("omega0"), 0u);  // free oscillation: no drive column
  std::remove(path.c_str());
}

TEST(BagRecordReader, PreferenceTopicChoiceAndAmbiguity) {
  const std::string path = tempBag("choice");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    writeSlow(bag, "/a/slow", 5);
    writeSlow(bag, "/b/slow", 6);
  }
  const std::string msg = expectInputError(path);
  EXPECT_NE(msg.find("several"), std::string::npos) << msg;
  EXPECT_NE(msg.find("--topic"), std::string::npos) << msg;
  BagReadOptions options;
  options.topic = "/b/slow";
  EXPECT_EQ(readRecordBag(path, options).slow.size(), 6u);
  options.topic = "/nope";
  EXPECT_NE(expectInputError(path, options).find("/a/slow"), std::string::npos);
  // A slow-state topic where only raw batches are acceptable (demod):
  options.topic = "/a/slow";
  options.kinds = {RecordKind::kRaw};
  EXPECT_NE(expectInputError(path, options).find("cvg_bench/SlowState"), std::string::npos);
  std::remove(path.c_str());
}

TEST(BagRecordReader, EmptyTruncatedAndMissingBags) {
  const std::string empty = tempBag("empty");
  { rosbag::Bag bag(empty, rosbag::bagmode::Write); }
  EXPECT_NE(expectInputError(empty).find("no topic of type"), std::string::npos);

  const std::string full = tempBag("full");
  {
    rosbag::Bag bag(full, rosbag::bagmode::Write);
    writeSlow(bag, "/cvg/slow", 2000);
  }
  std::ifstream in(full, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string cut = tempBag("truncated");
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  const std::string msg = expectInputError(cut);
  EXPECT_NE(msg.find(cut), std::string::npos) << msg;

  const std::string missing = tempBag("missing");
  const std::string missing_msg = expectInputError(missing);
  EXPECT_NE(missing_msg.find(missing), std::string::npos) << missing_msg;  // names the file
  EXPECT_NE(missing_msg.find("does not exist"), std::string::npos) << missing_msg;
  std::remove(empty.c_str());
  std::remove(full.c_str());
  std::remove(cut.c_str());
}

TEST(BagRecordReader, TimeGoingBackwardsIsNamed) {
  const std::string path = tempBag("loop");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    writeSlow(bag, "/cvg/slow", 5);
    // The same stamps again (a recorded bag loop), written later in bag time.
    for (int i = 0; i < 3; ++i) {
      const ros::Time stamp = timeAfter(kStart, 0.01 * i);
      bag.write("/cvg/slow", timeAfter(kStart, 1.0 + i),
                slowStateToMsg(slowAt(i), stamp, kStart, 5000.0));
    }
  }
  const std::string msg = expectInputError(path);
  EXPECT_NE(msg.find("message 6"), std::string::npos) << msg;
  std::remove(path.c_str());
}

}  // namespace
}  // namespace cvg_bench

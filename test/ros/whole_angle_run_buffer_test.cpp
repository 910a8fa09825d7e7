// The identifier's whole-angle run buffer (whole_angle_run_buffer.h): a new phase epoch starts a
// new run, states out of order are dropped and counted, sequence gaps count states lost.
#include "cvg_bench/ros/whole_angle_run_buffer.h"

#include <gtest/gtest.h>

namespace cvg_bench {
namespace {

const Eigen::Vector4d kQ(1.0, 0.0, 0.5, 0.0);

TEST(WholeAngleRunBuffer, KeepsOneRunInOrderAndCountsWhatIsMissing) {
  WholeAngleRunBuffer b;
  const ros::Time e1(100.0), e2(200.0);
  EXPECT_TRUE(b.add(e1, ros::Time(100.5), 1, kQ, 1000.0));
  EXPECT_TRUE(b.add(e1, ros::Time(100.6), 2, kQ, 0.0));
  EXPECT_FALSE(b.add(e1, ros::Time(100.6), 3, kQ, 0.0));  // same stamp: dropped
  EXPECT_FALSE(b.add(e1, ros::Time(100.4), 4, kQ, 0.0));  // back in time: dropped
  EXPECT_TRUE(b.add(e1, ros::Time(100.9), 8, kQ, 0.0));   // 5, 6, 7 never arrived
  EXPECT_EQ(b.dropped(), 2u);
  EXPECT_EQ(b.lost(), 3u);
  const SlowRecord r = b.record();
  ASSERT_EQ(r.size(), 3u);
  EXPECT_DOUBLE_EQ(r.t_s.front(), 0.0);
  EXPECT_NEAR(r.t_s.back(), 0.4, 1e-9);
  EXPECT_DOUBLE_EQ(r.omega_rad_s, 1000.0);  // a state with omega 0 does not erase it
  // A new phase epoch: a new run, nothing of the old one kept, losses counted afresh.
  EXPECT_TRUE(b.add(e2, ros::Time(200.1), 20, kQ, 0.0));
  EXPECT_EQ(b.size(), 1u);
  EXPECT_EQ(b.lost(), 0u);
  EXPECT_EQ(b.dropped(), 0u);  // counts are per run
  EXPECT_EQ(b.runs(), 2u);
  // A sequence number that goes back (another publisher, a wrap) is no loss.
  EXPECT_TRUE(b.add(e2, ros::Time(200.2), 3, kQ, 0.0));
  EXPECT_TRUE(b.add(e2, ros::Time(200.3), 4, kQ, 0.0));
  EXPECT_EQ(b.lost(), 0u);
  b.clear();
  EXPECT_EQ(b.size(), 0u);
}

TEST(WholeAngleRunBuffer, AFullBufferDropsInsteadOfGrowing) {
  WholeAngleRunBuffer b(2);
  const ros::Time e(1.0);
  EXPECT_TRUE(b.add(e, ros::Time(1.1), 1, kQ, 0.0));
  EXPECT_TRUE(b.add(e, ros::Time(1.2), 2, kQ, 0.0));
  EXPECT_FALSE(b.add(e, ros::Time(1.3), 3, kQ, 0.0));
  EXPECT_EQ(b.size(), 2u);
  EXPECT_EQ(b.dropped(), 1u);
}

}  // namespace
}  // namespace cvg_bench

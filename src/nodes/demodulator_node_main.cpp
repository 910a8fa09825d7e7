// Raw f, g -> slow variables (see include/cvg_bench/ros/demodulator_node.h).
#include <ros/ros.h>

#include "cvg_bench/ros/demodulator_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "demodulator");
  try {
    cvg_bench::DemodulatorNode node(ros::NodeHandle(), ros::NodeHandle("~"));
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("demodulator: %s", e.what());
    return 1;
  }
  return 0;
}

// Simulated resonator on the bench (see include/cvg_bench/ros/simulator_node.h).
#include <ros/ros.h>

#include "cvg_bench/ros/simulator_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "resonator_simulator");
  try {
    cvg_bench::SimulatorNode node(ros::NodeHandle(), ros::NodeHandle("~"));
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("resonator_simulator: %s", e.what());
    return 1;
  }
  return 0;
}

// Parameter identification on the bench (see include/cvg_bench/ros/identifier_node.h).
#include <ros/ros.h>

#include "cvg_bench/ros/identifier_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "identifier");
  try {
    cvg_bench::IdentifierNode node(ros::NodeHandle(), ros::NodeHandle("~"));
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("identifier: %s", e.what());
    return 1;
  }
  return 0;
}

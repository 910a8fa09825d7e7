// Start-up of a node: the node handles live in main's frame (a temporary handle would shut ROS down
// before a start-up failure is logged), and a start-up failure (e.g. InputError listing every
// invalid setting) is printed line by line to the console AND to /rosout before the process exits
// with status 1.
#pragma once

#include <ros/ros.h>

#include <exception>
#include <string>

namespace cvg_bench {

/// Logs `what` (one ROS_FATAL per line, prefixed by `node`) once /rosout has a subscriber (at most
/// wait_s [wall s]), then gives the log thread time to deliver.
void reportStartupFailure(const std::string& node, const std::string& what, double wait_s = 3.0);

/// ros::init, builds Node(nh, private nh) and spins; returns main's exit status.
template <class Node>
int runNode(int argc, char** argv, const std::string& name) {
  ros::init(argc, argv, name);
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  try {
    Node node(nh, pnh);
    ros::spin();
  } catch (const std::exception& e) {
    reportStartupFailure(name, e.what());
    return 1;
  }
  return 0;
}

}  // namespace cvg_bench

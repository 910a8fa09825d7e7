// Start-up failure reporting (see node_runner.h).
#include "cvg_bench/ros/node_runner.h"

#include <rosgraph_msgs/Log.h>

#include <sstream>

namespace cvg_bench {

void reportStartupFailure(const std::string& node, const std::string& what, double wait_s) {
  if (ros::isStarted()) {
    // The rosout appender publishes on /rosout without latching: a message sent before the
    // rosout node (or a test) connected is lost, so wait for a subscriber first.
    ros::NodeHandle nh;
    ros::Publisher rosout = nh.advertise<rosgraph_msgs::Log>("/rosout", 0);
    const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(wait_s);
    while (rosout.getNumSubscribers() == 0 && ros::WallTime::now() < until)
      ros::WallDuration(0.02).sleep();
  }
  std::istringstream lines(what);
  std::string line;
  while (std::getline(lines, line))
    if (!line.empty()) ROS_FATAL("%s: %s", node.c_str(), line.c_str());
  ROS_FATAL("%s: not started (fix the settings above)", node.c_str());
  if (ros::isStarted()) ros::WallDuration(0.5).sleep();  // the log thread delivers to /rosout
}

}  // namespace cvg_bench

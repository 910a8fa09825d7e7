// What rviz shows of the bench (config/bench.rviz, topic `markers`), in the resonator's frame:
//  - the undeformed ring (unit circle) and the standing wave: the ring's radial deformation
//    r cos 2(phi - theta) of the n = 2 mode ((5.2): main amplitude r, pattern angle theta), scaled
//    so the experiment's largest r is deformation_scale (drawn at no less than 15 % of it, so a
//    decayed pattern stays visible), turning as the pattern drifts;
//  - the stiffness axis (alpha), damping axis (beta) and wave pattern (theta) as arrows of
//    different lengths, each labelled at its own radius (stiffness 2.15, damping 1.7, wave 0.55
//    ring radii: labels never overprint, even when the angles coincide);
//  - a text panel beside the ring (Q, frequency split, drift rate with their intervals).
#pragma once

#include <ros/time.h>
#include <visualization_msgs/MarkerArray.h>

#include <string>

namespace cvg_bench {

struct BenchView {
  std::string frame_id = "resonator";
  ros::Time stamp;
  bool have_state = false;
  double r = 0.0;          ///< main amplitude of the latest slow state [amplitude units]
  double r_ref = 0.0;      ///< largest r of the experiment (normalises the deformation)
  double theta_rad = 0.0;  ///< pattern angle theta of the latest slow state [rad]
  bool have_axes = false;
  double alpha_rad = 0.0;          ///< stiffness axis angle [rad]
  double beta_rad = 0.0;           ///< damping axis angle [rad]
  std::string panel;               ///< text panel lines
  double deformation_scale = 0.3;  ///< largest radial deformation drawn [ring radii]
};

/// The markers (namespaces ring, standing_wave, axes, labels, panel; same ids each call, so each
/// call replaces the previous picture).
visualization_msgs::MarkerArray benchMarkers(const BenchView& view);

}  // namespace cvg_bench

// rviz markers of the bench (see bench_markers.h).
#include "cvg_bench/ros/bench_markers.h"

#include <algorithm>
#include <cmath>

namespace cvg_bench {
namespace {

constexpr int kRingPoints = 180;

visualization_msgs::Marker base(const BenchView& v, const std::string& ns, int id, int type) {
  visualization_msgs::Marker m;
  m.header.frame_id = v.frame_id;
  m.header.stamp = ros::Time();  // drawn at the latest transform: no tf lookup lag in rviz
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.color.a = 1.0;
  return m;
}

void colour(visualization_msgs::Marker& m, double r, double g, double b) {
  m.color.r = r;
  m.color.g = g;
  m.color.b = b;
}

geometry_msgs::Point point(double x, double y, double z = 0.0) {
  geometry_msgs::Point p;
  p.x = x;
  p.y = y;
  p.z = z;
  return p;
}

visualization_msgs::Marker arrow(const BenchView& v, int id, double angle, double length) {
  visualization_msgs::Marker m = base(v, "axes", id, visualization_msgs::Marker::ARROW);
  m.points = {point(0, 0), point(length * std::cos(angle), length * std::sin(angle))};
  m.scale.x = 0.04;  // shaft diameter
  m.scale.y = 0.09;  // head diameter
  m.scale.z = 0.12;  // head length
  return m;
}

visualization_msgs::Marker label(const BenchView& v, int id, double angle, double radius, double z,
                                 const std::string& text) {
  visualization_msgs::Marker m =
      base(v, "labels", id, visualization_msgs::Marker::TEXT_VIEW_FACING);
  m.pose.position = point(radius * std::cos(angle), radius * std::sin(angle), z);
  m.scale.z = 0.11;  // text height
  m.text = text;
  return m;
}

}  // namespace

visualization_msgs::MarkerArray benchMarkers(const BenchView& v) {
  visualization_msgs::MarkerArray out;
  visualization_msgs::Marker ring = base(v, "ring", 0, visualization_msgs::Marker::LINE_STRIP);
  ring.scale.x = 0.015;
  colour(ring, 0.6, 0.6, 0.6);
  for (int i = 0; i <= kRingPoints; ++i) {
    const double phi = 2 * M_PI * i / kRingPoints;
    ring.points.push_back(point(std::cos(phi), std::sin(phi)));
  }
  out.markers.push_back(ring);

  if (v.have_state) {
    // Radial deformation of the n = 2 standing wave: r cos 2(phi - theta), scaled.
    // Drawn at no less than 15 % of the scale, so a decayed pattern's orientation stays visible
    // (the panel gives r itself).
    const double rel = v.r_ref > 0.0 ? std::fabs(v.r) / v.r_ref : 0.0;
    const double amp = v.deformation_scale * std::max(rel, 0.15);
    visualization_msgs::Marker wave =
        base(v, "standing_wave", 0, visualization_msgs::Marker::LINE_STRIP);
    wave.scale.x = 0.05;
    colour(wave, 1.0, 0.85, 0.1);
    for (int i = 0; i <= kRingPoints; ++i) {
      const double phi = 2 * M_PI * i / kRingPoints;
      const double rad = 1.0 + amp * std::cos(2 * (phi - v.theta_rad));
      wave.points.push_back(point(rad * std::cos(phi), rad * std::sin(phi)));
    }
    out.markers.push_back(wave);
    visualization_msgs::Marker a = arrow(v, 2, v.theta_rad, 1.15 + amp);
    colour(a, 1.0, 0.85, 0.1);
    out.markers.push_back(a);
    // Inside the ring: never on the axes' labels outside it.
    visualization_msgs::Marker l = label(v, 2, v.theta_rad, 0.55, 0.0, "wave theta");
    colour(l, 1.0, 0.85, 0.1);
    out.markers.push_back(l);
  }
  if (v.have_axes) {
    // Different lengths and label heights: coinciding axes stay readable.
    visualization_msgs::Marker a = arrow(v, 0, v.alpha_rad, 1.7);
    colour(a, 0.95, 0.3, 0.3);
    out.markers.push_back(a);
    visualization_msgs::Marker la = label(v, 0, v.alpha_rad, 2.15, 0.0, "stiffness alpha");
    colour(la, 0.95, 0.3, 0.3);
    out.markers.push_back(la);
    visualization_msgs::Marker b = arrow(v, 1, v.beta_rad, 1.45);
    colour(b, 0.3, 0.6, 1.0);
    out.markers.push_back(b);
    visualization_msgs::Marker lb = label(v, 1, v.beta_rad, 1.7, 0.0, "damping beta");
    colour(lb, 0.3, 0.6, 1.0);
    out.markers.push_back(lb);
  }
  if (!v.panel.empty()) {
    visualization_msgs::Marker p =
        base(v, "panel", 0, visualization_msgs::Marker::TEXT_VIEW_FACING);
    p.pose.position = point(0.0, -1.95, 0.0);
    p.scale.z = 0.1;
    colour(p, 1.0, 1.0, 1.0);
    p.text = v.panel;
    out.markers.push_back(p);
  }
  return out;
}

}  // namespace cvg_bench

// The simulated world as the simulated cameras see it, in the robot's frame (metres, z up, the
// table top at table_z): the reference marker on the table, the objects with their markers on
// top, the robot's gripper and what it holds.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core/matx.hpp>
#include <opencv2/core/types.hpp>

#include "arbci/vision/marker.h"
#include "arbci/vision/pose.h"

namespace arbci::session {

struct SceneMarker {
  vision::MarkerKind kind = vision::MarkerKind::Bch;
  int id = 0;
  double side_m = 0.05;  // the black square
  double border = 0.0;   // of the side (the tracker's tracker.border for the session's markers)
};

struct SceneObject {
  SceneMarker marker;
  vision::Pose T_world_top;              // the centre of the top face; z out of the face
  double width_m = 0.0, height_m = 0.0;  // the session's world.objects[]
  cv::Vec3f color{0.85f, 0.35f, 0.25f};  // red, green, blue, 0-1
  bool covered = false;                  // a hand lies over its marker
  // The gripper's fingertip lies over a corner of its marker (the simulated arm coming down on it
  // to grasp it): a dark pad 0.36 of the marker's side across, centred on the corner, so that it
  // hides 18 % of the side along both edges from that corner.
  bool gripper_over_corner = false;
};

struct SceneGripper {
  cv::Vec3d tool;        // fingertips, robot frame
  double opening = 1.0;  // 0 closed, 1 open
};

// A printed chessboard held up for camera calibration (white margin of one square).
struct SceneBoard {
  vision::Pose T_world_board;  // origin at the board's centre, z out of the print
  cv::Size inner_corners{9, 6};
  double square_m = 0.025;
};

struct Scene {
  double table_z = 0.0;
  cv::Vec2d table_min{-0.7, 0.1}, table_max{0.7, 1.4};
  SceneMarker reference{vision::MarkerKind::Bch, 0, 0.08, 0.125};
  vision::Pose T_world_reference{cv::Matx33d::eye(), cv::Vec3d(0.0, 0.90, 0.0)};
  std::vector<SceneObject> objects;
  std::optional<SceneGripper> gripper;
  std::optional<SceneBoard> board;
};

}  // namespace arbci::session

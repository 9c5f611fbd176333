// Draws a Scene as an ideal pinhole camera sees it, on the CPU, so that the simulated cameras
// need no GL context and the session library runs its own default settings.
//
// Every surface is a flat convex polygon: a face of a box (the objects, a hand, the fingertip,
// the gripper), the table, a marker or the chessboard. The bodies are drawn far to near (painter's
// order) with their faces that turn away from the camera left out; for the scene's bodies (boxes
// standing apart, each marker on its own face) that order is exact. The picture is drawn at
// `supersample` times the image's resolution and averaged down: the anti-aliasing of a
// multisampled render with supersample^2 samples a pixel. Markers and the board are drawn from
// their texels (a cell each) enlarged to about a canvas pixel a texel, the level of detail a GPU's
// mipmaps would pick, and interpolated linearly: a cell's edge lands where it should to a small
// fraction of a pixel (drawn texel by texel, it would snap to the canvas's half-pixel grid, which
// moves a marker's edges by a quarter of a pixel and is enough to change what the tracker reads).
#pragma once

#include <array>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <opencv2/core.hpp>

#include "arbci/session/simulation/scene.h"

namespace arbci::session {

class ScenePainter {
 public:
  ScenePainter(const cv::Matx33d& camera_matrix, cv::Size image_size, int supersample = 2);
  // A BGR frame of `scene` seen from `T_cam_world` (x right, y down, z forward in the camera),
  // without lens distortion.
  cv::Mat paint(const Scene& scene, const vision::Pose& T_cam_world);

  // The colour behind the table (the room), BGR.
  static cv::Scalar background();

  // A flat convex polygon of the scene.
  struct Face {
    std::array<cv::Vec3d, 4> corners;  // world, in order around the face
    cv::Vec3d outward;                 // world normal (zero: seen from both sides)
    cv::Vec3f rgb;  // with a texture: the colour around it (a marker's white quiet zone)
    const cv::Mat* texture = nullptr;  // drawn over the face's corners, texel (0, 0) at corner 0
  };
  struct Body {
    double distance = 0.0;  // of its centre from the camera
    std::vector<Face> faces;
  };

 private:
  void drawTable(const Scene& scene);            // with the reference marker on it
  std::vector<Body> bodies(const Scene& scene);  // what stands on the table, far to near
  Face markerFace(const SceneMarker& marker, const vision::Pose& face, double lift);
  void draw(const Face& face);
  void fill(const std::vector<cv::Vec3d>& camera_points, const cv::Vec3f& rgb);
  void texture(const std::array<cv::Vec3d, 4>& camera_points, const cv::Mat& texels,
               const cv::Vec3f& surround);
  const cv::Mat& enlarged(const cv::Mat& texels, int scale, const cv::Vec3f& surround);
  cv::Point2d toCanvas(const cv::Vec3d& camera_point) const;
  const cv::Mat& markerTexels(const SceneMarker& marker);
  const cv::Mat& boardTexels(const SceneBoard& board);

  cv::Matx33d camera_matrix_;
  cv::Size size_;
  int supersample_;
  cv::Mat canvas_;  // BGR at supersample_ x the image size
  vision::Pose T_cam_world_;
  cv::Vec3d eye_;  // the camera's centre, world
  std::map<std::tuple<std::string, int, int>, cv::Mat> markers_;
  std::map<std::pair<int, int>, cv::Mat> boards_;
  std::map<std::pair<const cv::Mat*, int>, cv::Mat> enlarged_;
};

}  // namespace arbci::session

#include "arbci/render/camera_projection.h"

namespace arbci::render {

glm::mat4 projectionFromCamera(const cv::Matx33d& k, cv::Size size, double near_m, double far_m) {
  const double w = size.width, h = size.height;
  glm::mat4 p(0.0f);  // p[column][row]
  p[0][0] = static_cast<float>(2.0 * k(0, 0) / w);
  p[1][0] = static_cast<float>(-2.0 * k(0, 1) / w);  // skew
  p[2][0] = static_cast<float>(1.0 - 2.0 * (k(0, 2) + 0.5) / w);
  p[1][1] = static_cast<float>(2.0 * k(1, 1) / h);
  p[2][1] = static_cast<float>(2.0 * (k(1, 2) + 0.5) / h - 1.0);
  p[2][2] = static_cast<float>(-(far_m + near_m) / (far_m - near_m));
  p[3][2] = static_cast<float>(-2.0 * far_m * near_m / (far_m - near_m));
  p[2][3] = -1.0f;
  return p;
}

glm::mat4 cameraToGl() {
  glm::mat4 flip(1.0f);
  flip[1][1] = -1.0f;
  flip[2][2] = -1.0f;
  return flip;
}

glm::mat4 toMatrix(const vision::Pose& pose) {
  glm::mat4 m(1.0f);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m[c][r] = static_cast<float>(pose.rotation(r, c));
    m[3][r] = static_cast<float>(pose.translation[r]);
  }
  return m;
}

glm::mat4 worldToClip(const cv::Matx33d& k, cv::Size size, const vision::Pose& T_cam_world) {
  return projectionFromCamera(k, size) * cameraToGl() * toMatrix(T_cam_world);
}

}  // namespace arbci::render

// From a calibrated camera to OpenGL: the projection matrix is derived from the camera matrix
// and image size, so what is drawn lands on the pixel the camera model predicts (OpenCV pixel
// centres at integer coordinates; the viewport covers the whole image).
#pragma once

#include <glm/glm.hpp>
#include <opencv2/core/matx.hpp>
#include <opencv2/core/types.hpp>

#include "arbci/vision/pose.h"

namespace arbci::render {

// Clip-space projection of OpenCV camera coordinates (x right, y down, z forward) after
// `cameraToGl`: pixel (u, v) = (fx x/z + cx, fy y/z + cy) lands on that pixel of the viewport.
glm::mat4 projectionFromCamera(const cv::Matx33d& camera_matrix, cv::Size image_size,
                               double near_m = 0.05, double far_m = 20.0);
// OpenCV camera frame to OpenGL eye frame (y and z flipped).
glm::mat4 cameraToGl();
// A rigid transform as a matrix (column-major, glm).
glm::mat4 toMatrix(const vision::Pose& pose);
// The whole chain for a world point: projection * cameraToGl * T_cam_world.
glm::mat4 worldToClip(const cv::Matx33d& camera_matrix, cv::Size image_size,
                      const vision::Pose& T_cam_world);

}  // namespace arbci::render

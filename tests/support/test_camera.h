// The camera the render, HMD and simulated-camera tests draw and track with: 640x480, 700 px
// focal length, no lens.
#pragma once

#include "arbci/vision/camera_model.h"

namespace arbci::test {

inline vision::CameraModel camera640() {
  vision::CameraModel c;
  c.image_size = {640, 480};
  c.camera_matrix = cv::Matx33d(700, 0, 319.5, 0, 700, 239.5, 0, 0, 1);
  return c;
}

}  // namespace arbci::test

#include "arbci/session/simulation/simulated_camera.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "simulation/scene_painter.h"

namespace arbci::session {

SimulatedCamera::SimulatedCamera(const vision::CameraModel& camera, std::uint64_t seed)
    : camera_(camera),
      painter_(std::make_unique<ScenePainter>(camera.camera_matrix, camera.image_size)),
      random_(seed ? seed : 1) {
  const cv::Size size = camera.image_size;
  if (!camera.distortion.empty()) {
    // Where each pixel of the distorted image comes from in the ideal rendering.
    cv::Mat distort_x(size, CV_32FC1), distort_y(size, CV_32FC1);
    cv::Mat points(size.area(), 1, CV_64FC2);
    for (int y = 0, i = 0; y < size.height; ++y) {
      for (int x = 0; x < size.width; ++x, ++i) points.at<cv::Vec2d>(i) = cv::Vec2d(x, y);
    }
    cv::Mat ideal;
    cv::undistortPoints(points, ideal, camera.camera_matrix, camera.distortion, cv::noArray(),
                        camera.camera_matrix);
    for (int y = 0, i = 0; y < size.height; ++y) {
      for (int x = 0; x < size.width; ++x, ++i) {
        const cv::Vec2d p = ideal.at<cv::Vec2d>(i);
        distort_x.at<float>(y, x) = static_cast<float>(p[0]);
        distort_y.at<float>(y, x) = static_cast<float>(p[1]);
      }
    }
    cv::convertMaps(distort_x, distort_y, distort_map1_, distort_map2_, CV_16SC2);
  }
}

SimulatedCamera::~SimulatedCamera() = default;

cv::Mat SimulatedCamera::render(const Scene& scene, const vision::Pose& T_cam_world,
                                const CameraEffects& effects) {
  const cv::Size size = camera_.image_size;
  cv::Mat frame = painter_->paint(scene, T_cam_world);

  if (effects.distort && !distort_map1_.empty()) {
    cv::Mat distorted;
    cv::remap(frame, distorted, distort_map1_, distort_map2_, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
              ScenePainter::background());
    frame = distorted;
  }
  if (effects.blur_sigma > 0.0) cv::GaussianBlur(frame, frame, cv::Size(), effects.blur_sigma);
  if (effects.vignetting > 0.0 || effects.gradient > 0.0 || effects.noise_sigma > 0.0) {
    // Integer arithmetic on 16-bit pixels: a frame's effects cost about a millisecond.
    cv::Mat pixels;
    frame.convertTo(pixels, CV_16SC3);
    if (effects.vignetting > 0.0 || effects.gradient > 0.0) {
      if (effects.vignetting != gain_vignetting_ || effects.gradient != gain_gradient_) {
        cv::Mat gain(size, CV_16SC1);
        const double cx = size.width / 2.0, cy = size.height / 2.0, r2 = cx * cx + cy * cy;
        for (int y = 0; y < size.height; ++y) {
          auto* row = gain.ptr<std::int16_t>(y);
          for (int x = 0; x < size.width; ++x) {
            const double d2 = ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / r2;
            row[x] =
                static_cast<std::int16_t>(std::lround(256.0 * (1.0 - effects.vignetting * d2) *
                                                      (1.0 - effects.gradient * x / size.width)));
          }
        }
        cv::merge(std::vector<cv::Mat>{gain, gain, gain}, gain_);
        gain_vignetting_ = effects.vignetting;
        gain_gradient_ = effects.gradient;
      }
      cv::multiply(pixels, gain_, pixels, 1.0 / 256.0);
    }
    if (effects.noise_sigma > 0.0) {
      // Gaussian noise drawn once for a field 64 pixels larger than the frame; each frame takes
      // a window at a random offset, so the noise changes from frame to frame.
      if (effects.noise_sigma != noise_sigma_) {
        noise_.create(size.height + 64, size.width + 64, CV_16SC3);
        random_.fill(noise_, cv::RNG::NORMAL, cv::Scalar::all(0.0),
                     cv::Scalar::all(effects.noise_sigma));
        noise_sigma_ = effects.noise_sigma;
      }
      const cv::Rect window(random_.uniform(0, 64), random_.uniform(0, 64), size.width,
                            size.height);
      cv::add(pixels, noise_(window), pixels);
    }
    pixels.convertTo(frame, CV_8UC3);
  }
  return frame;
}

}  // namespace arbci::session

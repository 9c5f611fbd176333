#include "arbci/render/simulated_camera.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "arbci/render/camera_projection.h"
#include "arbci/render/gl_context.h"
#include "gl.h"

namespace arbci::render {

SimulatedCamera::SimulatedCamera(const vision::CameraModel& camera, std::uint64_t seed) : camera_(camera), random_(seed) {
  const cv::Size size = camera.image_size;
  GLint max_samples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  const GLsizei samples = std::min<GLint>(4, max_samples);
  glGenFramebuffers(1, &multisample_fbo_);
  glGenRenderbuffers(1, &color_rb_);
  glGenRenderbuffers(1, &depth_rb_);
  glBindRenderbuffer(GL_RENDERBUFFER, color_rb_);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, size.width, size.height);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_rb_);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH24_STENCIL8, size.width, size.height);
  glBindFramebuffer(GL_FRAMEBUFFER, multisample_fbo_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_rb_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, depth_rb_);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) throw GlError("simulated camera: multisample framebuffer incomplete");
  glGenFramebuffers(1, &resolve_fbo_);
  glGenRenderbuffers(1, &resolve_rb_);
  glBindRenderbuffer(GL_RENDERBUFFER, resolve_rb_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, size.width, size.height);
  glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolve_rb_);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) throw GlError("simulated camera: resolve framebuffer incomplete");
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (!camera.distortion.empty()) {
    // Where each pixel of the distorted image comes from in the ideal rendering.
    cv::initUndistortRectifyMap(camera.camera_matrix, cv::noArray(), cv::noArray(), camera.camera_matrix, size, CV_32FC1, distort_x_,
                                distort_y_);
    cv::Mat points(size.area(), 1, CV_64FC2);
    for (int y = 0, i = 0; y < size.height; ++y) {
      for (int x = 0; x < size.width; ++x, ++i) points.at<cv::Vec2d>(i) = cv::Vec2d(x, y);
    }
    cv::Mat ideal;
    cv::undistortPoints(points, ideal, camera.camera_matrix, camera.distortion, cv::noArray(), camera.camera_matrix);
    for (int y = 0, i = 0; y < size.height; ++y) {
      for (int x = 0; x < size.width; ++x, ++i) {
        const cv::Vec2d p = ideal.at<cv::Vec2d>(i);
        distort_x_.at<float>(y, x) = static_cast<float>(p[0]);
        distort_y_.at<float>(y, x) = static_cast<float>(p[1]);
      }
    }
  }
}

SimulatedCamera::~SimulatedCamera() {
  glDeleteFramebuffers(1, &multisample_fbo_);
  glDeleteFramebuffers(1, &resolve_fbo_);
  glDeleteRenderbuffers(1, &color_rb_);
  glDeleteRenderbuffers(1, &depth_rb_);
  glDeleteRenderbuffers(1, &resolve_rb_);
}

cv::Mat SimulatedCamera::render(const Scene& scene, const vision::Pose& T_cam_world, const CameraEffects& effects) {
  const cv::Size size = camera_.image_size;
  glBindFramebuffer(GL_FRAMEBUFFER, multisample_fbo_);
  glViewport(0, 0, size.width, size.height);
  glClearColor(0.30f, 0.32f, 0.35f, 1.0f);  // the room behind the table
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  renderer_.draw(scene, worldToClip(camera_.camera_matrix, size, T_cam_world));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, multisample_fbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo_);
  glBlitFramebuffer(0, 0, size.width, size.height, 0, 0, size.width, size.height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_fbo_);
  cv::Mat rgba(size, CV_8UC4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, size.width, size.height, GL_BGRA, GL_UNSIGNED_BYTE, rgba.data);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  cv::Mat frame;
  cv::cvtColor(rgba, frame, cv::COLOR_BGRA2BGR);
  cv::flip(frame, frame, 0);  // GL rows start at the bottom

  if (effects.distort && !distort_x_.empty()) {
    cv::Mat distorted;
    cv::remap(frame, distorted, distort_x_, distort_y_, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(77, 82, 90));
    frame = distorted;
  }
  if (effects.blur_sigma > 0.0) cv::GaussianBlur(frame, frame, cv::Size(), effects.blur_sigma);
  if (effects.vignetting > 0.0 || effects.gradient > 0.0 || effects.noise_sigma > 0.0) {
    cv::Mat f;
    frame.convertTo(f, CV_32FC3);
    const double cx = size.width / 2.0, cy = size.height / 2.0, r2 = cx * cx + cy * cy;
    std::normal_distribution<float> noise(0.0f, static_cast<float>(effects.noise_sigma));
    for (int y = 0; y < size.height; ++y) {
      auto* row = f.ptr<cv::Vec3f>(y);
      for (int x = 0; x < size.width; ++x) {
        const double d2 = ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / r2;
        const float gain = static_cast<float>((1.0 - effects.vignetting * d2) * (1.0 - effects.gradient * x / size.width));
        for (int c = 0; c < 3; ++c) row[x][c] = row[x][c] * gain + (effects.noise_sigma > 0.0 ? noise(random_) : 0.0f);
      }
    }
    f.convertTo(frame, CV_8UC3);
  }
  return frame;
}

}  // namespace arbci::render

#include "support/pose_sequences.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "arbci/vision/marker_poses.h"
#include "arbci/vision/marker_tracker.h"
#include "support/posed_markers.h"

namespace arbci::test {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kFlipDeg = 15.0;
constexpr int kSubFrames = 8;
constexpr int kArbciId = 1234;
constexpr int kAprilTagId = 123;

cv::Matx33d rotationY(double deg) {
  const double a = deg * kPi / 180.0;
  return {std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a)};
}
cv::Matx33d rotationX(double deg) {
  const double a = deg * kPi / 180.0;
  return {1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a)};
}

// Accumulates one run's comparison with the truth.
class Scorer {
 public:
  explicit Scorer(const PoseSequence& sequence) : sequence_(sequence) {}
  void add(double t, const std::optional<vision::Pose>& pose,
           const std::optional<vision::SquareCorners>& corners) {
    ++out_.frames;
    if (!pose) return;
    ++out_.found;
    const vision::Pose truth = sequence_.truth(t);
    const double angle = vision::rotationAngleDeg(pose->rotation, truth.rotation);
    if (angle > kFlipDeg) {
      ++out_.flips;
    } else {
      rotation_sum_ += angle;
      ++rotations_;
    }
    if (!corners) return;
    const auto object = vision::markerCorners(sequence_.side_m);
    cv::Point2d centre(0, 0), truth_px[4];
    for (int c = 0; c < 4; ++c) {
      truth_px[c] = vision::project(truth, sequence_.k, object[c]);
      centre += truth_px[c] * 0.25;
    }
    for (int c = 0; c < 4; ++c) {
      const cv::Point2d out = truth_px[c] - centre;
      const cv::Point2d found((*corners)[c].x, (*corners)[c].y);
      outward_sum_ += (found - truth_px[c]).dot(out * (1.0 / cv::norm(out)));
      ++outward_count_;
      corner_sq_sum_ += (found - truth_px[c]).dot(found - truth_px[c]);
    }
  }
  PoseStability result() const {
    PoseStability r = out_;
    r.outward_px = outward_count_ ? outward_sum_ / outward_count_ : 0.0;
    r.rotation_deg = rotations_ ? rotation_sum_ / rotations_ : 0.0;
    r.corner_rms_px = outward_count_ ? std::sqrt(corner_sq_sum_ / outward_count_) : 0.0;
    return r;
  }

 private:
  const PoseSequence& sequence_;
  PoseStability out_;
  double rotation_sum_ = 0.0, outward_sum_ = 0.0, corner_sq_sum_ = 0.0;
  int rotations_ = 0, outward_count_ = 0;
};

}  // namespace

PoseSequence fastHandheldSequence(double seconds) {
  PoseSequence s;
  s.name = "fast (handheld, JPEG 75)";
  s.seconds = seconds;
  s.jpeg_quality = 75;
  s.truth = [](double t) {
    // Across the image (0.18 m at 0.55 m: about 180 px each way, 0.6 Hz) and turning: tilt
    // 30 +- 25 deg at 1.2 Hz (up to about 190 deg/s), its axis and the spin swinging slower.
    const double x = 0.18 * std::sin(2 * kPi * 0.6 * t);
    const double y = 0.06 * std::sin(2 * kPi * 0.45 * t + 1.0);
    const double tilt = 30.0 + 25.0 * std::sin(2 * kPi * 1.2 * t);
    const double azimuth = 20.0 + 60.0 * std::sin(2 * kPi * 0.35 * t);
    const double spin = 35.0 + 40.0 * std::sin(2 * kPi * 0.5 * t + 0.5);
    return vision::Pose{markerRotation(tilt, azimuth, spin), cv::Vec3d(x, y, 0.55)};
  };
  return s;
}

PoseSequence farMarkerSequence(double seconds) {
  PoseSequence s;
  s.name = "far (1.1 m, JPEG 75)";
  s.seconds = seconds;
  s.jpeg_quality = 75;
  s.truth = [](double t) {
    // Fixed in the world; the head turns +-8 deg (yaw) and +-5 deg (pitch).
    const double yaw = 8.0 * (std::sin(2 * kPi * 0.5 * t) + 0.4 * std::sin(2 * kPi * 1.3 * t + 1));
    const double pitch = 5.0 * std::sin(2 * kPi * 0.7 * t + 0.5);
    const vision::Pose at_rest{markerRotation(40.0, 20.0, 35.0), cv::Vec3d(0.0, 0.0, 1.1)};
    vision::Pose turn;
    turn.rotation = (rotationY(yaw) * rotationX(pitch)).t();
    return turn * at_rest;
  };
  return s;
}

cv::Mat renderSequenceFrame(const PoseSequence& s, MarkerFamily family, int id, int index,
                            unsigned seed) {
  const double t = index / s.fps;
  cv::Mat sum(s.size, CV_32F, cv::Scalar(0));
  for (int k = 0; k < kSubFrames; ++k) {
    const double ts = t + s.exposure_ms / 1000.0 * ((k + 0.5) / kSubFrames - 0.5);
    cv::Mat frame(s.size, CV_8UC1, cv::Scalar(150));
    drawPosedMarker(frame, s.k, s.truth(ts), s.side_m, family, id);
    cv::Mat as_float;
    frame.convertTo(as_float, CV_32F);
    sum += as_float;
  }
  cv::Mat noise(s.size, CV_32F);
  cv::RNG rng(seed * 7919u + static_cast<unsigned>(index));
  rng.fill(noise, cv::RNG::NORMAL, 0.0, s.noise);
  cv::Mat image;
  cv::Mat(sum / kSubFrames + noise).convertTo(image, CV_8U);
  if (s.jpeg_quality > 0) {
    std::vector<uchar> bytes;
    cv::imencode(".jpg", image, bytes, {cv::IMWRITE_JPEG_QUALITY, s.jpeg_quality});
    image = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
  }
  return image;
}

PoseStability runArbciPoses(const PoseSequence& s, const vision::DetectorConfig& config,
                            const vision::PoseOptions& pose, bool smooth) {
  vision::MarkerDetector detector(config);
  vision::TrackerOptions options;
  options.smooth_corners = smooth;
  vision::MarkerTracker tracker(options);
  vision::MarkerPoses poses(s.k, pose);
  Scorer scorer(s);
  const auto size_of = [&](int id) { return id == kArbciId ? s.side_m : 0.0; };
  for (int f = 0; f < s.frames(); ++f) {
    const double t = f / s.fps;
    const cv::Mat image = renderSequenceFrame(s, MarkerFamily::ArbciBch, kArbciId, f, s.noise_seed);
    const vision::DetectionResult result = detector.detect(image);
    const auto markers = tracker.update(result.markers, detector.lastSquares(), t);
    const auto estimates = poses.estimate(markers, size_of);
    std::optional<vision::Pose> found;
    std::optional<vision::SquareCorners> corners;
    if (const auto it = estimates.find(kArbciId); it != estimates.end()) {
      found = it->second.pose;
    }
    for (const vision::MarkerDetection& m : markers) {
      if (m.id == kArbciId) corners = m.corners;
    }
    scorer.add(t, found, corners);
  }
  return scorer.result();
}

PoseStability runAprilTagIppe(const PoseSequence& s, int decimate) {
  vision::DetectorConfig config;
  config.kind = vision::MarkerKind::AprilTag;
  config.search_decimate = decimate;
  vision::MarkerDetector detector(config);
  vision::PoseOptions ippe;
  ippe.method = vision::PoseMethod::Ippe;
  ippe.refine = false;
  Scorer scorer(s);
  const auto object = vision::markerCorners(s.side_m);
  for (int f = 0; f < s.frames(); ++f) {
    const double t = f / s.fps;
    const cv::Mat image =
        renderSequenceFrame(s, MarkerFamily::AprilTag36h11, kAprilTagId, f, s.noise_seed);
    std::optional<vision::Pose> found;
    std::optional<vision::SquareCorners> corners;
    for (const vision::MarkerDetection& m : detector.detect(image).markers) {
      if (m.id != kAprilTagId) continue;
      std::vector<cv::Point2d> image_points;
      for (const cv::Point2f& c : m.corners) image_points.emplace_back(c.x, c.y);
      found = vision::estimatePose(object, image_points, s.k, ippe).pose;
      corners = m.corners;
    }
    scorer.add(t, found, corners);
  }
  return scorer.result();
}

}  // namespace arbci::test

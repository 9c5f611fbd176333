// Pose over time on a head-motion sequence with exact truth: a marker fixed on the table, seen by
// a head-mounted camera that turns (yaw and pitch as a sum of slow sinusoids, as a subject looking
// around the table), each frame integrated over its exposure so that the marker smears exactly as
// it moves. Per marker tilt, the tracker's poses without and with One-Euro corner smoothing are
// compared with the truth: error, frame-to-frame jitter, flips to the other planar solution, and
// the latency the smoothing adds. Then the same sequence drawn with each peer's markers: the
// fraction of frames each detector reads the marker in, and its time per frame.
//   pose_sequence_bench [--seconds S] [--fps F] [--exposure-ms E] [--head-deg A]   (--help)
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "arbci/vision/marker_detector.h"
#include "arbci/vision/marker_poses.h"
#include "arbci/vision/marker_tracker.h"
#include "marker_peers.h"
#include "support/posed_markers.h"

using namespace arbci;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kSideM = 0.06;      // the marker's black square
constexpr double kDistanceM = 0.55;  // from the camera, straight ahead at rest
constexpr double kFlipDeg = 15.0;    // a rotation error this large is the other planar solution
constexpr int kSubFrames = 8;        // renders averaged over one exposure
constexpr int kMarkerId = 1234;      // ARBCI's BCH marker; the peers' is kPeerId of their family
constexpr int kPeerId = 123;

struct HeadMotion {
  double amplitude_deg;
  // Yaw and pitch of the head (degrees) at time t: incommensurate sinusoids, so the sequence
  // holds rests, slow turns and fast ones.
  cv::Matx33d rotation(double t) const {
    const double a = amplitude_deg * kPi / 180.0;
    const double yaw = a * (std::sin(2 * kPi * 0.5 * t) + 0.4 * std::sin(2 * kPi * 1.3 * t + 1.0));
    const double pitch = a * 0.6 * std::sin(2 * kPi * 0.7 * t + 0.5);
    const cv::Matx33d ry(std::cos(yaw), 0, std::sin(yaw), 0, 1, 0, -std::sin(yaw), 0,
                         std::cos(yaw));
    const cv::Matx33d rx(1, 0, 0, 0, std::cos(pitch), -std::sin(pitch), 0, std::sin(pitch),
                         std::cos(pitch));
    return ry * rx;
  }
};

// The marker in the camera's frame at time t: fixed in the world, the camera turning.
vision::Pose markerInCamera(const HeadMotion& head, const vision::Pose& at_rest, double t) {
  vision::Pose camera_turn;
  camera_turn.rotation = head.rotation(t).t();
  return camera_turn * at_rest;
}

struct Stats {
  int frames = 0, found = 0, flips = 0;
  std::vector<double> position_mm, rotation_deg;
  double jitter_mm_sum = 0.0, jitter_deg_sum = 0.0;
  int jitter_count = 0;
  std::optional<cv::Vec3d> last_position_error;
  std::optional<cv::Matx33d> last_rotation_error;

  void add(const vision::Pose& truth, const std::optional<vision::Pose>& estimate) {
    ++frames;
    if (!estimate) {
      last_position_error.reset();
      last_rotation_error.reset();
      return;
    }
    ++found;
    const cv::Vec3d position_error = (estimate->translation - truth.translation) * 1000.0;
    const double angle = vision::rotationAngleDeg(estimate->rotation, truth.rotation);
    if (angle > kFlipDeg) {
      ++flips;  // a flip is counted, not averaged into the error
      last_position_error.reset();
      last_rotation_error.reset();
      return;
    }
    position_mm.push_back(cv::norm(position_error));
    rotation_deg.push_back(angle);
    const cv::Matx33d rotation_error = estimate->rotation * truth.rotation.t();
    if (last_position_error) {
      jitter_mm_sum += std::pow(cv::norm(position_error - *last_position_error), 2);
      jitter_deg_sum += std::pow(vision::rotationAngleDeg(rotation_error, *last_rotation_error), 2);
      ++jitter_count;
    }
    last_position_error = position_error;
    last_rotation_error = rotation_error;
  }
  static double mean(const std::vector<double>& v) {
    double sum = 0.0;
    for (double x : v) sum += x;
    return v.empty() ? 0.0 : sum / static_cast<double>(v.size());
  }
  static double p95(std::vector<double> v) {
    if (v.empty()) return 0.0;
    const size_t k = std::min(v.size() - 1, static_cast<size_t>(0.95 * v.size()));
    std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
    return v[k];
  }
  double jitterMm() const { return jitter_count ? std::sqrt(jitter_mm_sum / jitter_count) : 0.0; }
  double jitterDeg() const { return jitter_count ? std::sqrt(jitter_deg_sum / jitter_count) : 0.0; }
};

// The lag (ms) at which the estimated positions best match the truth's: the estimate at frame
// time t against the truth at t - lag, over lags 0..150 ms.
double bestLagMs(const std::vector<double>& times, const std::vector<std::optional<cv::Vec3d>>& est,
                 const HeadMotion& head, const vision::Pose& at_rest) {
  double best_lag = 0.0, best_rms = 1e300;
  for (int lag_ms = 0; lag_ms <= 150; ++lag_ms) {
    double sum = 0.0;
    int n = 0;
    for (size_t i = 0; i < times.size(); ++i) {
      if (!est[i]) continue;
      const cv::Vec3d truth = markerInCamera(head, at_rest, times[i] - lag_ms / 1000.0).translation;
      sum += std::pow(cv::norm(*est[i] - truth), 2);
      ++n;
    }
    if (n > 0 && std::sqrt(sum / n) < best_rms) {
      best_rms = std::sqrt(sum / n);
      best_lag = lag_ms;
    }
  }
  return best_lag;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{
      "Pose over time on a simulated head-motion sequence with exact truth: error, jitter, flips "
      "and smoothing latency per marker tilt"};
  double seconds = 10.0, fps = 30.0, exposure_ms = 16.0, head_deg = 8.0, noise = 2.0;
  std::vector<double> tilts{0.0, 30.0, 50.0, 70.0};
  vision::TrackerOptions smoothing;
  smoothing.smooth_corners = true;
  cli.add_option("--seconds", seconds, "length of the sequence")
      ->check(CLI::Range(1.0, 600.0))
      ->capture_default_str();
  cli.add_option("--fps", fps, "camera frame rate")
      ->check(CLI::Range(5.0, 240.0))
      ->capture_default_str();
  cli.add_option("--exposure-ms", exposure_ms, "exposure per frame (the motion blur)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  cli.add_option("--head-deg", head_deg, "amplitude of the head's yaw (pitch is 0.6 of it)")
      ->check(CLI::Range(0.0, 30.0))
      ->capture_default_str();
  cli.add_option("--noise", noise, "sensor noise, grey levels (sigma)")
      ->check(CLI::Range(0.0, 30.0))
      ->capture_default_str();
  cli.add_option("--tilts", tilts, "marker tilts away from the camera, degrees")
      ->delimiter(',')
      ->check(CLI::Range(0.0, 80.0))
      ->capture_default_str();
  cli.add_option("--min-cutoff-hz", smoothing.min_cutoff_hz, "One-Euro cutoff at rest")
      ->check(CLI::Range(0.01, 100.0))
      ->capture_default_str();
  cli.add_option("--beta", smoothing.beta, "One-Euro cutoff increase per px/s")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  int decimate = 1;
  cli.add_option("--decimate", decimate,
                 "the tracker's search_decimate for the pose table: 1 full resolution, 2 the "
                 "frame averaged over 2x2 pixels")
      ->check(CLI::IsMember({1, 2}))
      ->capture_default_str();
  CLI11_PARSE(cli, argc, argv);

  const cv::Size size(640, 480);
  const cv::Matx33d k(560, 0, 319.5, 0, 560, 239.5, 0, 0, 1);
  const HeadMotion head{head_deg};
  const int frames = static_cast<int>(std::lround(seconds * fps));
  // Peak image speed of the marker's centre, for the reader: the blur it causes in one exposure.
  double peak_px_per_s = 0.0;
  for (int i = 1; i < frames * 4; ++i) {
    const double t0 = (i - 1) / (4 * fps), t1 = i / (4 * fps);
    const vision::Pose rest{cv::Matx33d::eye(), cv::Vec3d(0, 0, kDistanceM)};
    const cv::Point2d a = vision::project(markerInCamera(head, rest, t0), k, {0, 0, 0});
    const cv::Point2d b = vision::project(markerInCamera(head, rest, t1), k, {0, 0, 0});
    peak_px_per_s = std::max(peak_px_per_s, cv::norm(b - a) / (t1 - t0));
  }
  std::printf(
      "Head-motion sequence: %.0f s at %.0f fps, exposure %.0f ms, head yaw +-%.1f deg (pitch "
      "0.6 of it), peak image speed %.0f px/s (%.1f px of blur per exposure); %.0f mm marker at "
      "%.2f m, 640x480, f = 560 px, noise sigma %.1f.\n"
      "Tracker search_decimate %d. Smoothing: One-Euro, min cutoff %.2f Hz, beta %.2f. Errors "
      "exclude flips (rotation error > %.0f deg), which are counted; jitter is the RMS "
      "frame-to-frame change of the error.\n\n",
      seconds, fps, exposure_ms, head_deg, peak_px_per_s, peak_px_per_s * exposure_ms / 1000.0,
      kSideM * 1000, kDistanceM, noise, decimate, smoothing.min_cutoff_hz, smoothing.beta,
      kFlipDeg);
  std::printf("%5s %-9s %6s %7s %8s %7s %8s %9s %9s %6s %8s\n", "tilt", "corners", "found",
              "pos mm", "pos p95", "rot deg", "rot p95", "jitter mm", "jitter deg", "flips",
              "lag ms");

  std::mt19937 random(7);
  // One frame: the marker integrated over the exposure centred on t, then sensor noise.
  auto render = [&](test::MarkerFamily family, int id, const vision::Pose& at_rest, double t) {
    cv::Mat sum(size, CV_32F, cv::Scalar(0));
    for (int s = 0; s < kSubFrames; ++s) {
      const double ts = t + exposure_ms / 1000.0 * ((s + 0.5) / kSubFrames - 0.5);
      cv::Mat frame(size, CV_8UC1, cv::Scalar(150));
      test::drawPosedMarker(frame, k, markerInCamera(head, at_rest, ts), kSideM, family, id);
      cv::Mat as_float;
      frame.convertTo(as_float, CV_32F);
      sum += as_float;
    }
    cv::Mat noisy(size, CV_32F);
    cv::theRNG().state = random();
    cv::randn(noisy, 0.0, noise);
    cv::Mat image;
    cv::Mat(sum / kSubFrames + noisy).convertTo(image, CV_8U);
    return image;
  };
  auto restingPose = [](double tilt) {
    vision::Pose at_rest;
    at_rest.rotation = test::markerRotation(tilt, 20.0, 35.0);
    at_rest.translation = cv::Vec3d(0.0, 0.0, kDistanceM);
    return at_rest;
  };
  for (const double tilt : tilts) {
    const vision::Pose at_rest = restingPose(tilt);
    vision::DetectorConfig config;
    config.search_decimate = decimate;
    vision::MarkerDetector detector(config);
    vision::MarkerTracker raw_tracker, smooth_tracker(smoothing);
    vision::MarkerPoses raw_poses(k), smooth_poses(k);
    Stats raw, smooth;
    std::vector<double> times;
    std::vector<std::optional<cv::Vec3d>> raw_positions, smooth_positions;
    for (int f = 0; f < frames; ++f) {
      const double t = f / fps;  // the middle of the exposure
      const cv::Mat image = render(test::MarkerFamily::ArbciBch, kMarkerId, at_rest, t);

      const vision::DetectionResult result = detector.detect(image);
      const vision::Pose truth = markerInCamera(head, at_rest, t);
      const auto size_of = [](int id) { return id == kMarkerId ? kSideM : 0.0; };
      auto poseOf = [&](vision::MarkerTracker& tracker,
                        vision::MarkerPoses& poses) -> std::optional<vision::Pose> {
        const auto markers = tracker.update(result.markers, detector.lastSquares(), t);
        const auto estimates = poses.estimate(markers, size_of);
        const auto it = estimates.find(kMarkerId);
        if (it == estimates.end()) return std::nullopt;
        return it->second.pose;
      };
      const auto raw_pose = poseOf(raw_tracker, raw_poses);
      const auto smooth_pose = poseOf(smooth_tracker, smooth_poses);
      raw.add(truth, raw_pose);
      smooth.add(truth, smooth_pose);
      times.push_back(t);
      raw_positions.push_back(raw_pose ? std::optional(raw_pose->translation) : std::nullopt);
      smooth_positions.push_back(smooth_pose ? std::optional(smooth_pose->translation)
                                             : std::nullopt);
    }
    const double raw_lag = bestLagMs(times, raw_positions, head, at_rest);
    const double smooth_lag = bestLagMs(times, smooth_positions, head, at_rest);
    for (const auto& [name, stats, lag] :
         {std::tuple{"raw", &raw, raw_lag}, std::tuple{"One-Euro", &smooth, smooth_lag}}) {
      std::printf("%5.0f %-9s %6.3f %7.2f %8.2f %7.2f %8.2f %9.2f %9.2f %6d %8.0f\n", tilt, name,
                  static_cast<double>(stats->found) / stats->frames,
                  Stats::mean(stats->position_mm), Stats::p95(stats->position_mm),
                  Stats::mean(stats->rotation_deg), Stats::p95(stats->rotation_deg),
                  stats->jitterMm(), stats->jitterDeg(), stats->flips, lag);
    }
  }
  std::printf(
      "\nlag ms: the delay at which the estimated positions best match the true ones (1 ms "
      "steps); the smoothing's added latency is the One-Euro row's lag minus the raw row's.\n");

  // Detection only, every detector on the same sequence drawn with its own marker.
  auto detectors = bench::detectorsUnderTest();
  std::printf(
      "\nframes in which the marker is read (its id, centre inside the true outline), and "
      "ms per frame, one core:\n%-30s",
      "detector");
  for (const double tilt : tilts) std::printf("  tilt %2.0f        ", tilt);
  std::printf("\n");
  for (auto& detector : detectors) {
    const int id = detector->family() == test::MarkerFamily::ArbciBch ? kMarkerId : kPeerId;
    std::printf("%-30s", detector->name().c_str());
    for (const double tilt : tilts) {
      const vision::Pose at_rest = restingPose(tilt);
      int read = 0;
      double seconds_spent = 0.0;
      for (int f = 0; f < frames; ++f) {
        const double t = f / fps;
        const cv::Mat image = render(detector->family(), id, at_rest, t);
        test::Corners truth;
        const auto corners = vision::markerCorners(kSideM);
        for (int c = 0; c < 4; ++c) {
          const cv::Point2d p = vision::project(markerInCamera(head, at_rest, t), k, corners[c]);
          truth[c] = cv::Point2f(static_cast<float>(p.x), static_cast<float>(p.y));
        }
        const auto start = std::chrono::steady_clock::now();
        const std::vector<test::FoundMarker> found = detector->detect(image);
        seconds_spent +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        read += test::scoreFrame({id}, {truth}, found, detector->orderedCorners()).found;
      }
      std::printf("  %5.3f %6.3f ms", static_cast<double>(read) / frames,
                  1000.0 * seconds_spent / frames);
    }
    std::printf("\n");
  }
  return 0;
}

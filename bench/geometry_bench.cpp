// Pose and undistortion: time and accuracy of Robust Planar Pose, OpenCV's IPPE and OpenCV's
// iterative solver on the same corner sets (5 cm markers at 0.3-1.0 m, 0.05 px corner noise, a
// 1280x720 camera of 900 px focal length), and the cost of the three undistortion modes.
//   geometry_bench [--poses N]
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include <opencv2/calib3d.hpp>

#include "arbci/vision/pose.h"
#include "arbci/vision/undistortion.h"
#include "support/posed_markers.h"

using namespace arbci::vision;
using Clock = std::chrono::steady_clock;

namespace {

struct Case {
  Pose truth;
  std::vector<cv::Point2d> image;
  double tilt_deg;
};

double seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{
      "Pose time and accuracy of RPP, IPPE and OpenCV's iterative solver; undistortion time of the "
      "three modes"};
  int poses = 2000;
  cli.add_option("--poses", poses, "random marker poses")
      ->check(CLI::Range(10, 1000000))
      ->capture_default_str();
  CLI11_PARSE(cli, argc, argv);
  const cv::Matx33d k(900, 0, 639.5, 0, 900, 359.5, 0, 0, 1);
  std::mt19937 random(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.05);
  const auto object = markerCorners(0.05);
  std::vector<Case> cases;
  for (int i = 0; i < poses; ++i) {
    const double distance = 0.3 + 0.7 * unit(random), tilt = 60.0 * unit(random);
    Case c;
    c.tilt_deg = tilt;
    c.truth.rotation =
        arbci::test::markerRotation(tilt, 360.0 * unit(random), 360.0 * unit(random));
    const cv::Vec3d direction((unit(random) - 0.5) * 0.9, (unit(random) - 0.5) * 0.5, 1.0);
    c.truth.translation = direction / cv::norm(direction) * distance;
    for (const cv::Point3d& p : object)
      c.image.push_back(project(c.truth, k, p) + cv::Point2d(noise(random), noise(random)));
    cases.push_back(c);
  }
  std::printf(
      "Pose of a 5 cm marker from its 4 corners, %d poses, 0.05 px corner noise, tilt 0-60 deg.\n",
      poses);
  std::printf("%-10s %-7s %9s %11s %11s %13s %13s\n", "method", "refine", "us/pose", "pos err %",
              "rot err deg", "rot <30deg", "rot >=30deg");
  for (PoseMethod method : {PoseMethod::Rpp, PoseMethod::Ippe, PoseMethod::Iterative}) {
    for (bool refine : {false, true}) {
      PoseOptions options;
      options.method = method;
      options.refine = refine;
      double position = 0.0, rotation = 0.0, rotation_low = 0.0, rotation_high = 0.0;
      int low = 0, high = 0;
      const auto start = Clock::now();
      std::vector<PoseEstimate> estimates;
      estimates.reserve(cases.size());
      for (const Case& c : cases) estimates.push_back(estimatePose(object, c.image, k, options));
      const double elapsed = seconds(start, Clock::now());
      for (size_t i = 0; i < cases.size(); ++i) {
        const double distance = cv::norm(cases[i].truth.translation);
        position += cv::norm(estimates[i].pose.translation - cases[i].truth.translation) / distance;
        const double r = rotationAngleDeg(estimates[i].pose.rotation, cases[i].truth.rotation);
        rotation += r;
        (cases[i].tilt_deg < 30.0 ? rotation_low : rotation_high) += r;
        (cases[i].tilt_deg < 30.0 ? low : high) += 1;
      }
      const double n = static_cast<double>(cases.size());
      std::printf("%-10s %-7s %9.1f %11.3f %11.3f %13.3f %13.3f\n", toString(method).c_str(),
                  refine ? "yes" : "no", 1e6 * elapsed / n, 100.0 * position / n, rotation / n,
                  rotation_low / std::max(1, low), rotation_high / std::max(1, high));
    }
  }

  // Undistortion with ARToolKitPlus's 2.5 mm lens scaled to each size.
  CameraModel camera;
  camera.source = "PGR M12x0.5 2.5 mm (ARToolKitPlus sample)";
  camera.image_size = {640, 480};
  camera.camera_matrix = cv::Matx33d(492.37, 0, 259.38, 0, 493.26, 213.46, 0, 0, 1);
  camera.distortion = {-0.4186, 0.1791, -0.00025, 0.00258, 0.0};
  std::printf("\nUndistortion (%s), per point and per whole image:\n", camera.source.c_str());
  std::printf("%-12s %-10s %12s %14s %12s\n", "size", "mode", "us/point", "ms/image", "setup ms");
  for (cv::Size size : {cv::Size(640, 480), cv::Size(1280, 720)}) {
    CameraModel scaled = camera.scaledTo(size);
    if (size.width * 3 != size.height * 4) {  // 16:9: crop-free model of the same lens
      scaled = camera;
      scaled.image_size = size;
      scaled.camera_matrix = cv::Matx33d(492.37 * 2, 0, 639.5, 0, 493.26 * 2, 359.5, 0, 0, 1);
    }
    cv::Mat image(size, CV_8UC1);
    cv::randu(image, 0, 256);
    for (UndistortMode mode :
         {UndistortMode::None, UndistortMode::Algorithmic, UndistortMode::LookupTable}) {
      const auto setup_start = Clock::now();
      const Undistorter lens(scaled, mode);
      const double setup = seconds(setup_start, Clock::now());
      std::vector<cv::Point2d> points;
      for (int i = 0; i < 20000; ++i)
        points.emplace_back(unit(random) * (size.width - 1), unit(random) * (size.height - 1));
      double sink = 0.0;
      const auto point_start = Clock::now();
      for (const cv::Point2d& p : points) sink += lens.undistort(p).x;
      const double per_point =
          seconds(point_start, Clock::now()) / static_cast<double>(points.size());
      cv::Mat out;
      const int repeats = 20;
      const auto image_start = Clock::now();
      for (int r = 0; r < repeats; ++r) lens.undistortImage(image, out);
      const double per_image = seconds(image_start, Clock::now()) / repeats;
      std::printf("%4dx%-7d %-10s %12.3f %14.3f %12.1f%s\n", size.width, size.height,
                  toString(mode).c_str(), 1e6 * per_point, 1e3 * per_image, 1e3 * setup,
                  sink == 12345.678 ? "!" : "");
    }
  }
  return 0;
}

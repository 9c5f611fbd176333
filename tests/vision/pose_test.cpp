// Pose from rendered markers with exact ground truth: Robust Planar Pose (and IPPE, iterative)
// accuracy for 5 cm markers at 0.3-1.0 m, no flips through face-on, multi-marker sets, and the
// three undistortion modes.
#include <gtest/gtest.h>

#include <numbers>
#include <random>
#include <tuple>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <opencv2/core.hpp>

#include "arbci/vision/marker_detector.h"
#include "arbci/vision/marker_set.h"
#include "arbci/vision/pose.h"
#include "arbci/vision/undistortion.h"
#include "support/posed_markers.h"
#include "support/shared_data.h"

namespace arbci::vision {
namespace {

// An HMD camera: 1280x720, 71 degrees wide.
CameraModel hmdCamera(std::vector<double> distortion = {}) {
  CameraModel camera;
  camera.image_size = {1280, 720};
  camera.camera_matrix = cv::Matx33d(900, 0, 639.5, 0, 900, 359.5, 0, 0, 1);
  camera.distortion = std::move(distortion);
  camera.source = "test camera";
  return camera;
}

std::vector<cv::Point2d> ideal(const MarkerDetection& m) {
  std::vector<cv::Point2d> points;
  for (const cv::Point2f& p : m.ideal_corners) points.emplace_back(p.x, p.y);
  return points;
}

const std::array<cv::Point3d, 4> kMarker5cm = markerCorners(0.05);

struct Errors {
  double position_fraction = 0.0, rotation_deg = 0.0;
};

// Renders one 5 cm BCH marker, detects it, estimates its pose; errors against the truth. With a
// lens, the frame is distorted and the detector undistorts.
struct Lens {
  std::shared_ptr<const Undistorter> undistorter;
  std::shared_ptr<const test::DistortingCamera> camera;
};

std::optional<Errors> measure(const CameraModel& camera, const Pose& truth, PoseMethod method,
                              const std::optional<Lens>& lens = std::nullopt, int decimate = 1) {
  cv::Mat frame(camera.image_size, CV_8UC1, cv::Scalar(190));
  test::drawPosedMarker(frame, camera.camera_matrix, truth, 0.05, test::MarkerFamily::ArbciBch,
                        321);
  DetectorConfig config;
  if (lens) {
    frame = (*lens->camera)(frame);
    config.lens = lens->undistorter;
  }
  config.search_decimate = decimate;
  MarkerDetector detector(config);
  const auto markers = detector.detect(frame).markers;
  if (markers.size() != 1 || markers[0].id != 321) return std::nullopt;
  PoseOptions options;
  options.method = method;
  const PoseEstimate estimate =
      estimatePose(kMarker5cm, ideal(markers[0]), camera.camera_matrix, options);
  const double distance = cv::norm(truth.translation);
  return Errors{cv::norm(estimate.pose.translation - truth.translation) / distance,
                rotationAngleDeg(estimate.pose.rotation, truth.rotation)};
}

Pose randomPose(std::mt19937& random, double min_tilt, double max_tilt) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double distance = 0.3 + 0.7 * unit(random);
  const cv::Matx33d r = test::markerRotation(min_tilt + (max_tilt - min_tilt) * unit(random),
                                             360 * unit(random), 360 * unit(random));
  // Anywhere in the central two thirds of the view.
  const cv::Vec3d direction((unit(random) - 0.5) * 0.9, (unit(random) - 0.5) * 0.5, 1.0);
  return {r, direction / cv::norm(direction) * distance};
}

// (distorting lens, the tracker's search_decimate): the decimated search finds its quads without
// the lens and refines them through it on the frame. Its corners on the thinnest marker here
// (52 x 10 px at 0.83 m, pinhole) are up to 0.43 px off, and its position 0.79 % (the full
// search: 0.44 px, 0.43 %; 3 px and a flipped pose before thin quads were refined on the halved
// frame first), so it is held to 1 %.
class PoseAccuracy : public testing::TestWithParam<std::tuple<bool, int>> {};

TEST_P(PoseAccuracy, RppWithinHalfAPercentAndHalfADegreeAt30To60DegreesTilt) {
  const auto [distorting, decimate] = GetParam();
  const CameraModel camera = hmdCamera(
      distorting ? std::vector<double>{-0.12, 0.04, 0.0005, -0.0004, 0.0} : std::vector<double>{});
  std::optional<Lens> lens;
  if (distorting) {
    lens = Lens{std::make_shared<Undistorter>(camera, UndistortMode::LookupTable),
                std::make_shared<test::DistortingCamera>(camera)};
  }
  std::mt19937 random(distorting ? 17 : 3);
  int measured = 0;
  for (int trial = 0; trial < 25; ++trial) {
    const Pose truth = randomPose(random, 30.0, 60.0);
    const auto errors = measure(camera, truth, PoseMethod::Rpp, lens, decimate);
    ASSERT_TRUE(errors.has_value()) << "marker not found at " << truth.translation;
    EXPECT_LT(errors->position_fraction, decimate == 1 ? 0.005 : 0.01)
        << "at " << truth.translation;
    EXPECT_LT(errors->rotation_deg, 0.5) << "at " << truth.translation;
    ++measured;
  }
  EXPECT_EQ(measured, 25);
}

INSTANTIATE_TEST_SUITE_P(Lens, PoseAccuracy,
                         testing::Combine(testing::Values(false, true), testing::Values(1, 2)),
                         [](const auto& info) {
                           return std::string(std::get<0>(info.param) ? "distorting" : "pinhole") +
                                  (std::get<1>(info.param) == 2 ? "_decimated" : "");
                         });

TEST(PoseAccuracy, PositionWithinHalfAPercentAtAnyTiltForEveryMethod) {
  const CameraModel camera = hmdCamera();
  for (PoseMethod method : {PoseMethod::Rpp, PoseMethod::Ippe, PoseMethod::Iterative}) {
    std::mt19937 random(5);
    for (int trial = 0; trial < 15; ++trial) {
      const auto errors = measure(camera, randomPose(random, 0.0, 60.0), method);
      ASSERT_TRUE(errors.has_value());
      EXPECT_LT(errors->position_fraction, 0.005) << toString(method);
    }
  }
}

// libapriltag's own canonical image of a tag (apriltag_to_image, as the tags are printed), upright
// in a white frame: the first corner reported is the printed top-left, then clockwise.
TEST(AprilTagCorners, TheCanonicalImageIsReadTopLeftFirstClockwise) {
  const int cell = 20;
  const cv::Mat tag = test::markerImage(test::MarkerFamily::AprilTag36h11, 0, cell);
  cv::Mat frame(tag.rows + 200, tag.cols + 200, CV_8UC1, cv::Scalar(255));
  tag.copyTo(frame(cv::Rect(100, 100, tag.cols, tag.rows)));
  DetectorConfig config;
  config.kind = MarkerKind::AprilTag;
  const auto markers = MarkerDetector(config).detect(frame).markers;
  ASSERT_EQ(markers.size(), 1u);
  EXPECT_EQ(markers[0].id, 0);
  // The black square spans cells 1..9 of the 10 (libapriltag's white ring is cell 0), in pixel
  // areas; OpenCV pixel centres sit 0.5 inside.
  const float lo = 100 + cell - 0.5f, hi = 100 + 9 * cell - 0.5f;
  const cv::Point2f printed[4] = {{lo, lo}, {hi, lo}, {hi, hi}, {lo, hi}};
  for (int k = 0; k < 4; ++k)
    EXPECT_LT(cv::norm(markers[0].corners[k] - printed[k]), 1.0)
        << "corner " << k << " at " << markers[0].corners[k];
}

// A tilted tag36h11 at a known pose: its pose from the reported corners is the true one (a tag
// whose corners came rotated would be 180 degrees off about its normal).
TEST(AprilTagCorners, APoseFromTheCornersIsTheTruePose) {
  const CameraModel camera = hmdCamera();
  std::mt19937 random(11);
  for (int trial = 0; trial < 8; ++trial) {
    const Pose truth = randomPose(random, 10.0, 50.0);
    cv::Mat frame(camera.image_size, CV_8UC1, cv::Scalar(190));
    const test::Corners drawn = test::drawPosedMarker(frame, camera.camera_matrix, truth, 0.05,
                                                      test::MarkerFamily::AprilTag36h11, 42);
    DetectorConfig config;
    config.kind = MarkerKind::AprilTag;
    const auto markers = MarkerDetector(config).detect(frame).markers;
    ASSERT_EQ(markers.size(), 1u) << "at " << truth.translation;
    for (int k = 0; k < 4; ++k) EXPECT_LT(cv::norm(markers[0].corners[k] - drawn[k]), 1.0);
    const PoseEstimate estimate = estimatePose(kMarker5cm, ideal(markers[0]), camera.camera_matrix);
    EXPECT_LT(rotationAngleDeg(estimate.pose.rotation, truth.rotation), 2.0)
        << "at " << truth.translation;
    EXPECT_LT(cv::norm(estimate.pose.translation - truth.translation),
              0.01 * cv::norm(truth.translation));
  }
}

TEST(PoseAmbiguity, NoFlipWhileAMarkerSweepsThroughFaceOn) {
  const CameraModel camera = hmdCamera();
  MarkerDetector detector(DetectorConfig{});
  std::optional<Pose> previous;
  int flips_without_memory = 0;
  for (int step = 0; step <= 50; ++step) {
    const double tilt = -25.0 + step;  // degrees, through 0
    const Pose truth{test::markerRotation(tilt, 20.0, 35.0), cv::Vec3d(0.02, -0.01, 0.55)};
    cv::Mat frame(camera.image_size, CV_8UC1, cv::Scalar(190));
    test::drawPosedMarker(frame, camera.camera_matrix, truth, 0.05, test::MarkerFamily::ArbciBch,
                          77);
    const auto markers = detector.detect(frame).markers;
    ASSERT_EQ(markers.size(), 1u) << "tilt " << tilt;
    PoseOptions options;
    options.previous = previous;
    const PoseEstimate estimate =
        estimatePose(kMarker5cm, ideal(markers[0]), camera.camera_matrix, options);
    // A flip mirrors the tilt: an error of about twice the tilt.
    const double error = rotationAngleDeg(estimate.pose.rotation, truth.rotation);
    if (previous) {
      EXPECT_LT(error, 3.0) << "tilt " << tilt;
    }
    previous = estimate.pose;
    const PoseEstimate memoryless =
        estimatePose(kMarker5cm, ideal(markers[0]), camera.camera_matrix, {});
    flips_without_memory += rotationAngleDeg(memoryless.pose.rotation, truth.rotation) > 3.0;
  }
  RecordProperty("flips_without_previous_pose", flips_without_memory);
}

TEST(MarkerSets, ABoardOfFourIsMoreAccurateThanAnyOfItsMarkers) {
  const CameraModel camera = hmdCamera();
  // 2x2 markers of 5 cm, 7 cm apart, on a board.
  std::vector<MarkerPlacement> placements;
  const int ids[4] = {10, 11, 12, 13};
  for (int i = 0; i < 4; ++i) {
    placements.push_back(
        {ids[i],
         0.05,
         {cv::Matx33d::eye(), cv::Vec3d(i % 2 ? 0.035 : -0.035, i < 2 ? 0.035 : -0.035, 0)}});
  }
  const MarkerSet board(placements);
  ASSERT_TRUE(board.planar());
  std::mt19937 random(9);
  double set_error = 0.0, single_error[4] = {};
  for (int view = 0; view < 12; ++view) {
    const Pose truth = randomPose(random, 20.0, 50.0);
    const Pose T_cam_set{truth.rotation, truth.translation * (0.8 / cv::norm(truth.translation))};
    cv::Mat frame(camera.image_size, CV_8UC1, cv::Scalar(190));
    for (const MarkerPlacement& p : placements) {
      test::drawPosedMarker(frame, camera.camera_matrix, T_cam_set * p.T_set_marker, 0.05,
                            test::MarkerFamily::ArbciBch, p.id);
    }
    MarkerDetector detector(DetectorConfig{});
    const auto markers = detector.detect(frame).markers;
    ASSERT_EQ(markers.size(), 4u);
    const auto set_pose = estimateSetPose(board, markers, camera.camera_matrix);
    ASSERT_TRUE(set_pose.has_value());
    EXPECT_EQ(set_pose->used_ids.size(), 4u);
    set_error += rotationAngleDeg(set_pose->estimate.pose.rotation, T_cam_set.rotation);
    for (const MarkerDetection& m : markers) {
      const int index = m.id - 10;
      const PoseEstimate single = estimatePose(kMarker5cm, ideal(m), camera.camera_matrix);
      const Pose T_cam_set_single = single.pose * placements[index].T_set_marker.inverse();
      single_error[index] += rotationAngleDeg(T_cam_set_single.rotation, T_cam_set.rotation);
    }
  }
  for (double e : single_error)
    EXPECT_LT(set_error, e) << "the set is not better than a single marker";
}

TEST(MarkerSets, ArToolKitBoardConfigurationReadsAndPosesTheRealBoard) {
  const MarkerSet board = MarkerSet::loadArToolKitConfig(
      test::sharedData("vision/artoolkitplus_samples/markerboard_480-499.cfg"));
  ASSERT_EQ(board.markers().size(), 20u);
  EXPECT_NEAR(board.markers()[0].size_m, 0.040, 1e-12);
  // Marker 480 sits at (-100, 75) mm: its top-left corner at (-120, 95).
  EXPECT_NEAR(board.cornersOf(480)->at(0).x, -0.120, 1e-12);
  EXPECT_NEAR(board.cornersOf(480)->at(0).y, 0.095, 1e-12);
  // ARToolKitPlus poses the bent board photo at t = (4.49, -14.77, 177.61) mm from 10 markers.
  const CameraModel camera =
      CameraModel::load(test::sharedData("vision/artoolkitplus_samples/PGR_M12x0.5_2.5mm.cal"))
          .scaledTo({320, 240});
  DetectorConfig config;
  config.kind = MarkerKind::Simple;
  config.threshold.mode = ThresholdMode::Constant;
  config.threshold.value = 160;
  config.lens = std::make_shared<Undistorter>(camera, UndistortMode::LookupTable);
  MarkerDetector detector(config);
  const cv::Mat image =
      cv::imread(test::sharedData("vision/artoolkitplus_samples/markerboard_480-499_from_raw.png"),
                 cv::IMREAD_GRAYSCALE);
  const auto pose = estimateSetPose(board, detector.detect(image).markers, camera.camera_matrix);
  ASSERT_TRUE(pose.has_value());
  EXPECT_GE(pose->used_ids.size(), 10u);
  const cv::Vec3d t = pose->estimate.pose.translation * 1000.0;
  EXPECT_LT(cv::norm(t - cv::Vec3d(4.49, -14.77, 177.61)), 10.0) << t;
}

TEST(Undistortion, TheThreeModesAgreeOnPointsAndImages) {
  const CameraModel camera =
      CameraModel::load(test::sharedData("vision/artoolkitplus_samples/PGR_M12x0.5_2.5mm.cal"));
  const Undistorter none(camera, UndistortMode::None),
      algorithmic(camera, UndistortMode::Algorithmic), table(camera, UndistortMode::LookupTable);
  double worst_table = 0.0, worst_round_trip = 0.0;
  for (double y = 5.3; y < 475; y += 23.7) {
    for (double x = 3.1; x < 637; x += 21.9) {
      const cv::Point2d p(x, y);
      EXPECT_EQ(none.undistort(p), p);
      const cv::Point2d a = algorithmic.undistort(p), t = table.undistort(p);
      worst_table = std::max(worst_table, cv::norm(a - t));
      worst_round_trip = std::max(worst_round_trip, cv::norm(algorithmic.distort(a) - p));
    }
  }
  EXPECT_LT(worst_table, 0.05);
  EXPECT_LT(worst_round_trip, 1e-4);
  // Images: the table's remap and the per-call maps give the same picture.
  cv::Mat image(480, 640, CV_8UC1);
  cv::randu(image, 0, 256);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 3.0);
  cv::Mat from_table, from_algorithm;
  table.undistortImage(image, from_table);
  algorithmic.undistortImage(image, from_algorithm);
  cv::Mat difference;
  cv::absdiff(from_table, from_algorithm, difference);
  EXPECT_LT(cv::mean(difference(cv::Rect(40, 40, 560, 400)))[0], 0.5);
}

TEST(CameraLookingAt, TheTargetIsOnTheAxisTheWorldsRightIsImageRightAndUpIsImageUp) {
  const cv::Matx33d k(900, 0, 639.5, 0, 900, 359.5, 0, 0, 1);
  const cv::Vec3d eye(0.1, 1.4, 0.5), target(0.0, 0.65, 0.0);
  const Pose T_cam_world = cameraLookingAt(eye, target);
  EXPECT_NEAR(cv::norm(T_cam_world.apply(eye)), 0.0, 1e-12);
  const cv::Point2d centre = project(T_cam_world, k, cv::Point3d(0.0, 0.65, 0.0));
  EXPECT_NEAR(centre.x, 639.5, 1e-9);
  EXPECT_NEAR(centre.y, 359.5, 1e-9);
  // The camera faces -y: the world's -x is on its right; +z (up) is up in the image.
  EXPECT_GT(project(T_cam_world, k, cv::Point3d(-0.1, 0.65, 0.0)).x, 700.0);
  EXPECT_LT(project(T_cam_world, k, cv::Point3d(0.0, 0.65, 0.1)).y, 300.0);
  EXPECT_NEAR(cv::determinant(T_cam_world.rotation), 1.0, 1e-12);
  // Straight down: still a rotation, image x along the world's x.
  const Pose down = cameraLookingAt({0.0, 0.6, 1.0}, {0.0, 0.6, 0.0});
  EXPECT_NEAR(cv::determinant(down.rotation), 1.0, 1e-12);
  EXPECT_GT(project(down, k, cv::Point3d(0.1, 0.6, 0.0)).x, 700.0);
}

}  // namespace
}  // namespace arbci::vision

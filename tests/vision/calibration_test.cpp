// Camera calibration on OpenCV's sample chessboards against the reference in SOURCES.md, the
// incremental API's rejections and coverage, ChArUco, stereo, and calibration files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "arbci/vision/calibration.h"
#include "arbci/vision/pose.h"
#include "support/shared_data.h"
#include "support/synthetic_markers.h"

namespace arbci::vision {
namespace {

const int kViews[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14};

cv::Mat chessboard(const char* side, int index) {
  char name[64];
  std::snprintf(name, sizeof name, "vision/opencv_samples_chessboard/%s%02d.jpg", side, index);
  return cv::imread(test::sharedData(name), cv::IMREAD_GRAYSCALE);
}

CalibrationBoard sampleBoard() {
  CalibrationBoard board;
  board.inner_corners = {9, 6};
  board.square_m = 0.025;
  return board;
}

TEST(Calibration, OpenCvLeftChessboardsGiveTheReferenceIntrinsics) {
  IncrementalCalibrator calibrator(sampleBoard());
  for (int i : kViews)
    EXPECT_EQ(calibrator.addView(chessboard("left", i)).outcome, ViewOutcome::Accepted) << i;
  const CalibrationResult result = calibrator.calibrate();
  // Reference (SOURCES.md): RMS 0.4088, fx 536.074, fy 536.017, cx 342.370, cy 235.538.
  EXPECT_NEAR(result.rms_px, 0.4088, 0.05);
  EXPECT_NEAR(result.camera.fx(), 536.074, 536.074 * 0.005);
  EXPECT_NEAR(result.camera.fy(), 536.017, 536.017 * 0.005);
  EXPECT_NEAR(result.camera.cx(), 342.370, 342.370 * 0.005);
  EXPECT_NEAR(result.camera.cy(), 235.538, 235.538 * 0.005);
  ASSERT_EQ(result.per_view_rms_px.size(), 13u);
  // left02 is the outlier view (1.22 px).
  const auto worst = std::max_element(result.per_view_rms_px.begin(), result.per_view_rms_px.end());
  EXPECT_EQ(result.view_names[worst - result.per_view_rms_px.begin()], "view 2");
  EXPECT_NEAR(*worst, 1.22, 0.1);
  CalibrationFlags fixed;
  fixed.fix_aspect_ratio = true;
  const CalibrationResult aspect = calibrator.calibrate(fixed);
  EXPECT_NEAR(aspect.camera.fx(), 536.109, 536.109 * 0.005);
  EXPECT_DOUBLE_EQ(aspect.camera.fx(), aspect.camera.fy());
}

TEST(Calibration, RejectsBoardlessBlurredDuplicateAndMisfitViewsWithAReason) {
  IncrementalCalibrator calibrator(sampleBoard());
  ASSERT_EQ(calibrator.addView(chessboard("left", 1), "first").outcome, ViewOutcome::Accepted);
  EXPECT_DOUBLE_EQ(calibrator.coverageFraction(), calibrator.coverageFraction());
  const double coverage_one = calibrator.coverageFraction();
  const ViewResult duplicate = calibrator.addView(chessboard("left", 1));
  EXPECT_EQ(duplicate.outcome, ViewOutcome::Duplicate);
  EXPECT_NE(duplicate.reason.find("first"), std::string::npos);
  cv::Mat blurred;
  cv::GaussianBlur(chessboard("left", 3), blurred, cv::Size(0, 0), 3.0);
  const ViewResult blur = calibrator.addView(blurred);
  EXPECT_EQ(blur.outcome, ViewOutcome::Blurred) << blur.reason;
  EXPECT_NE(blur.reason.find("px"), std::string::npos);
  EXPECT_EQ(calibrator.addView(cv::Mat(480, 640, CV_8UC1, cv::Scalar(128))).outcome,
            ViewOutcome::NoBoard);
  EXPECT_EQ(calibrator.addView(cv::Mat(240, 320, CV_8UC1, cv::Scalar(128))).outcome,
            ViewOutcome::WrongSize);
  EXPECT_THROW(calibrator.calibrate(), std::runtime_error);
  for (int i : {5, 9, 12}) calibrator.addView(chessboard("left", i));
  EXPECT_GT(calibrator.coverageFraction(), coverage_one);
  EXPECT_EQ(calibrator.viewCount(), 4u);
}

TEST(Calibration, CharucoViewsCalibrateASyntheticCamera) {
  // The tutorial's ChArUco board (5x7 squares, DICT_6X6_250) seen by a camera with f = 800 px
  // from eight sides.
  const cv::Mat board =
      cv::imread(test::sharedData("vision/opencv_contrib_aruco_tutorial/charucoboard.png"),
                 cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(board.empty());
  CalibrationBoard spec;
  spec.kind = CalibrationBoard::Kind::Charuco;
  spec.squares = {5, 7};
  spec.square_m = 0.04;
  spec.marker_m = 0.02;
  IncrementalCalibrator calibrator(spec);
  const cv::Matx33d k(800, 0, 319.5, 0, 800, 239.5, 0, 0, 1);
  // The image holds 5 x 7 squares of 200 px inside an 80 px margin: 5.8 x 7.8 squares of 4 cm.
  const double w = 0.232, h = 0.312;
  for (int view = 0; view < 8; ++view) {
    const double angle = view * CV_PI / 4;
    cv::Matx33d r;
    cv::Rodrigues(cv::Vec3d(std::cos(angle), std::sin(angle), 0) * 0.45, r);
    const Pose pose{r * cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1),
                    cv::Vec3d(0.01 * (view % 3), -0.01, 0.55)};
    test::Corners outline;
    const cv::Point3d corners[4] = {
        {-w / 2, h / 2, 0}, {w / 2, h / 2, 0}, {w / 2, -h / 2, 0}, {-w / 2, -h / 2, 0}};
    for (int c = 0; c < 4; ++c) {
      const cv::Point2d p = project(pose, k, corners[c]);
      outline[c] = cv::Point2f(static_cast<float>(p.x), static_cast<float>(p.y));
    }
    cv::Mat frame(480, 640, CV_8UC1, cv::Scalar(120));
    test::drawWarped(frame, board, outline);
    EXPECT_EQ(calibrator.addView(frame).outcome, ViewOutcome::Accepted) << "view " << view;
  }
  const CalibrationResult result = calibrator.calibrate({true, true, true});
  EXPECT_NEAR(result.camera.fx(), 800.0, 800.0 * 0.02);
  EXPECT_LT(result.rms_px, 0.5);
}

TEST(Calibration, StereoPairsGiveTheBaselineAndRectify) {
  std::vector<cv::Mat> left, right;
  for (int i : kViews) {
    left.push_back(chessboard("left", i));
    right.push_back(chessboard("right", i));
  }
  const StereoResult stereo = calibrateStereo(sampleBoard(), left, right);
  EXPECT_GE(stereo.pairs, 10);
  EXPECT_LT(stereo.rms_px, 1.0);
  // The sample rig's cameras sit side by side: the baseline is mostly along x.
  const cv::Vec3d t = stereo.cameras.translation;
  EXPECT_GT(std::abs(t[0]), 3.0 * std::hypot(t[1], t[2]));
  // After rectification, the same corner lies on the same row in both images.
  cv::Mat r1, r2, p1, p2, q;
  cv::stereoRectify(cv::Mat(stereo.cameras.left.camera_matrix), stereo.cameras.left.distortion,
                    cv::Mat(stereo.cameras.right.camera_matrix), stereo.cameras.right.distortion,
                    cv::Size(640, 480), cv::Mat(stereo.cameras.rotation),
                    cv::Mat(stereo.cameras.translation), r1, r2, p1, p2, q);
  std::vector<cv::Point2f> lc, rc;
  ASSERT_TRUE(cv::findChessboardCorners(left[0], {9, 6}, lc));
  ASSERT_TRUE(cv::findChessboardCorners(right[0], {9, 6}, rc));
  std::vector<cv::Point2f> lr, rr;
  cv::undistortPoints(lc, lr, cv::Mat(stereo.cameras.left.camera_matrix),
                      stereo.cameras.left.distortion, r1, p1);
  cv::undistortPoints(rc, rr, cv::Mat(stereo.cameras.right.camera_matrix),
                      stereo.cameras.right.distortion, r2, p2);
  double worst = 0.0;
  for (size_t i = 0; i < lr.size(); ++i)
    worst = std::max(worst, static_cast<double>(std::abs(lr[i].y - rr[i].y)));
  EXPECT_LT(worst, 1.5);
  const auto path = std::filesystem::temp_directory_path() / "arbci_stereo.yml";
  stereo.cameras.save(path);
  const StereoCameras loaded = StereoCameras::load(path);
  EXPECT_NEAR(cv::norm(loaded.translation - stereo.cameras.translation), 0.0, 1e-9);
  EXPECT_NEAR(loaded.left.fx(), stereo.cameras.left.fx(), 1e-9);
}

TEST(CalibrationFiles, OpenCvFilesLoadUnchangedAndRoundTrip) {
  const CameraModel reference =
      CameraModel::load(test::sharedData("vision/opencv_samples_chessboard/left_intrinsics.yml"));
  EXPECT_EQ(reference.image_size, cv::Size(640, 480));
  EXPECT_NEAR(reference.fx(), 535.916, 0.001);
  ASSERT_EQ(reference.distortion.size(), 5u);
  EXPECT_NEAR(reference.distortion[4], 0.23839, 1e-5);
  EXPECT_NEAR(reference.rms_px, 0.3926, 1e-4);
  for (const char* extension : {".yml", ".xml"}) {
    const auto path =
        std::filesystem::temp_directory_path() / (std::string("arbci_camera") + extension);
    reference.save(path);
    const CameraModel loaded = CameraModel::load(path);
    EXPECT_EQ(loaded.image_size, reference.image_size);
    EXPECT_NEAR(cv::norm(cv::Mat(loaded.camera_matrix), cv::Mat(reference.camera_matrix)), 0.0,
                1e-9);
    EXPECT_EQ(loaded.distortion, reference.distortion);
  }
  const CameraModel artk =
      CameraModel::load(test::sharedData("vision/artoolkitplus_samples/PGR_M12x0.5_2.5mm.cal"));
  EXPECT_NEAR(artk.fx(), 492.370, 0.001);
  EXPECT_NEAR(artk.distortion[0], -0.41862, 1e-5);
  const CameraModel half = artk.scaledTo({320, 240});
  EXPECT_NEAR(half.fx(), 246.185, 0.001);
}

void expectError(const std::filesystem::path& path, const std::string& text,
                 const std::string& mentions) {
  std::ofstream(path) << text;
  try {
    CameraModel::load(path);
    FAIL() << "accepted: " << text;
  } catch (const CalibrationFileError& error) {
    EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find(mentions), std::string::npos) << error.what();
  }
}

TEST(CalibrationFiles, BadFilesNameTheFileAndTheField) {
  const auto dir = std::filesystem::temp_directory_path();
  expectError(dir / "missing_k.yml", "%YAML:1.0\nimage_width: 640\nimage_height: 480\n",
              "camera_matrix");
  expectError(dir / "no_size.yml",
              "%YAML:1.0\ncamera_matrix: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n  data: "
              "[500, 0, 320, 0, 500, 240, 0, 0, 1]\n",
              "image_width");
  expectError(dir / "negative_f.yml",
              "%YAML:1.0\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n  "
              "rows: 3\n  cols: 3\n  dt: d\n  data: [-500, 0, 320, 0, 500, 240, 0, 0, 1]\n",
              "focal");
  expectError(dir / "garbage.yml", "this is not yaml: [", "YAML");
  EXPECT_THROW(CameraModel::load(dir / "does_not_exist.yml"), CalibrationFileError);
  const CameraModel camera =
      CameraModel::load(test::sharedData("vision/opencv_samples_chessboard/left_intrinsics.yml"));
  try {
    camera.checkImageSize({1280, 800});
    FAIL();
  } catch (const CalibrationFileError& error) {
    EXPECT_NE(std::string(error.what()).find("image_width"), std::string::npos) << error.what();
  }
  EXPECT_NO_THROW(camera.checkImageSize({320, 240}));
}

}  // namespace
}  // namespace arbci::vision

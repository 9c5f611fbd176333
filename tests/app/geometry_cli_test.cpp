// `arbci calibrate` and `arbci detect --camera`: a calibration file OpenCV reads, progress per
// view, and poses in the detection JSON.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <sstream>

#include "support/run_process.h"
#include "support/shared_data.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;

TEST(CalibrateCommand, WritesAnOpenCvCalibrationWithProgressPerView) {
  std::vector<std::string> arguments{"calibrate", "--board", "9x6", "--square-mm", "25"};
  for (int i : {1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14}) {
    char name[64];
    std::snprintf(name, sizeof name, "vision/opencv_samples_chessboard/left%02d.jpg", i);
    arguments.push_back(sharedData(name));
  }
  const auto out = std::filesystem::temp_directory_path() / "arbci_cli_left.yml";
  arguments.insert(arguments.end(), {"--out", out.string()});
  const ProcessResult result = runProcess(kArbci, arguments);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.err.find("[13/13]"), std::string::npos) << result.err;
  EXPECT_NE(result.out.find("rms 0.40"), std::string::npos) << result.out;
  cv::FileStorage file(out.string(), cv::FileStorage::READ);
  ASSERT_TRUE(file.isOpened());
  cv::Mat k;
  file["camera_matrix"] >> k;
  EXPECT_NEAR(k.at<double>(0, 0), 536.07, 2.7);
  EXPECT_EQ(static_cast<int>(file["image_width"]), 640);
}

TEST(CalibrateCommand, TooFewViewsAndBadBoardsGiveAReason) {
  const auto out = std::filesystem::temp_directory_path() / "arbci_cli_bad.yml";
  const ProcessResult few =
      runProcess(kArbci, {"calibrate", sharedData("vision/opencv_samples_chessboard/left01.jpg"),
                          "--out", out.string()});
  EXPECT_NE(few.exit_code, 0);
  EXPECT_NE(few.err.find("at least 3"), std::string::npos) << few.err;
  const ProcessResult board =
      runProcess(kArbci, {"calibrate", "--board", "9by6", "x.png", "--out", out.string()});
  EXPECT_NE(board.exit_code, 0);
  EXPECT_NE(board.err.find("--board"), std::string::npos) << board.err;
}

TEST(DetectCommand, WithACameraAddsUndistortedCornersAndPoses) {
  const std::string samples = sharedData("vision/artoolkitplus_samples/");
  const ProcessResult result = runProcess(
      kArbci, {"detect", "--kind", "simple", "--border", "0.125", "--threshold", "160", "--camera",
               samples + "PGR_M12x0.5_2.5mm.cal", "--marker-size-mm", "40", "--marker-set",
               samples + "markerboard_480-499.cfg", samples + "markerboard_480-499_from_raw.png"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json frame = nlohmann::json::parse(result.out);
  ASSERT_GE(frame["markers"].size(), 10u);
  for (const auto& marker : frame["markers"]) {
    ASSERT_TRUE(marker.contains("pose"));
    ASSERT_TRUE(marker.contains("ideal_corners"));
    const double z = marker["pose"]["t_m"][2];
    EXPECT_GT(z, 0.12);  // the board lies 15-25 cm from the camera
    EXPECT_LT(z, 0.30);
  }
  const auto& t = frame["set_pose"]["t_m"];
  // ARToolKitPlus: (4.49, -14.77, 177.61) mm.
  EXPECT_NEAR(t[2].get<double>(), 0.1776, 0.01);
  const ProcessResult wrong = runProcess(kArbci, {"detect", "--camera", samples + "no_such.cal",
                                                  samples + "markerboard_480-499_from_raw.png"});
  EXPECT_NE(wrong.exit_code, 0);
  EXPECT_NE(wrong.err.find("no_such.cal"), std::string::npos) << wrong.err;
}

}  // namespace
}  // namespace arbci::test

// Which HMD frames a session keeps (hmd.screenshots), from phase changes alone: every trial
// phase, trial 1's only, the end's only, or none; a flashing phase waits for a lit frame; and an
// image that cannot be written is counted with its reason, never thrown.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "hmd/image_writer.h"
#include "hmd/phase_screenshots.h"
#include "support/test_files.h"

namespace arbci::app {
namespace {

// The files kept over a calibration and two trials' phases and the end.
std::vector<std::string> kept(const std::string& mode) {
  PhaseScreenshots shots("/day", mode);
  bci::FrameStimulus lit;
  lit.lit = {1};
  std::vector<std::string> out;
  auto enter = [&](bci::Phase phase, int trial) {
    shots.phaseEntered(phase, trial);
    if (const auto path = shots.take(lit)) out.push_back(path->filename().string());
  };
  enter(bci::Phase::CalibrationFlashing, 0);
  for (int trial : {1, 2}) {
    enter(bci::Phase::ObjectFlashing, trial);
    enter(bci::Phase::Grasping, trial);
  }
  enter(bci::Phase::Finished, 2);
  return out;
}

TEST(PhaseScreenshots, TheSettingChoosesTheFramesKept) {
  using V = std::vector<std::string>;
  EXPECT_EQ(kept("phases"), (V{"hmd_calibration.png", "hmd_trial1_1_objects_flashing.png",
                               "hmd_trial1_3_grasping.png", "hmd_trial2_1_objects_flashing.png",
                               "hmd_trial2_3_grasping.png", "hmd_finished.png"}));
  EXPECT_EQ(kept("first_trial"), (V{"hmd_calibration.png", "hmd_trial1_1_objects_flashing.png",
                                    "hmd_trial1_3_grasping.png", "hmd_finished.png"}));
  EXPECT_EQ(kept("end"), (V{"hmd_finished.png"}));
  EXPECT_TRUE(kept("none").empty());
}

TEST(PhaseScreenshots, AFlashingPhaseWaitsForALitFrame) {
  PhaseScreenshots shots("/day", "phases");
  shots.phaseEntered(bci::Phase::CellFlashing, 3);
  EXPECT_FALSE(shots.take(bci::FrameStimulus{}));
  bci::FrameStimulus lit;
  lit.lit = {2};
  const auto path = shots.take(lit);
  ASSERT_TRUE(path);
  EXPECT_EQ(path->filename(), "hmd_trial3_4_grid_flashing.png");
}

TEST(ImageWriter, AnImageThatCannotBeWrittenIsCountedWithItsReason) {
  const auto folder = test::freshTempPath("image_writer", "ok");
  std::filesystem::create_directories(folder);
  ImageWriter writer;
  writer.write(folder / "a.png", cv::Mat(8, 8, CV_8UC3, cv::Scalar(10, 20, 30)));
  writer.write(folder / "missing" / "b.png", cv::Mat(8, 8, CV_8UC3, cv::Scalar(10, 20, 30)));
  writer.flush();
  EXPECT_EQ(writer.written(), 1);
  EXPECT_EQ(writer.failed(), 1);
  ASSERT_TRUE(writer.failure());
  EXPECT_NE(writer.failure()->find("missing/b.png"), std::string::npos) << *writer.failure();
  EXPECT_NE(writer.failure()->find("No such file or directory"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(folder / "a.png"));
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace arbci::app

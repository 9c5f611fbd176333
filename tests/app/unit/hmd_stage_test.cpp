// The HMD's render stage on hand-built records, headless (EGL): what the paradigm shows this frame
// drawn over the camera images (both eyes), the photodiode patch read back from the frame drawn,
// an unchanged frame not drawn again, the phase's screenshot written once a flash shows, and the
// frame copied into each eye's image as an OpenXR headset is given it.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "arbci/render/framebuffer.h"
#include "arbci/render/gl_context.h"
#include "arbci/render/openxr_display.h"
#include "hmd/hmd_stage.h"
#include "support/stage_bench.h"
#include "support/test_camera.h"

namespace arbci::app {
namespace {

using test::camera640;

// Tracking as it stands with the table in view: a grey camera image each eye (the same picture
// from frame to frame, as tracking keeps it while nothing moves), the cameras' poses over the
// table.
void tracked(session::CycleRecord& r) {
  static const cv::Mat grey(480, 640, CV_8UC3, cv::Scalar(150, 150, 150));
  session::TrackingPart& t = r.tracking;
  t.left_image = t.right_image = grey;
  t.stereo = true;
  t.left_camera = t.right_camera = camera640();
  t.T_cam_world_left = vision::cameraLookingAt({-0.032, 1.30, 0.45}, {0.0, 0.65, 0.0});
  t.T_cam_world_right = vision::cameraLookingAt({0.032, 1.30, 0.45}, {0.0, 0.65, 0.0});
  t.world = std::make_shared<const vision::WorldModel>();
  r.paradigm.slots = {0, 1, 2, 3};
}

class HmdStageTest : public ::testing::Test {
 protected:
  HmdStageTest() : bench_("hmd"), context_(render::createHeadlessContext({64, 64})) {
    session::SessionConfig config;
    config.eeg.photodiode_channel = "Photodiode";
    session::CycleRecord warm_up;
    tracked(warm_up);
    stage_ = std::make_unique<HmdStage>(HmdSettings::of(config), bench_.folder(), *context_,
                                        warm_up, bench_.services());
  }
  test::StageBench bench_;
  std::unique_ptr<render::GlContext> context_;
  std::unique_ptr<HmdStage> stage_;
};

TEST_F(HmdStageTest, AFlashOnTheGridLightsThePatchInBothEyesAndIsReadBack) {
  tracked(bench_.record);
  bench_.record.paradigm.phase_changes.push_back({bci::Phase::CellFlashing, 1, ""});
  bci::FrameStimulus& shown = bench_.record.paradigm.stimulus;
  shown.phase = bci::Phase::CellFlashing;
  shown.grid_visible = true;
  shown.lit = {2};  // a row
  bench_.step(*stage_);
  const session::DisplayPart& display = bench_.record.display;
  EXPECT_TRUE(display.redrawn);
  EXPECT_TRUE(display.photodiode);
  ASSERT_TRUE(display.patch_lit.has_value());
  EXPECT_TRUE(*display.patch_lit);
  // The phase's screenshot: a flash shows, so this frame is kept.
  session::Cycle end = bench_.cycle();
  stage_->stop(end, "finished");
  const auto shot = bench_.folder() / "hmd_trial1_4_grid_flashing.png";
  ASSERT_TRUE(std::filesystem::exists(shot));
  const cv::Mat image = cv::imread(shot.string());
  ASSERT_EQ(image.size(), cv::Size(1280, 480));
  for (const int eye : {0, 640}) {
    const cv::Mat half = image(cv::Rect(eye, 0, 640, 480));
    EXPECT_GT(cv::mean(half(cv::Rect(2, 2, 24, 24)))[0], 225) << "eye at x=" << eye;
    EXPECT_GT(cv::mean(half(cv::Rect(40, 360, 200, 100)))[0], 80) << "eye at x=" << eye;
    // The grid's light lines on the grey table in the middle of the view.
    int white = 0;
    const cv::Mat middle = half(cv::Rect(150, 100, 350, 240));
    for (int y = 0; y < middle.rows; ++y)
      for (int x = 0; x < middle.cols; ++x) {
        const cv::Vec3b p = middle.at<cv::Vec3b>(y, x);
        white += p[0] > 200 && p[1] > 200 && p[2] > 200;
      }
    EXPECT_GT(white, 400) << "eye at x=" << eye;
  }
}

TEST_F(HmdStageTest, AnUnchangedFrameIsNotDrawnAgainAndADarkOneReadsBackDark) {
  tracked(bench_.record);
  bench_.record.paradigm.stimulus.phase = bci::Phase::ObjectFlashing;
  bench_.record.paradigm.stimulus.lit = {1};
  bench_.step(*stage_);
  EXPECT_TRUE(*bench_.record.display.patch_lit);
  bench_.next();
  // The flash over: drawn again, the patch dark.
  tracked(bench_.record);
  bench_.record.paradigm.stimulus.phase = bci::Phase::ObjectFlashing;
  bench_.step(*stage_);
  EXPECT_TRUE(bench_.record.display.redrawn);
  ASSERT_TRUE(bench_.record.display.patch_lit.has_value());
  EXPECT_FALSE(*bench_.record.display.patch_lit);
  bench_.next();
  tracked(bench_.record);
  bench_.record.paradigm.stimulus.phase = bci::Phase::ObjectFlashing;
  bench_.step(*stage_);
  EXPECT_FALSE(bench_.record.display.redrawn);
  EXPECT_FALSE(bench_.record.display.patch_lit.has_value());
}

// A row of the grid flashing: the grid and the lit photodiode patch in both eyes.
void drawFlash(test::StageBench& bench, HmdStage& stage) {
  tracked(bench.record);
  bci::FrameStimulus& shown = bench.record.paradigm.stimulus;
  shown.phase = bci::Phase::CellFlashing;
  shown.grid_visible = true;
  shown.lit = {2};
  bench.step(stage);
  ASSERT_TRUE(bench.record.display.redrawn);
}

bool samePixels(const render::RgbaImage& a, const render::RgbaImage& b, int b_x0) {
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      for (int c = 0; c < 4; ++c)
        if (a.at(x, y)[c] != b.at(b_x0 + x, y)[c]) return false;
  return true;
}

TEST_F(HmdStageTest, EachEyesImageForTheHeadsetIsItsHalfOfTheFrameAsDrawn) {
  drawFlash(bench_, *stage_);
  const render::Size eye{640, 480};
  ASSERT_EQ(stage_->size(), (render::Size{1280, 480}));
  render::Framebuffer left(eye), right(eye);
  render::copyEyes(stage_->texture(), stage_->size(), left.colorTexture(), right.colorTexture(),
                   eye);
  const render::RgbaImage frame = render::readTexture(stage_->texture(), stage_->size());
  const render::RgbaImage l = render::readTexture(left.colorTexture(), eye);
  const render::RgbaImage r = render::readTexture(right.colorTexture(), eye);
  EXPECT_TRUE(samePixels(l, frame, 0));
  EXPECT_TRUE(samePixels(r, frame, 640));
  // The eyes differ (the cameras are apart), and each carries the lit patch in its corner.
  EXPECT_FALSE(samePixels(l, frame, 640));
  for (const render::RgbaImage* image : {&l, &r}) EXPECT_GT(image->at(10, 10)[0], 225);
}

TEST_F(HmdStageTest, AHeadsetsSmallerEyeImageIsTheWholeHalfScaled) {
  drawFlash(bench_, *stage_);
  const render::Size eye{320, 240};  // the runtime's largest image, smaller than the HMD's eye
  render::Framebuffer left(eye), right(eye);
  render::copyEyes(stage_->texture(), stage_->size(), left.colorTexture(), right.colorTexture(),
                   eye);
  for (const render::Framebuffer* target : {&left, &right}) {
    const render::RgbaImage image = render::readTexture(target->colorTexture(), eye);
    EXPECT_GT(image.at(5, 5)[0], 225);      // the patch, half as large
    EXPECT_LT(image.at(300, 230)[0], 225);  // the table's grey, far from it
    EXPECT_GT(image.at(300, 230)[0], 60);
  }
}

}  // namespace
}  // namespace arbci::app

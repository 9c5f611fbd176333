// Every registered panel drawn in process (headless EGL, Dear ImGui) over a stand-in of the
// session's model with known contents: each shows its window and the widgets its state calls for
// (enabled or greyed out with the reason the model gives), and the model's figures reach the
// picture (kept in test-artefacts/panels/) — a few milliseconds a panel, where a live simulated
// session took seconds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "arbci/render/framebuffer.h"
#include "arbci/render/gl_context.h"
#include "arbci/ui/experimenter_shell.h"
#include "arbci/ui/imgui_layer.h"
#include "arbci/ui/panel_registry.h"
#include "arbci/ui/widget_registry.h"

namespace arbci::ui {
namespace {

// A session in phase 1 of trial 2: the arm idle, two markers tracked, a model trained.
class StandInModel final : public WorkstationModel {
 public:
  StandInModel() {
    camera_ = cv::Mat(480, 640, CV_8UC3, cv::Scalar(90, 110, 130));
    cv::rectangle(camera_, cv::Rect(280, 200, 80, 80), cv::Scalar(0, 0, 0), cv::FILLED);
    binary_ = cv::Mat(480, 640, CV_8UC1, cv::Scalar(255));
    vision::MarkerDetection marker;
    marker.id = 20;
    marker.corners = {cv::Point2f(280, 200), cv::Point2f(360, 200), cv::Point2f(360, 280),
                      cv::Point2f(280, 280)};
    detection_.markers.push_back(marker);
    status_.state = robot::RobotState::Idle;
    status_.tool = {0.0, 0.45, 0.45};
    erp_.channels = {"Fz", "Cz", "Pz"};
    erp_.rate_hz = 256.0;
    erp_.window_start_s = 0.0;
    erp_.window_end_s = 0.8;
    // 44 channels (over 64k vertices of traces: the GL back end must split the draw list): Fz
    // clean, Cz flat, Pz with 30 uV of 50 Hz, the photodiode, and 40 more clean ones.
    bci::SignalInfo info;
    info.rate_hz = 256.0;
    info.block_size = 16;
    info.channels = {"Fz", "Cz", "Pz", "Photodiode"};
    for (int c = 5; c <= 44; ++c) {
      std::string name = "E";
      name += std::to_string(c);
      info.channels.push_back(name);
    }
    scope_.emplace(info, 10.0, bci::FilterSettings{});
    std::mt19937 random(5);
    std::normal_distribution<float> noise(0.0f, 8.0f);
    for (std::int64_t first = 0; first < 6 * 256; first += 16) {
      bci::Block block(first, info.channelCount(), 16);
      for (int c = 0; c < info.channelCount(); ++c) {
        for (int k = 0; k < 16; ++k) {
          const double t = static_cast<double>(first + k) / 256.0;
          float v = noise(random);
          if (c == 1) v = 0.01f * v;
          if (c == 2) v += static_cast<float>(30.0 * std::sin(2.0 * M_PI * 50.0 * t));
          if (c == 3) v = (first / 16) % 12 < 2 ? 1000.0f : 0.0f;
          block.at(c, k) = v;
        }
      }
      scope_->append(block);
      if ((first / 16) % 12 == 0) scope_->markStimulus(first);
    }
  }

  cv::Mat cameraImage() override { return camera_; }
  cv::Mat binaryImage() override { return binary_; }
  vision::DetectionResult detection() override { return detection_; }
  vision::ThresholdSettings threshold() override { return {}; }
  void setThreshold(const vision::ThresholdSettings&) override { ++calls_["threshold"]; }
  std::vector<TrackedObject> trackedObjects() override {
    return {{20, {-0.09, 0.42, 0.06}, 0.03, 0.4}, {40, {0.27, 0.42, 0.06}, 0.03, 0.5}};
  }
  std::string worldStatus() override { return "reference marker 0 in view"; }
  vision::CameraModel camera() override {
    vision::CameraModel c;
    c.camera_matrix = cv::Matx33d(800, 0, 319.5, 0, 800, 239.5, 0, 0, 1);
    c.image_size = {640, 480};
    return c;
  }
  bool canHoldBoard() override { return true; }
  void holdBoard(bool) override {}
  int referenceId() override { return 0; }
  cv::Vec3d referencePosition() override { return {0.0, 0.9, 0.0}; }
  void setReference(int, const cv::Vec3d&) override {}
  std::optional<bci::P300Model> model() override { return std::nullopt; }
  void useModel(const bci::P300Model&) override {}
  std::optional<robot::StatusPayload> robotStatus() override { return status_; }
  bool robotSilent() override { return false; }
  std::vector<std::string> robotLog() override { return {"connected", "finished GRASP"}; }
  void emergencyStop() override { ++calls_["estop"]; }
  std::string whyNot(Action action) override {
    switch (action) {
      case Action::Pause:
        return setup_ ? "the session has not started" : "";
      case Action::Abort:
      case Action::EmergencyStop:
      case Action::EndSession:
        return "";
      case Action::Start:
        return setup_ ? "" : "the session has started";
      default:
        return "only after an emergency stop or a robot fault";
    }
  }
  void robotReset() override {}
  void robotHome() override {}
  void openGripper() override {}
  void retryStep() override {}
  void skipTrial() override {}
  void endSession() override {}
  std::string phase() override { return "phase 1: objects flashing"; }
  int trial() override { return 2; }
  int trials() override { return 3; }
  int sequence() override { return 4; }
  bool started() override { return true; }
  std::vector<std::string> preflight() override { return {"pre-flight passed"}; }
  bool preflightRunning() override { return false; }
  bool ended() override { return false; }
  std::vector<std::pair<std::string, std::string>> endSummary() override {
    return {{"ended", "finished"}, {"objects", "accuracy 100 %"}};
  }
  std::string trackingAlarm() override { return ""; }
  double maxPoseAgeS() override { return 0.5; }
  std::optional<double> referenceAgeS() override { return 0.02; }
  void start() override {}
  void pause() override { ++calls_["pause"]; }
  void resume() override {}
  void abort() override {}
  double sessionTime() override { return 83.4; }
  double budgetMs() override { return 58.6; }
  int overruns() override { return 0; }
  std::vector<StageTiming> timing() override {
    return {{"eeg", 0.3, 0.4, 0.6, 0.9, 0.3}, {"tracking", 1.8, 2.2, 3.1, 4.0, 1.9}};
  }
  std::vector<OperatorLine> operatorLog() override {
    return {{OperatorLine::Severity::Info, 2.1, "pre-flight passed"},
            {OperatorLine::Severity::Warning, 40.2, "12 EEG samples lost"},
            {OperatorLine::Severity::Error, 61.0,
             "object 10: tracking lost (pose 28.3 s old), not grasped; Retry step once it is seen "
             "again"}};
  }
  size_t operatorLogSize() override { return 3; }
  const bci::SignalScope* eegScope() override { return scope_ ? &*scope_ : nullptr; }
  std::string photodiodeChannel() override { return "Photodiode"; }
  std::vector<std::string> selections() override {
    return {"trial 1: object 20 (intended), cell 1,3 (intended), placed 0.3 mm off [placed]"};
  }

  std::map<std::string, int> calls_;
  bool setup_ = false;  // before Start, rather than in phase 1

 private:
  cv::Mat camera_, binary_;
  vision::DetectionResult detection_;
  robot::StatusPayload status_;
  bci::ErpCurves erp_;
  std::optional<bci::SignalScope> scope_;
};

struct Drawn {
  std::set<std::string> windows;
  std::map<std::string, DrawnWidget> widgets;  // by label
  cv::Mat image;                               // RGBA, top row first
};

// The shell with `panel` alone, drawn for a few frames (ImGui settles its layout).
// `layout`: an ImGui layout file to start from ("" for none).
Drawn draw(render::GlContext& context, Panel& panel, const std::string& layout = "") {
  const render::Size size{1000, 700};
  ImGuiLayer imgui(context, layout);
  ExperimenterShell shell;
  shell.addPanel(panel);
  for (int frame = 0; frame < 3; ++frame) {
    context.makeCurrent();
    imgui.beginFrame(1.0f / 60.0f);
    shell.draw(size, {16.7f, "phase 1: objects flashing", "t=83.4 s"});
    render::clearFramebuffer(context.drawFramebuffer(), size, {0.08f, 0.09f, 0.11f, 1.0f});
    imgui.endFrame();
    context.present();
  }
  Drawn out;
  for (const std::string& w : drawnWindows()) out.windows.insert(w);
  for (const DrawnWidget& w : drawnWidgets()) out.widgets[w.label] = w;
  const render::RgbaImage pixels = render::readPixels(context.drawFramebuffer(), size);
  out.image =
      cv::Mat(pixels.height, pixels.width, CV_8UC4, const_cast<std::uint8_t*>(pixels.pixels.data()))
          .clone();
  return out;
}

class Panels : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { context_ = render::createHeadlessContext({1000, 700}); }
  static void TearDownTestSuite() { context_.reset(); }
  std::unique_ptr<Panel> make(const std::string& name) {
    return panels().at(name).make.make({model_, 0, 1280.0f / 480.0f});
  }
  static std::unique_ptr<render::GlContext> context_;
  StandInModel model_;
};
std::unique_ptr<render::GlContext> Panels::context_;

// The buttons each panel must offer (enabled or greyed out); the panels without buttons are
// checked by pixel probes below.
const std::map<std::string, std::vector<std::string>> kExpectedWidgets = {
    {"session", {"Start", "Pause", "Resume", "Abort", "EMERGENCY STOP"}},
    {"log", {}},
    {"robot",
     {"EMERGENCY STOP", "Reset", "Home", "Open gripper", "Retry step", "Skip trial",
      "End session"}},
    {"calibration", {"Capture view", "Calibrate", "Apply reference"}},
    {"training", {"Browse", "Train"}},
};

TEST_F(Panels, EveryRegisteredPanelDrawsItsWindowAndButtons) {
  ASSERT_GE(panels().entries().size(), 7u);
  for (const auto& entry : panels().entries()) {
    auto panel = make(entry.name);
    const Drawn d = draw(*context_, *panel);
    EXPECT_TRUE(d.windows.count(panel->title())) << entry.name;
    const auto expected = kExpectedWidgets.find(entry.name);
    if (expected != kExpectedWidgets.end()) {
      for (const std::string& label : expected->second) {
        EXPECT_TRUE(d.widgets.count(label)) << entry.name << " lacks " << label;
      }
    }
    // Kept for a person to look at.
    std::filesystem::create_directories(ARBCI_TEST_ARTEFACTS_DIR "/panels");
    cv::Mat bgr;
    cv::cvtColor(d.image, bgr, cv::COLOR_RGBA2BGR);
    cv::imwrite(ARBCI_TEST_ARTEFACTS_DIR "/panels/" + entry.name + ".png", bgr);
    cv::Scalar mean, deviation;
    cv::meanStdDev(d.image, mean, deviation);
    EXPECT_GT(deviation[0] + deviation[1] + deviation[2], 30.0) << entry.name;
  }
}

TEST_F(Panels, TheSessionPanelOffersWhatThePhaseAllowsAndSaysWhyNotTheRest) {
  auto panel = make("session");
  const Drawn d = draw(*context_, *panel);
  ASSERT_TRUE(d.widgets.count("Pause"));
  EXPECT_TRUE(d.widgets.at("Pause").enabled);
  ASSERT_TRUE(d.widgets.count("Resume"));
  EXPECT_FALSE(d.widgets.at("Resume").enabled);
  EXPECT_EQ(d.widgets.at("Resume").why_disabled, "only after an emergency stop or a robot fault");
  EXPECT_TRUE(d.widgets.count("Abort"));
}

// A double click must not land on a button that took another's place: Start, Pause, Resume and
// Abort stay where they are when the session starts.
TEST_F(Panels, TheSessionPanelsButtonsKeepTheirPlaceWhenTheSessionStarts) {
  model_.setup_ = true;
  auto panel = make("session");
  const Drawn before = draw(*context_, *panel);
  model_.setup_ = false;
  const Drawn after = draw(*context_, *panel);
  EXPECT_TRUE(before.widgets.at("Start").enabled);
  EXPECT_FALSE(after.widgets.at("Start").enabled);
  EXPECT_TRUE(after.widgets.at("Pause").enabled);
  for (const char* label : {"Start", "Pause", "Resume", "Abort", "EMERGENCY STOP"}) {
    const DrawnWidget& a = before.widgets.at(label);
    const DrawnWidget& b = after.widgets.at(label);
    EXPECT_EQ(a.x0, b.x0) << label;
    EXPECT_EQ(a.y0, b.y0) << label;
  }
}

// A layout saved on a larger screen is fitted to this one: the panel and its buttons in reach.
TEST_F(Panels, APanelSavedOutsideASmallerScreenIsFittedToIt) {
  const std::string layout = ::testing::TempDir() + "/panels_layout.ini";
  std::ofstream(layout) << "[Window][Robot]\nPos=1300,820\nSize=900,800\nCollapsed=0\n";
  auto panel = make("robot");
  const Drawn d = draw(*context_, *panel, layout);
  for (const char* label : {"EMERGENCY STOP", "Home", "End session"}) {
    ASSERT_TRUE(d.widgets.count(label)) << label;
    const DrawnWidget& w = d.widgets.at(label);
    EXPECT_GE(w.x0, 0.0f) << label;
    EXPECT_LE(w.x1, 1000.0f) << label;
    EXPECT_LE(w.y1, 700.0f) << label;
  }
}

// The EEG panel: traces with each channel's quality, the flat and the noisy ones in red, the
// finding named with its threshold in the table.
TEST_F(Panels, TheEegPanelGradesEachChannelAndNamesTheFinding) {
  const auto& quality = model_.eegScope()->quality();
  ASSERT_EQ(quality.size(), 44u);
  EXPECT_EQ(quality[0].grade, bci::Grade::Good) << quality[0].finding;
  EXPECT_EQ(quality[1].grade, bci::Grade::Bad) << quality[1].finding;
  EXPECT_EQ(quality[1].finding.rfind("flat", 0), 0u) << quality[1].finding;
  EXPECT_EQ(quality[2].grade, bci::Grade::Bad) << quality[2].finding;
  EXPECT_NE(quality[2].finding.find("line noise 50 Hz"), std::string::npos);
  auto panel = make("eeg");
  const Drawn d = draw(*context_, *panel);
  EXPECT_TRUE(d.windows.count("EEG"));
  // The grade marks left of the traces: green for Fz, red for Cz (rows from the top).
  int green = 0, red = 0, yellow = 0;
  for (int y = 60; y < d.image.rows; ++y) {
    for (int x = 8; x < 16; ++x) {
      const cv::Vec4b p = d.image.at<cv::Vec4b>(y, x);
      green += p[1] > 150 && p[0] < 120 && p[2] < 130;
      red += p[0] > 200 && p[1] < 100;
      yellow += p[0] > 200 && p[1] > 180 && p[2] < 120;
    }
  }
  EXPECT_GT(green, 100);
  EXPECT_GT(red, 20);
  EXPECT_GT(yellow, 10);
}

// Everything the experimenter was told, coloured by severity, filterable.
TEST_F(Panels, TheOperatorLogListsWhatTheSessionSaid) {
  auto panel = make("log");
  const Drawn d = draw(*context_, *panel);
  EXPECT_TRUE(d.windows.count("Operator log"));
  // The error line is drawn in red somewhere in the panel.
  int red = 0;
  for (int y = 0; y < d.image.rows; ++y)
    for (int x = 0; x < d.image.cols; ++x) {
      const cv::Vec4b p = d.image.at<cv::Vec4b>(y, x);
      red += p[0] > 200 && p[1] < 120 && p[2] < 110;
    }
  EXPECT_GT(red, 50);
}

TEST_F(Panels, TheRobotPanelHasTheRecoveryButtonsGreyedWithTheirReasons) {
  auto panel = make("robot");
  const Drawn d = draw(*context_, *panel);
  for (const char* label : {"Home", "Open gripper", "Retry step", "Skip trial"}) {
    ASSERT_TRUE(d.widgets.count(label)) << label;
    EXPECT_FALSE(d.widgets.at(label).enabled) << label;
    EXPECT_FALSE(d.widgets.at(label).why_disabled.empty()) << label;
  }
}

TEST_F(Panels, TheThresholdPanelShowsTheCameraAndBinaryImagesSideBySide) {
  auto panel = make("threshold");
  const Drawn d = draw(*context_, *panel);
  // The camera image's grey-blue (B 90, G 110, R 130) and the black marker square are drawn.
  cv::Mat bgr;
  cv::cvtColor(d.image, bgr, cv::COLOR_RGBA2BGR);
  int camera = 0, black = 0;
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
      camera += std::abs(p[0] - 90) < 6 && std::abs(p[1] - 110) < 6 && std::abs(p[2] - 130) < 6;
      black += p[0] < 8 && p[1] < 8 && p[2] < 8;
    }
  }
  EXPECT_GT(camera, 5000);
  EXPECT_GT(black, 200);
}

// The fraction of pixels in `area` within `tolerance` of `bgr`.
double share(const cv::Mat& rgba, const cv::Rect& area, const cv::Vec3b& rgb, int tolerance) {
  int hits = 0;
  for (int y = area.y; y < area.br().y; ++y) {
    for (int x = area.x; x < area.br().x; ++x) {
      const cv::Vec4b p = rgba.at<cv::Vec4b>(y, x);
      hits += std::abs(p[0] - rgb[0]) <= tolerance && std::abs(p[1] - rgb[1]) <= tolerance &&
              std::abs(p[2] - rgb[2]) <= tolerance;
    }
  }
  return static_cast<double>(hits) / area.area();
}

TEST_F(Panels, TheHmdPanelShowsTheViewAtTheHmdAspectAcrossTheWindow) {
  auto panel = make("hmd");
  const Drawn d = draw(*context_, *panel);
  // The stand-in's view is texture 0 (black), 1280:480 wide across the 1000-pixel window: about
  // 980 x 367 pixels below the title bar; the window's own background below it.
  EXPECT_GT(share(d.image, cv::Rect(40, 80, 920, 300), {0, 0, 0}, 2), 0.99);
  EXPECT_LT(share(d.image, cv::Rect(40, 460, 920, 150), {0, 0, 0}, 2), 0.01);
}

TEST_F(Panels, TheSummaryPanelSaysTheSessionIsStillRunning) {
  auto panel = make("summary");
  const Drawn d = draw(*context_, *panel);
  // One line of grey text under the title bar, nothing below it while the session runs.
  const cv::Rect line(0, 48, 500, 16), below(0, 90, 1000, 500);
  EXPECT_LT(share(d.image, line, {15, 15, 15}, 6), 0.95);
  EXPECT_GT(share(d.image, below, {15, 15, 15}, 6), 0.99);
}

TEST_F(Panels, TheTrainingPanelWaitsForARecordingAndSaysSo) {
  auto panel = make("training");
  const Drawn d = draw(*context_, *panel);
  ASSERT_TRUE(d.widgets.count("Train"));
  EXPECT_FALSE(d.widgets.at("Train").enabled);  // no recording named yet
  EXPECT_EQ(d.widgets.at("Train").why_disabled, "name at least one recording above");
}

}  // namespace
}  // namespace arbci::ui

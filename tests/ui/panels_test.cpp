// Every registered panel drawn in process (headless EGL, Dear ImGui) over a cycle record built by
// hand: each shows its window and the widgets its state calls for (enabled, or greyed out with the
// reason the record's why-not gives), the record's figures reach the picture (kept in
// test-artefacts/panels/), and a click posts the request the button stands for — a few
// milliseconds a panel, where a live simulated session took seconds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
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
#include "arbci/ui/start_error_screen.h"
#include "arbci/ui/widget_registry.h"
#include "support/panel_bench.h"

namespace arbci::ui {
namespace {

vision::PoseEstimate at(double x, double y) {
  vision::PoseEstimate p;
  p.pose = {cv::Matx33d::eye(), cv::Vec3d(x, y, 1.0)};
  p.reprojection_rms_px = 0.4;
  return p;
}

// 44 channels (over 64k vertices of traces: the GL back end must split the draw list): Fz clean,
// Cz flat, Pz with 30 uV of 50 Hz, the photodiode, and 40 more clean ones; six seconds of it,
// block by block on cycle records, a flash every twelfth block.
void feedEeg(test::PanelBench& b) {
  auto info = std::make_shared<bci::SignalInfo>();
  info->rate_hz = 256.0;
  info->block_size = 16;
  info->channels = {"Fz", "Cz", "Pz", "Photodiode"};
  for (int c = 5; c <= 44; ++c) {
    std::string name = "E";  // (appended: GCC 12 warns wrongly of "E" + to_string)
    name += std::to_string(c);
    info->channels.push_back(name);
  }
  std::mt19937 random(5);
  std::normal_distribution<float> noise(0.0f, 8.0f);
  for (std::int64_t first = 0; first < 6 * 256; first += 16) {
    session::CycleRecord r;
    r.eeg.info = info;
    bci::Block block(first, info->channelCount(), 16);
    for (int c = 0; c < info->channelCount(); ++c) {
      for (int k = 0; k < 16; ++k) {
        const double t = static_cast<double>(first + k) / 256.0;
        float v = noise(random);
        if (c == 1) v = 0.01f * v;
        if (c == 2) v += static_cast<float>(30.0 * std::sin(2.0 * M_PI * 50.0 * t));
        if (c == 3) v = (first / 16) % 12 < 2 ? 1000.0f : 0.0f;
        block.at(c, k) = v;
      }
    }
    r.eeg.blocks.push_back(block);
    if ((first / 16) % 12 == 0) r.presentation.onsets.push_back({session::Flash{}, first});
    b.window.ingest(r, b.settings);
  }
  // The grades as the session's quality stage puts them on the record: the EEG channels only.
  session::QualityPart& quality = b.record.quality;
  for (const std::string& channel : info->channels) {
    if (channel == "Photodiode") continue;
    quality.channels.push_back(channel);
    bci::SignalQuality q;
    q.rms_uv = 8.0;
    q.finding = "RMS 8.0 uV";
    if (channel == "Cz") {
      q.grade = bci::Grade::Bad;
      q.finding = "flat: SD 0.08 uV (bad below 0.5)";
    } else if (channel == "Pz") {
      q.grade = bci::Grade::Bad;
      q.finding = "line noise 50 Hz: 30.0 uV (bad above 20)";
    }
    quality.quality.push_back(q);
  }
}

// A session in phase 1 of trial 2: the arm idle and home, the reference and two objects tracked,
// the operator told three things, the cycle timed.
void phaseOneOfTrialTwo(test::PanelBench& b) {
  session::CycleRecord& r = b.record;
  r.frame = 5004;
  r.time_s = 83.4;
  r.paradigm.phase = bci::Phase::ObjectFlashing;
  r.paradigm.trial = 2;
  r.paradigm.sequence = 4;
  session::TrialRecord t;
  t.trial = 1;
  t.intended_object = 20;
  t.selected_object = 20;
  t.intended_cell = t.selected_cell = {1, 3};
  t.outcome = "placed";
  t.placement_error_m = 0.0003;
  r.paradigm.trials = std::make_shared<const std::vector<session::TrialRecord>>(
      std::vector<session::TrialRecord>{t});
  r.preflight.lines = {"pre-flight passed"};
  cv::Mat camera(480, 640, CV_8UC3, cv::Scalar(90, 110, 130));
  cv::rectangle(camera, cv::Rect(280, 200, 80, 80), cv::Scalar(0, 0, 0), cv::FILLED);
  r.tracking.left_image = camera;
  r.tracking.binary = cv::Mat(480, 640, CV_8UC1, cv::Scalar(255));
  vision::MarkerDetection marker;
  marker.id = 20;
  marker.corners = {cv::Point2f(280, 200), cv::Point2f(360, 200), cv::Point2f(360, 280),
                    cv::Point2f(280, 280)};
  r.tracking.detection.markers.push_back(marker);
  vision::WorldModel world;
  world.update(83.37, {{0, at(0.0, 0.0)}, {20, at(-0.09, -0.48)}, {40, at(0.27, -0.48)}});
  r.tracking.world = std::make_shared<const vision::WorldModel>(world);
  r.tracking.max_pose_age_s = 0.5;
  robot::StatusPayload status;
  status.state = robot::RobotState::Idle;
  status.tool = {0.0, 0.45, 0.45};
  r.robot.status = status;
  r.robot.messages = std::make_shared<const std::vector<std::string>>(
      std::vector<std::string>{"connected", "finished GRASP"});
  b.log.add(2.1, session::Severity::Info, "pre-flight passed");
  b.log.add(40.2, session::Severity::Warning, "12 EEG samples lost");
  b.log.add(61.0, session::Severity::Error,
            "object 10: tracking lost (pose 28.3 s old), not grasped; Retry step once it is seen "
            "again");
  for (int cycle = 0; cycle < 31; ++cycle) {
    session::CycleRecord timed;
    timed.stage_ms = {{"eeg", 0.3}, {"tracking", 1.9}};
    timed.compute_ms = 19.6;
    b.window.ingest(timed, b.settings);
  }
  feedEeg(b);
}

struct Drawn {
  std::set<std::string> windows;
  std::map<std::string, DrawnWidget> widgets;  // by label
  cv::Mat image;                               // RGBA, top row first
};

constexpr render::Size kSize{1000, 700};

// The shell with one panel, drawn a frame at a time (ImGui settles its layout over a few).
class Drawer {
 public:
  // `layout`: an ImGui layout file to start from ("" for none).
  Drawer(render::GlContext& context, Panel& panel, const std::string& layout = "",
         render::Size size = kSize)
      : context_(context), imgui_(context, layout), size_(size) {
    shell_.addPanel(panel);
  }
  Drawn frames(test::PanelBench& bench, int count = 3) {
    for (int i = 0; i < count; ++i) frame(bench, {});
    return collect();
  }
  // Pointer over the button, pressed, released (ImGui's click); false when no such button.
  bool click(test::PanelBench& bench, const std::string& label) {
    frames(bench, 1);
    const auto& widgets = drawnWidgets();
    const auto found = std::find_if(widgets.begin(), widgets.end(),
                                    [&](const DrawnWidget& w) { return w.label == label; });
    if (found == widgets.end()) return false;
    SyntheticInput input;
    input.x = 0.5f * (found->x0 + found->x1);
    input.y = 0.5f * (found->y0 + found->y1);
    frame(bench, input);
    input.left_down = true;
    frame(bench, input);
    input.left_down = false;
    frame(bench, input);
    return true;
  }
  // A text field clicked and `text` typed in it (a number field selects its value on the click,
  // so the text replaces it); false when no field is drawn under that label.
  bool type(test::PanelBench& bench, const std::string& label, const std::string& text) {
    if (!click(bench, label)) return false;
    SyntheticInput input;
    input.text = text;
    frame(bench, input);
    frames(bench, 2);
    return true;
  }
  // A key pressed with Ctrl (a shortcut), over one frame.
  void ctrlKey(test::PanelBench& bench, char key) {
    SyntheticInput input;
    input.key = key;
    input.ctrl = true;
    frame(bench, input);
    frames(bench, 2);
  }
  ExperimenterShell& shell() { return shell_; }

 private:
  void frame(test::PanelBench& bench, const SyntheticInput& input) {
    context_.makeCurrent();
    imgui_.beginFrame(1.0f / 60.0f, &input);
    shell_.draw(size_, {16.7f, "phase 1: objects flashing", "t=83.4 s"}, bench.input());
    render::clearFramebuffer(context_.drawFramebuffer(), size_, {0.08f, 0.09f, 0.11f, 1.0f});
    imgui_.endFrame();
    context_.present();
  }
  Drawn collect() {
    Drawn out;
    for (const std::string& w : drawnWindows()) out.windows.insert(w);
    for (const DrawnWidget& w : drawnWidgets()) out.widgets[w.label] = w;
    const render::RgbaImage pixels = render::readPixels(context_.drawFramebuffer(), size_);
    out.image = cv::Mat(pixels.height, pixels.width, CV_8UC4,
                        const_cast<std::uint8_t*>(pixels.pixels.data()))
                    .clone();
    return out;
  }
  render::GlContext& context_;
  ImGuiLayer imgui_;
  render::Size size_;
  ExperimenterShell shell_;
};

class Panels : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { context_ = render::createHeadlessContext(kSize); }
  static void TearDownTestSuite() { context_.reset(); }
  void SetUp() override {
    phaseOneOfTrialTwo(bench_);
    bench_.window.hmd_aspect = 1280.0f / 480.0f;
  }
  std::unique_ptr<Panel> make(const std::string& name) { return panels().at(name).make.make(); }
  Drawn draw(Panel& panel, const std::string& layout = "") {
    return Drawer(*context_, panel, layout).frames(bench_);
  }
  static std::unique_ptr<render::GlContext> context_;
  test::PanelBench bench_;
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
    const Drawn d = draw(*panel);
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

TEST_F(Panels, EveryScreenshotNameIsAPanelsShotAndNamedOnce) {
  std::set<std::string> names;
  for (const auto& [panel, shot] : panelShots()) {
    EXPECT_TRUE(panels().find(panel)) << panel;
    EXPECT_TRUE(names.insert(shot->name).second) << shot->name << " named twice";
    EXPECT_TRUE(shot->ready) << shot->name;
  }
  for (const char* name : {"threshold", "calibration", "training", "session-model", "robot",
                           "session", "eeg", "log", "settings", "hmd"})
    EXPECT_TRUE(names.count(name)) << name;
}

TEST_F(Panels, TheSessionPanelOffersWhatThePhaseAllowsAndSaysWhyNotTheRest) {
  auto panel = make("session");
  const Drawn d = draw(*panel);
  ASSERT_TRUE(d.widgets.count("Pause"));
  EXPECT_TRUE(d.widgets.at("Pause").enabled);
  ASSERT_TRUE(d.widgets.count("Resume"));
  EXPECT_FALSE(d.widgets.at("Resume").enabled);
  EXPECT_EQ(d.widgets.at("Resume").why_disabled,
            "nothing to resume: the session is not paused or stopped");
  EXPECT_FALSE(d.widgets.at("Start").enabled);
  EXPECT_EQ(d.widgets.at("Start").why_disabled, "the session has started");
}

// Pixels of about this colour (RGBA image) in the drawn panel.
int pixelsNear(const cv::Mat& image, int r, int g, int b) {
  int n = 0;
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) {
      const cv::Vec4b p = image.at<cv::Vec4b>(y, x);
      n += std::abs(p[0] - r) < 25 && std::abs(p[1] - g) < 25 && std::abs(p[2] - b) < 25;
    }
  return n;
}

TEST_F(Panels, TheSessionPanelSaysWhatLearningFromUseWaitsForAndWhenTheArmMoves) {
  auto panel = make("session");
  const int amber_before = pixelsNear(draw(*panel).image, 255, 204, 89);
  session::LearningState learning;
  learning.selections = 4;
  learning.fits = 2;
  learning.waiting_for = "1 more selection";
  EXPECT_EQ(learning.line(),
            "learning: 4 selections, not yet moving the arm; waiting for 1 more selection");
  bench_.record.p300.learning = std::make_shared<const session::LearningState>(learning);
  EXPECT_GT(pixelsNear(draw(*panel).image, 255, 204, 89), amber_before + 50);  // amber: held
  learning.trusted = true;
  learning.waiting_for.clear();
  EXPECT_EQ(learning.line(), "learning: 4 selections, the model trusted: the arm moves");
  bench_.record.p300.learning = std::make_shared<const session::LearningState>(learning);
  EXPECT_GT(pixelsNear(draw(*panel).image, 128, 230, 128), 50);  // green: trusted
}

TEST_F(Panels, TheSessionPanelsButtonsPostTheirRequests) {
  auto panel = make("session");
  Drawer drawer(*context_, *panel);
  ASSERT_TRUE(drawer.click(bench_, "Pause"));
  EXPECT_EQ(bench_.requests.count<session::PauseRequest>(), 1);
  // A disabled button posts nothing.
  ASSERT_TRUE(drawer.click(bench_, "Resume"));
  EXPECT_EQ(bench_.requests.count<session::ResumeRequest>(), 0);
  ASSERT_TRUE(drawer.click(bench_, "EMERGENCY STOP"));
  EXPECT_EQ(bench_.requests.count<session::EmergencyStopRequest>(), 1);
}

TEST_F(Panels, BeforeStartTheSessionPanelTakesTheSubjectAndPostsStart) {
  bench_.record = session::CycleRecord{};
  bench_.record.labels.subject = "07";
  bench_.window = WindowState([](const core::RunLabels& l) {
    return RunTarget{"", "run 3 of subject " + l.subject};
  });
  bench_.window.ingest(bench_.record, bench_.settings);
  EXPECT_EQ(bench_.window.runTarget().target, "run 3 of subject 07");
  auto panel = make("session");
  Drawer drawer(*context_, *panel);
  const Drawn d = drawer.frames(bench_);
  EXPECT_TRUE(d.widgets.count("subject"));
  EXPECT_TRUE(d.widgets.at("Start").enabled);
  ASSERT_TRUE(drawer.click(bench_, "Start"));
  EXPECT_EQ(bench_.requests.count<session::StartRequest>(), 1);
  // What stops a start is shown on Start's button.
  bench_.window = WindowState([](const core::RunLabels&) {
    return RunTarget{"give the subject: the run is exported to the BIDS dataset bids", ""};
  });
  bench_.window.ingest(bench_.record, bench_.settings);
  const Drawn refused = drawer.frames(bench_);
  EXPECT_FALSE(refused.widgets.at("Start").enabled);
  EXPECT_EQ(refused.widgets.at("Start").why_disabled,
            "give the subject: the run is exported to the BIDS dataset bids");
}

// The pre-flight asks about a display too slow for display_hz: the Session panel offers to run
// annotated, and the answer is the Start that accepts the display.
TEST_F(Panels, ASlowDisplaysQuestionIsAnsweredFromTheSessionPanel) {
  bench_.record = session::CycleRecord{};
  bench_.record.preflight.display_question =
      "display: a frame every 75 ms (13.3 Hz; display_hz 60 asks for 16.7 ms): flashes will last "
      "about 75 ms instead of 67, and onsets come about 225 ms apart instead of 183";
  bench_.window = WindowState([](const core::RunLabels&) { return RunTarget{"", "a run"}; });
  bench_.window.ingest(bench_.record, bench_.settings);
  auto panel = make("session");
  Drawer drawer(*context_, *panel);
  const std::string label = "Run annotated on this display (no timing pauses this run)";
  ASSERT_TRUE(drawer.frames(bench_).widgets.count(label));
  ASSERT_TRUE(drawer.click(bench_, label));
  ASSERT_EQ(bench_.requests.count<session::StartRequest>(), 1);
  const auto& start = std::get<session::StartRequest>(bench_.requests.posted.back());
  EXPECT_TRUE(start.despite_display);
  EXPECT_FALSE(start.despite_quality);
}

// A double click must not land on a button that took another's place: Start, Pause, Resume and
// Abort stay where they are when the session starts.
TEST_F(Panels, TheSessionPanelsButtonsKeepTheirPlaceWhenTheSessionStarts) {
  const session::CycleRecord started = bench_.record;
  bench_.record.paradigm.phase = bci::Phase::Setup;
  auto panel = make("session");
  const Drawn before = draw(*panel);
  bench_.record = started;
  const Drawn after = draw(*panel);
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
  const Drawn d = draw(*panel, layout);
  for (const char* label : {"EMERGENCY STOP", "Home", "End session"}) {
    ASSERT_TRUE(d.widgets.count(label)) << label;
    const DrawnWidget& w = d.widgets.at(label);
    EXPECT_GE(w.x0, 0.0f) << label;
    EXPECT_LE(w.x1, 1000.0f) << label;
    EXPECT_LE(w.y1, 700.0f) << label;
  }
}

// The EEG panel: the traces from the window's scope, fed from the records; the grades from the
// record (the quality stage's, matched to the traces by channel name), the scope grading nothing.
// The flat and the noisy channels in red, the photodiode in yellow.
TEST_F(Panels, TheEegPanelShowsTheRecordsGradeOfEachChannel) {
  ASSERT_NE(bench_.window.eegScope(), nullptr);
  EXPECT_TRUE(bench_.window.eegScope()->quality().empty());
  EXPECT_EQ(bench_.window.eegScope()->stimuli().size(), 8u);
  auto panel = make("eeg");
  const Drawn d = draw(*panel);
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

// Without grades on the record (the first two seconds) the marks are grey: the panel grades
// nothing of its own.
TEST_F(Panels, TheEegPanelGradesNothingItself) {
  bench_.record.quality = {};
  auto panel = make("eeg");
  const Drawn d = draw(*panel);
  int red = 0, grey = 0;
  for (int y = 60; y < d.image.rows; ++y) {
    for (int x = 8; x < 16; ++x) {
      const cv::Vec4b p = d.image.at<cv::Vec4b>(y, x);
      red += p[0] > 200 && p[1] < 100;
      grey += p[0] == 150 && p[1] == 150 && p[2] == 150;
    }
  }
  EXPECT_EQ(red, 0);
  EXPECT_GT(grey, 100);
}

TEST_F(Panels, TheEegPanelSaysSoBeforeTheFirstSamples) {
  bench_.window = WindowState();
  auto panel = make("eeg");
  const Drawn d = draw(*panel);
  EXPECT_TRUE(d.windows.count("EEG"));
  EXPECT_EQ(bench_.window.eegScope(), nullptr);
}

// The window's cycle history: each stage's percentiles and the total, from the records' times.
TEST_F(Panels, TheWindowKeepsEachStagesTimesFromTheRecords) {
  const std::vector<StageTiming>& timing = bench_.window.timing();
  ASSERT_EQ(timing.size(), 3u);
  EXPECT_EQ(timing[0].stage, "eeg");
  EXPECT_NEAR(timing[0].p50_ms, 0.3, 1e-9);
  EXPECT_EQ(timing[1].stage, "tracking");
  EXPECT_EQ(timing[2].stage, "total");
  EXPECT_NEAR(timing[2].max_ms, 19.6, 1e-9);
  EXPECT_NEAR(bench_.window.cycleP50Ms(), 19.6, 1e-9);
  EXPECT_EQ(bench_.window.recentCycles().size(), 31u);
}

// Everything the experimenter was told, coloured by severity, filterable.
TEST_F(Panels, TheOperatorLogListsWhatTheSessionSaid) {
  auto panel = make("log");
  const Drawn d = draw(*panel);
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
  const Drawn d = draw(*panel);
  for (const char* label : {"Home", "Open gripper", "Retry step", "Skip trial"}) {
    ASSERT_TRUE(d.widgets.count(label)) << label;
    EXPECT_FALSE(d.widgets.at(label).enabled) << label;
    EXPECT_FALSE(d.widgets.at(label).why_disabled.empty()) << label;
  }
  EXPECT_EQ(d.widgets.at("Retry step").why_disabled,
            "nothing to retry: no emergency stop or robot fault");
}

// After an emergency stop in a trial's flashing, with the arm home and empty: Retry step and Skip
// trial go, each posting its request.
TEST_F(Panels, AfterAStopTheRobotPanelsRecoveryPostsRetryAndSkip) {
  bench_.record.paradigm.interrupted = bench_.record.paradigm.phase;
  bench_.record.paradigm.phase = bci::Phase::EmergencyStop;
  auto panel = make("robot");
  Drawer drawer(*context_, *panel);
  const Drawn d = drawer.frames(bench_);
  EXPECT_TRUE(d.widgets.at("Retry step").enabled) << d.widgets.at("Retry step").why_disabled;
  EXPECT_TRUE(d.widgets.at("Skip trial").enabled) << d.widgets.at("Skip trial").why_disabled;
  ASSERT_TRUE(drawer.click(bench_, "Retry step"));
  ASSERT_TRUE(drawer.click(bench_, "Skip trial"));
  EXPECT_EQ(bench_.requests.count<session::RetryStepRequest>(), 1);
  EXPECT_EQ(bench_.requests.count<session::SkipTrialRequest>(), 1);
}

TEST_F(Panels, TheThresholdPanelShowsTheCameraAndBinaryImagesSideBySide) {
  auto panel = make("threshold");
  const Drawn d = draw(*panel);
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
  const Drawn d = draw(*panel);
  // The view is texture 0 (black), 1280:480 wide across the 1000-pixel window: about 980 x 367
  // pixels below the title bar; the window's own background below it.
  EXPECT_GT(share(d.image, cv::Rect(40, 80, 920, 300), {0, 0, 0}, 2), 0.99);
  EXPECT_LT(share(d.image, cv::Rect(40, 460, 920, 150), {0, 0, 0}, 2), 0.01);
}

TEST_F(Panels, TheSummaryPanelSaysTheSessionIsStillRunning) {
  auto panel = make("summary");
  const Drawn d = draw(*panel);
  // One line of grey text under the title bar, nothing below it while the session runs.
  const cv::Rect line(0, 48, 500, 16), below(0, 90, 1000, 500);
  EXPECT_LT(share(d.image, line, {15, 15, 15}, 6), 0.95);
  EXPECT_GT(share(d.image, below, {15, 15, 15}, 6), 0.99);
}

// Once ended, the last record carries the summary: one row per figure and per trial.
TEST_F(Panels, TheSummaryPanelShowsTheEndedSessionsSummary) {
  bench_.record.ended = true;
  bench_.record.end_kind = bench_.record.end_reason = "finished";
  bench_.record.summary = std::make_shared<const nlohmann::json>(nlohmann::json{
      {"ended", "finished"},
      {"end_reason", "finished"},
      {"duration_s", 131.2},
      {"folder", "arbci-session"},
      {"objects", {{"accuracy", 1.0}, {"seconds_per_selection", 9.8}, {"bits_per_minute", 12.1}}},
      {"trials",
       {{{"trial", 1},
         {"selected_object", 20},
         {"intended_object", 20},
         {"selected_cell", {1, 1}},
         {"intended_cell", {3, 1}},
         {"outcome", "placed"},
         {"interruptions", {{{"kind", "emergency stop"}, {"at_s", 80.2}, {"resumed_s", 89.0}}}},
         {"placement_error_m", 0.001}},
        {{"trial", 2}, {"selected_object", nullptr}, {"outcome", "skipped"}}}},
      {"timing", {{"late_frames", 0}, {"lost_samples", 0}}}});
  auto panel = make("summary");
  const Drawn d = draw(*panel);
  // Rows of text down the panel: the ended session's figures.
  const cv::Rect rows(0, 48, 1000, 200);
  EXPECT_LT(share(d.image, rows, {15, 15, 15}, 6), 0.9);
}

TEST_F(Panels, TheTrainingPanelWaitsForARecordingAndSaysSo) {
  auto panel = make("training");
  const Drawn d = draw(*panel);
  ASSERT_TRUE(d.widgets.count("Train"));
  EXPECT_FALSE(d.widgets.at("Train").enabled);  // no recording named yet
  EXPECT_EQ(d.widgets.at("Train").why_disabled, "name at least one recording above");
}

TEST_F(Panels, TheCalibrationPanelAppliesTheReferenceAsARequest) {
  // A tall window: the reference's fields come below the views and the coverage map.
  const render::Size tall{1000, 1400};
  auto context = render::createHeadlessContext(tall);
  auto panel = make("calibration");
  Drawer drawer(*context, *panel, "", tall);
  ASSERT_TRUE(drawer.click(bench_, "Apply reference"));
  ASSERT_EQ(bench_.requests.count<session::ReferenceRequest>(), 1);
  const auto& reference = std::get<session::ReferenceRequest>(bench_.requests.posted.back());
  // Where the tracker has the reference now (the default: 0.90 m along the robot's y axis).
  EXPECT_EQ(reference.id, 0);
  EXPECT_NEAR(reference.position[1], 0.9, 1e-6);
}

// An ERP by hand: eight channels, 0.8 s at 64 Hz, a target bump at 0.35 s over a flat other.
std::shared_ptr<const bci::ErpCurves> handErp() {
  auto erp = std::make_shared<bci::ErpCurves>();
  erp->channels = {"Fz", "Cz", "P3", "Pz", "P4", "PO7", "Oz", "PO8"};
  erp->rate_hz = 64.0;
  erp->window_end_s = 0.8;
  erp->targets = 40;
  erp->others = 120;
  const int n = 52;
  erp->target_mean.resize(8, n);
  erp->other_mean.resize(8, n);
  erp->target_se = Eigen::MatrixXd::Constant(8, n, 0.5);
  erp->other_se = Eigen::MatrixXd::Constant(8, n, 0.3);
  erp->signed_r2 = Eigen::MatrixXd::Zero(8, n);
  for (int c = 0; c < 8; ++c) {
    for (int i = 0; i < n; ++i) {
      const double t = i / 64.0;
      erp->target_mean(c, i) = 5.0 * std::exp(-std::pow((t - 0.35) / 0.09, 2) / 2);
      erp->other_mean(c, i) = -0.5 * std::exp(-std::pow((t - 0.2) / 0.05, 2) / 2);
    }
  }
  return erp;
}

int countPixels(const cv::Mat& rgba, const std::function<bool(const cv::Vec4b&)>& pick) {
  int n = 0;
  for (int y = 0; y < rgba.rows; ++y)
    for (int x = 0; x < rgba.cols; ++x) n += pick(rgba.at<cv::Vec4b>(y, x));
  return n;
}

// The session's own averages, on the record once it trained: the P300's target (red) and
// non-target (blue) curves beside the ErrP's.
TEST_F(Panels, TheTrainingPanelPlotsTheSessionsAveragesOfBothClassifiers) {
  bench_.record.p300.erp = handErp();
  bench_.record.errp.erp = handErp();
  auto panel = make("training");
  const Drawn d = draw(*panel);
  const int red =
      countPixels(d.image, [](const cv::Vec4b& p) { return p[0] > 170 && p[1] < 90 && p[2] < 90; });
  const int blue =
      countPixels(d.image, [](const cv::Vec4b& p) { return p[2] > 170 && p[0] < 120; });
  EXPECT_GT(red, 500);
  EXPECT_GT(blue, 500);
}

// Ending with an object in the gripper: the dialog says so and offers to put it back first.
TEST_F(Panels, EndingWithAnObjectHeldOffersToPutItBackFirst) {
  bench_.record.paradigm.interrupted = bci::Phase::Grasping;
  bench_.record.paradigm.phase = bci::Phase::EmergencyStop;
  bench_.record.robot.status->holding = 20;
  bench_.record.robot.at_home = false;
  auto panel = make("robot");
  Drawer drawer(*context_, *panel);
  ASSERT_TRUE(drawer.click(bench_, "End session"));
  const Drawn dialog = drawer.frames(bench_, 2);
  ASSERT_TRUE(dialog.widgets.count("Put it back first"));
  EXPECT_TRUE(dialog.widgets.count("End now"));
  EXPECT_TRUE(dialog.widgets.at("Put it back first").enabled)
      << dialog.widgets.at("Put it back first").why_disabled;
  ASSERT_TRUE(drawer.click(bench_, "Put it back first"));
  EXPECT_EQ(bench_.requests.count<session::RobotReleaseRequest>(), 1);
  EXPECT_EQ(bench_.requests.count<session::EndSessionRequest>(), 0);
}

// A setting out of its range: refused with the session file's message, Save disabled with it.
TEST_F(Panels, TheSettingsPanelRefusesABadValueWithItsReason) {
  bench_.settings.paradigm.flash_ms = 1.0;
  auto panel = make("settings");
  const Drawn d = draw(*panel);
  ASSERT_TRUE(d.widgets.count("Save"));
  EXPECT_FALSE(d.widgets.at("Save").enabled);
  const std::string why = d.widgets.at("Save").why_disabled;
  EXPECT_NE(why.find("paradigm.flash_ms"), std::string::npos) << why;
}

// Before Start an edit applies to the run about to start (the window opens the session again
// with it); once the run goes on, the panel offers it to the next run only.
TEST_F(Panels, TheSettingsPanelAppliesAnEditBeforeStartAndNotOnceRunning) {
  bench_.record.paradigm.phase = bci::Phase::Setup;
  bench_.settings.paradigm.trials = 3;
  auto panel = make("settings");
  Drawer drawer(*context_, *panel);
  const Drawn unedited = drawer.frames(bench_);
  ASSERT_TRUE(unedited.widgets.count("Apply to this run"));
  EXPECT_FALSE(unedited.widgets.at("Apply to this run").enabled) << "nothing edited yet";
  ASSERT_TRUE(drawer.type(bench_, "find a setting", "trials"));
  ASSERT_TRUE(drawer.type(bench_, "paradigm.trials", "2"));
  const Drawn edited = drawer.frames(bench_);
  ASSERT_TRUE(edited.widgets.at("Apply to this run").enabled)
      << edited.widgets.at("Apply to this run").why_disabled;
  ASSERT_TRUE(drawer.click(bench_, "Apply to this run"));
  ASSERT_EQ(bench_.requests.count<session::ApplySettingsRequest>(), 1);
  const auto& apply = std::get<session::ApplySettingsRequest>(bench_.requests.posted.back());
  EXPECT_EQ(nlohmann::json::parse(apply.settings_json).at("paradigm").at("trials"), 2);

  bench_.record.paradigm.phase = bci::Phase::CalibrationFlashing;
  const Drawn running = drawer.frames(bench_);
  EXPECT_FALSE(running.widgets.count("Apply to this run"));
  EXPECT_TRUE(running.widgets.count("Save"));
}

TEST(StartError, TheScreenShowsTheReasonAndQuitEndsIt) {
  auto context = render::createHeadlessContext(kSize);
  ImGuiLayer imgui(*context, "");
  const std::string reason = "session.json: eeg.file = \"x.bdf\": no such file";
  bool quit = false;
  for (int frame = 0; frame < 6 && !quit; ++frame) {
    SyntheticInput input;
    if (frame >= 3) {
      const auto& widgets = drawnWidgets();
      const auto found = std::find_if(widgets.begin(), widgets.end(),
                                      [](const DrawnWidget& w) { return w.label == "Quit"; });
      ASSERT_NE(found, widgets.end());
      input.x = 0.5f * (found->x0 + found->x1);
      input.y = 0.5f * (found->y0 + found->y1);
      input.left_down = frame == 4;
    }
    context->makeCurrent();
    imgui.beginFrame(1.0f / 60.0f, &input);
    quit = drawStartError(1000.0f, 700.0f, reason);
    render::clearFramebuffer(context->drawFramebuffer(), kSize, {0.08f, 0.09f, 0.11f, 1.0f});
    imgui.endFrame();
    context->present();
  }
  EXPECT_TRUE(quit);
}

// Ctrl+Q quits as the File menu says: before a session starts, at once.
TEST_F(Panels, CtrlQQuitsTheShell) {
  auto panel = make("log");
  bench_.record.paradigm.phase = bci::Phase::Setup;
  ImGuiLayer imgui(*context_, "");
  ExperimenterShell shell;
  shell.addPanel(*panel);
  int quits = 0;
  shell.setQuitHandler([&] { ++quits; });
  for (int frame = 0; frame < 3; ++frame) {
    SyntheticInput input;
    if (frame == 1) {
      input.key = 'Q';
      input.ctrl = true;
    }
    context_->makeCurrent();
    imgui.beginFrame(1.0f / 60.0f, &input);
    shell.draw(kSize, {16.7f, "", ""}, bench_.input());
    imgui.endFrame();
  }
  EXPECT_EQ(quits, 1);
}

// While a session runs, Ctrl+Q asks the question Abort asks before it ends anything.
TEST_F(Panels, CtrlQInARunningSessionAsksFirst) {
  auto panel = make("log");
  Drawer drawer(*context_, *panel);
  int quits = 0;
  drawer.shell().setQuitHandler([&] { ++quits; });
  bench_.record.paradigm.phase = bci::Phase::CalibrationFlashing;
  drawer.ctrlKey(bench_, 'Q');
  EXPECT_EQ(quits, 0) << "quit without asking";
  ASSERT_TRUE(drawer.click(bench_, "Cancel"));
  EXPECT_EQ(quits, 0);
  drawer.ctrlKey(bench_, 'Q');
  ASSERT_TRUE(drawer.click(bench_, "Yes, quit"));
  EXPECT_EQ(quits, 1);
}

}  // namespace
}  // namespace arbci::ui

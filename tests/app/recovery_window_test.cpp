// A study day in the real window under Xvfb, driven by a scripted experimenter (arbci run
// --script: real mouse clicks on the panels' buttons, found by label): the subject typed on the
// start screen and Start, the calibration run, an emergency stop during the grasp, Home, Retry
// step, and the session finishes; and a session file that cannot start, shown in the window. A
// marker covered in calibration is tested on the paradigm stage: a cover at fixed session seconds
// (9-12 s) missed the calibration's flashes on a loaded machine, and the walk waited in vain. The
// screenshots of each step are kept (build/test-artefacts/recovery) and checked with their
// sidecars: the panels drawn, each button's state and the reason it is disabled. Each panel's
// behaviour on its own is tested in process on hand-built records (tests/ui/panels_test.cpp).
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <sstream>
#include <thread>

#include "support/background_process.h"
#include "support/run_process.h"
#include "support/test_files.h"
#include "support/xvfb_server.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;
const std::filesystem::path kArtefacts = ARBCI_TEST_ARTEFACTS_DIR;

// A quick session (a short calibration run, one trial) with a slow arm, so a grasp lasts long
// enough to be stopped. Under Xvfb on a loaded machine most frames come late: the timing gate
// would pause the run (gates.timing "pause", its own tests' subject); here flashes are annotated.
// A quick calibration gives a model too unsure for the arm's paradigm.act_certainty; what these
// tests check is the window and the arm's recovery, so the arm acts on every selection.
void writeSession(const std::filesystem::path& file) {
  std::ofstream(file) << R"({
    "cameras": {"head_motion_m": 0.0, "head_motion_deg": 0.0},
    "paradigm": {"calibration_selections": 4, "calibration_sequences": 5, "sequences": 5,
                 "min_sequences": 5, "certainty": 0.0, "act_certainty": 0.0, "trials": 1,
                 "cue_s": 1.0, "pause_s": 0.5,
                 "intended": [{"object": 40, "cell": [3, 1]}]},
    "robot": {"speed_factor": 2},
    "gates": {"timing": "annotate"}})";
}

// The window at 1280x720 (a laptop screen), its layout file in a fresh folder: arbci run with
// the session file FOLDER/session.json and the script, and `extra` options; `out`: the session
// folder (FOLDER/out by default).
ProcessResult runWindow(const std::filesystem::path& folder, const std::string& script,
                        const std::vector<std::string>& extra, const std::string& out) {
  std::ofstream(folder / "script.txt") << script;
  const XvfbServer x("1280x720x24");
  std::vector<std::string> arguments = {"-u",
                                        "XAUTHORITY",
                                        "DISPLAY=" + x.display(),
                                        "XDG_CONFIG_HOME=" + (folder / "config").string(),
                                        kArbci,
                                        "run",
                                        "--session",
                                        (folder / "session.json").string(),
                                        "--out",
                                        (folder / out).string(),
                                        "--script",
                                        (folder / "script.txt").string(),
                                        "--exit-when-done"};
  arguments.insert(arguments.end(), extra.begin(), extra.end());
  return runProcess("/usr/bin/env", arguments, 420.0);
}

// The same with the quick session (writeSession).
ProcessResult runScript(const std::filesystem::path& folder, const std::string& script,
                        const std::vector<std::string>& extra = {},
                        const std::string& out = "out") {
  std::filesystem::create_directories(folder);
  writeSession(folder / "session.json");
  return runWindow(folder, script, extra, out);
}

std::vector<nlohmann::json> logEvents(const std::filesystem::path& log, const std::string& event) {
  std::vector<nlohmann::json> out;
  std::ifstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    const nlohmann::json j = nlohmann::json::parse(line);
    if (j["event"] == event) out.push_back(j);
  }
  return out;
}

const nlohmann::json* button(const nlohmann::json& shot, const std::string& label,
                             const std::string& panel) {
  for (const nlohmann::json& b : shot["buttons"]) {
    if (b["label"] == label && b["panel"] == panel) return &b;
  }
  return nullptr;
}

// A screenshot that shows the window: 1280x720, not one flat colour, the panels named, and the
// Robot panel's EMERGENCY STOP button red where the sidecar says it is.
nlohmann::json checkScreenshot(const std::filesystem::path& png,
                               const std::vector<std::string>& panels) {
  const cv::Mat image = cv::imread(png.string(), cv::IMREAD_COLOR);
  EXPECT_EQ(image.cols, 1280) << png;
  EXPECT_EQ(image.rows, 720) << png;
  if (image.empty()) return {};
  cv::Scalar mean, sd;
  cv::meanStdDev(image, mean, sd);
  EXPECT_GT(sd[0] + sd[1] + sd[2], 30.0) << png << ": nearly one flat colour";
  std::filesystem::path sidecar = png;
  const nlohmann::json shot = readJson(sidecar.replace_extension(".json"));
  for (const std::string& panel : panels) {
    EXPECT_NE(std::find(shot["panels"].begin(), shot["panels"].end(), panel), shot["panels"].end())
        << png << " lacks the " << panel << " panel: " << shot["panels"];
  }
  if (const nlohmann::json* stop = button(shot, "EMERGENCY STOP", "Robot");
      stop && !(*stop)["enabled"].get<bool>()) {
    // Once the session has ended it no longer drives the arm: the button says so.
    EXPECT_NE((*stop)["why_disabled"].get<std::string>().find("emergency switch"),
              std::string::npos)
        << *stop;
  } else if (stop) {
    const auto& r = (*stop)["rect"];
    const cv::Point centre(static_cast<int>((r[0].get<double>() + r[2].get<double>()) / 2),
                           static_cast<int>((r[1].get<double>() + r[3].get<double>()) / 2 - 4));
    const cv::Vec3b bgr = image.at<cv::Vec3b>(centre);
    EXPECT_GT(bgr[2], 150) << png << ": the stop button is not red at " << centre;
    EXPECT_LT(bgr[1], 90) << png;
  } else {
    ADD_FAILURE() << png << ": no EMERGENCY STOP button in the Robot panel";
  }
  return shot;
}

TEST(RecoveryWindow, EmergencyStopDuringTheGraspThenHomeRetryAndTheSessionFinishes) {
  const auto folder = kArtefacts / "recovery";
  std::filesystem::remove_all(folder);
  const std::string shots = (folder / "shots").string();
  std::filesystem::create_directories(shots);
  const ProcessResult r = runScript(folder, R"(# the start screen: the subject, then Start
pause 1
click "subject"
type "07"
pause 0.3
click "Start"
# the calibration review: the experimenter goes online
wait "calibration review" 240
pause 0.5
screenshot )" + shots + R"(/0-review.png
click "Go online"
# an emergency stop during the grasp
wait "robot grasping" 240
pause 1
click "EMERGENCY STOP"
wait "EMERGENCY STOP"
pause 0.3
screenshot )" + shots + R"(/1-stopped.png
click "Home"
pause 0.3
screenshot )" + shots + R"(/2-homing.png
click "Retry step" 90
wait "phase 2" 120
screenshot )" + shots + R"(/3-retried.png
wait "finished" 240
pause 0.5
screenshot )" + shots + R"(/4-finished.png
)",
                                    {}, "out");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto out = folder / "out";
  const nlohmann::json summary = readJson(out / "summary.json");
  EXPECT_EQ(summary["ended"], "finished") << summary["end_reason"];
  // The subject given on the start screen; the run numbered among the session folders (the first).
  EXPECT_EQ(summary["labels"]["subject"], "07");
  EXPECT_EQ(summary["labels"]["run"], "1");
  ASSERT_EQ(summary["trials"].size(), 1u);
  EXPECT_EQ(summary["trials"][0]["outcome"], "placed");
  EXPECT_TRUE(summary["trials"][0]["placement_error_m"].is_number());
  // The calibration run, every selection trained on.
  EXPECT_EQ(summary["calibration"]["selections"], 4);
  EXPECT_EQ(summary["calibration"]["selections_used"].size(), 4u);

  // The log: the stop, the experimenter's HOME, the retry, and a second GRASP that succeeded.
  const auto log = out / "log.jsonl";
  EXPECT_EQ(logEvents(log, "emergency_stop").size(), 1u);
  int grasps = 0, experimenter_homes = 0;
  for (const nlohmann::json& c : logEvents(log, "robot_command")) {
    grasps += c["command"] == "GRASP";
    experimenter_homes += c["command"] == "HOME" && c.value("by", "") == "experimenter";
  }
  EXPECT_EQ(grasps, 2);
  EXPECT_EQ(experimenter_homes, 1);
  const auto recovery = logEvents(log, "recovery");
  ASSERT_EQ(recovery.size(), 1u);
  EXPECT_EQ(recovery[0]["action"], "retry step");
  int grasps_done = 0;
  for (const nlohmann::json& e : logEvents(log, "robot"))
    grasps_done += e["command"] == "GRASP" && e["kind"] == "finished" && e["outcome"] == "success";
  EXPECT_EQ(grasps_done, 1);  // the first was stopped

  // The steps as the experimenter saw them.
  const nlohmann::json stopped =
      checkScreenshot(folder / "shots/1-stopped.png", {"Session", "Robot", "HMD view"});
  EXPECT_EQ(stopped["phase"], "EMERGENCY STOP");
  const nlohmann::json* retry = button(stopped, "Retry step", "Robot");
  ASSERT_NE(retry, nullptr);
  EXPECT_TRUE((*retry)["enabled"].get<bool>());
  for (const char* label : {"Skip trial"}) {
    const nlohmann::json* b = button(stopped, label, "Robot");
    ASSERT_NE(b, nullptr) << label;
    EXPECT_FALSE((*b)["enabled"].get<bool>()) << label;
    EXPECT_NE((*b)["why_disabled"].get<std::string>().find("arm"), std::string::npos) << *b;
  }
  // Resume would start the next trial with the arm out: refused, and the button says why.
  const nlohmann::json* resume = button(stopped, "Resume", "Session");
  ASSERT_NE(resume, nullptr);
  EXPECT_FALSE((*resume)["enabled"].get<bool>());
  EXPECT_FALSE((*resume)["why_disabled"].get<std::string>().empty());

  checkScreenshot(folder / "shots/2-homing.png", {"Session", "Robot"});
  const nlohmann::json retried = checkScreenshot(folder / "shots/3-retried.png", {"Robot"});
  EXPECT_NE(retried["phase"].get<std::string>().find("phase 2"), std::string::npos);
  EXPECT_FALSE((*button(retried, "Retry step", "Robot"))["enabled"].get<bool>());
  const nlohmann::json finished =
      checkScreenshot(folder / "shots/4-finished.png", {"Session", "Robot", "Session summary"});
  for (const char* label : {"Pause", "Abort"})
    EXPECT_FALSE((*button(finished, label, "Session"))["enabled"].get<bool>()) << label;
}

// A session file the window cannot start with: the window opens anyway and says why, in the
// same words as the terminal, with Quit; no session folder is left behind.
TEST(RecoveryWindow, ASessionFileThatCannotStartIsShownInTheWindowWithItsReason) {
  const auto folder = kArtefacts / "recovery_bad_file";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "session.json") << R"({"paradigm": {"min_sequences": 0}})";
  const auto shot = folder / "cannot-start.png";
  const ProcessResult r =
      runWindow(folder, "pause 0.5\nscreenshot " + shot.string() + "\nclick \"Quit\"\n", {}, "out");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  const std::string reason = "paradigm.min_sequences = 0 must lie in [1, 100]";
  EXPECT_NE(r.err.find(reason), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(folder / "out"));
  const cv::Mat image = cv::imread(shot.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  std::filesystem::path sidecar = shot;
  const nlohmann::json drawn = readJson(sidecar.replace_extension(".json"));
  EXPECT_EQ(drawn["phase"], "cannot start");
  EXPECT_EQ(drawn["panels"], nlohmann::json{"The session cannot start"});
  ASSERT_NE(button(drawn, "Quit", "The session cannot start"), nullptr);
  // The message is drawn: red text in the window's first lines.
  const cv::Mat top = image(cv::Rect(0, 25, 640, 25));
  std::vector<cv::Mat> bgr;
  cv::split(top, bgr);
  EXPECT_GT(cv::countNonZero((bgr[2] > 180) & (bgr[1] < 140)), 100);
}

// The X server gone under the window (killed, the desktop logged out): Xlib would end the process
// on the spot. The run ends as a fault with the reason, its summary written and its recording
// whole; exit 3.
TEST(RecoveryWindow, TheDisplayGoneEndsTheRunAsAFaultWithItsSummary) {
  const auto folder = kArtefacts / "recovery_display_gone";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  writeSession(folder / "session.json");
  const auto out = folder / "out";
  std::optional<XvfbServer> x(std::in_place, "1280x720x24");
  BackgroundProcess arbci(
      "/usr/bin/env",
      {"-u", "XAUTHORITY", "DISPLAY=" + x->display(),
       "XDG_CONFIG_HOME=" + (folder / "config").string(), kArbci, "run", "--session",
       (folder / "session.json").string(), "--out", out.string(), "--start-now"});
  // Running: the log has its cycles (however slowly this machine draws them).
  const auto running = [&] {
    std::ifstream log(out / "log.jsonl");
    std::stringstream text;
    text << log.rdbuf();
    return text.str().find("\"event\":\"cycle\"") != std::string::npos;
  };
  for (int i = 0; i < 1200 && !running(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(running());
  x.reset();  // the X server ends
  const std::optional<int> status = arbci.wait(120.0);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(*status, 3);
  const nlohmann::json summary = readJson(out / "summary.json");
  EXPECT_EQ(summary["ended"], "fault");
  EXPECT_NE(summary["end_reason"].get<std::string>().find("the display (X server"),
            std::string::npos)
      << summary["end_reason"];
  const ProcessResult info = runProcess(kArbci, {"eeg", "info", (out / "recording.bdf").string()});
  EXPECT_EQ(info.exit_code, 0) << info.err;
}

}  // namespace
}  // namespace arbci::test

// A study day's recovery in the real window under Xvfb, driven by a scripted experimenter
// (arbci run --script: real mouse clicks on the panels' buttons, found by label): a marker
// covered during the calibration run (the selection paused, retaken, left out of training), an
// emergency stop during the grasp, Home, Retry step, and the session finishes; or the
// experimenter ends it in the stop. The screenshots of each step are kept
// (build/test-artefacts/recovery) and checked with their sidecars: the panels drawn, each button's
// state and the reason it is disabled.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "support/run_process.h"
#include "support/test_files.h"
#include "support/xvfb_server.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;
const std::filesystem::path kArtefacts = ARBCI_TEST_ARTEFACTS_DIR;

// A quick session (a short calibration run, one trial) with a slow arm, so a grasp lasts long
// enough to be stopped. `covered`: a hand over object 10's marker from 9 s to 12 s of session
// time, during the calibration run (longer than a cue and its pause, so it meets flashes).
void writeSession(const std::filesystem::path& file, bool covered) {
  std::ofstream(file) << R"({
    "cameras": {"head_motion_m": 0.0, "head_motion_deg": 0.0},)"
                      << (covered ? R"(
    "world": {"objects": [
      {"id": 10, "position": [-0.27, 0.42, 0.06], "color": [0.85, 0.30, 0.25],
       "covered_s": [9, 12]},
      {"id": 20, "position": [-0.09, 0.42, 0.06], "color": [0.25, 0.55, 0.85]},
      {"id": 30, "position": [0.09, 0.42, 0.06], "color": [0.30, 0.75, 0.35]},
      {"id": 40, "position": [0.27, 0.42, 0.06], "color": [0.90, 0.75, 0.20]}]},)"
                                  : "")
                      << R"(
    "paradigm": {"calibration_selections": 4, "calibration_sequences": 5, "sequences": 5,
                 "min_sequences": 5, "certainty": 0.0, "trials": 1, "cue_s": 1.0, "pause_s": 0.5,
                 "intended": [{"object": 40, "cell": [3, 1]}]},
    "robot": {"speed_factor": 2}})";
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
                        const std::vector<std::string>& extra = {}, const std::string& out = "out",
                        bool covered = false) {
  std::filesystem::create_directories(folder);
  writeSession(folder / "session.json", covered);
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
  const ProcessResult r =
      runScript(folder, R"(# a marker covered in calibration: its selection retaken
wait "paused" 120
pause 0.5
screenshot )" + shots + R"(/0-covered.png
wait "target cued" 60
pause 0.3
screenshot )" + shots + R"(/0-retaken.png
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
                {}, "out", true);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto out = folder / "out";
  const nlohmann::json summary = readJson(out / "summary.json");
  EXPECT_EQ(summary["ended"], "finished") << summary["end_reason"];
  ASSERT_EQ(summary["trials"].size(), 1u);
  EXPECT_EQ(summary["trials"][0]["outcome"], "placed");
  EXPECT_TRUE(summary["trials"][0]["placement_error_m"].is_number());
  // The calibration selection the hand cut was retaken and left out of training.
  const nlohmann::json& calibration = summary["calibration"];
  ASSERT_EQ(calibration["retaken"].size(), 1u) << calibration.dump();
  EXPECT_EQ(calibration["retaken"][0]["reason"], "tracking lost: object 10");
  EXPECT_EQ(calibration["selections"], 4);
  EXPECT_EQ(calibration["selections_used"].size(), 4u);
  const nlohmann::json covered = checkScreenshot(folder / "shots/0-covered.png", {"Session"});
  EXPECT_EQ(covered["phase"], "paused");
  const nlohmann::json retaken = checkScreenshot(folder / "shots/0-retaken.png", {"Session"});
  EXPECT_EQ(retaken["phase"], "calibration: target cued");

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

TEST(RecoveryWindow, EndingTheSessionInAnEmergencyStopIsRecordedAsEstop) {
  const auto folder = kArtefacts / "recovery_end";
  std::filesystem::remove_all(folder);
  const ProcessResult r = runScript(folder, R"(wait "robot grasping" 240
click "EMERGENCY STOP"
wait "EMERGENCY STOP"
click "End session"
pause 0.3
screenshot )" + (folder / "asked.png").string() +
                                                R"(
click "End now"
wait "ended by the experimenter"
screenshot )" + (folder / "ended.png").string() +
                                                "\n");
  EXPECT_EQ(r.exit_code, 3) << r.err;  // ended otherwise than finished
  const nlohmann::json summary = readJson(folder / "out/summary.json");
  EXPECT_EQ(summary["ended"], "estop");
  EXPECT_NE(summary["end_reason"].get<std::string>().find("experimenter"), std::string::npos);
  // End session asked first, in a dialog of its own.
  const nlohmann::json asked = checkScreenshot(folder / "asked.png", {"Robot"});
  EXPECT_NE(button(asked, "End now", "End session?"), nullptr) << asked["buttons"];
  EXPECT_NE(button(asked, "Cancel", "End session?"), nullptr);
  const nlohmann::json shot = checkScreenshot(folder / "ended.png", {"Session summary"});
  EXPECT_FALSE((*button(shot, "End session", "Robot"))["enabled"].get<bool>());
  EXPECT_EQ(shot["phase"].get<std::string>().rfind("ended: estop (ended by the experimenter", 0),
            0u)
      << shot["phase"];
  // After the end the E-STOP says it no longer reaches the arm, and the log says how it ended.
  EXPECT_FALSE((*button(shot, "EMERGENCY STOP", "Robot"))["enabled"].get<bool>());
  EXPECT_TRUE(shot["panels"].dump().find("Operator log") != std::string::npos) << shot["panels"];
}

// End session with an object in the gripper: the dialog offers to put it back first; the arm
// does, and the session ends holding nothing.
TEST(RecoveryWindow, EndingWithAnObjectHeldOffersToPutItBackFirst) {
  const auto folder = kArtefacts / "recovery_held";
  std::filesystem::remove_all(folder);
  const ProcessResult r = runScript(folder, R"(wait "phase 2" 240
click "EMERGENCY STOP"
wait "EMERGENCY STOP"
click "End session"
pause 0.3
screenshot )" + (folder / "held.png").string() + R"(
click "Put it back first"
pause 15
click "End session"
pause 0.3
screenshot )" + (folder / "empty.png").string() +
                                                R"(
click "End now"
wait "ended" 30
)");
  EXPECT_EQ(r.exit_code, 3) << r.err;
  const nlohmann::json held = checkScreenshot(folder / "held.png", {"Robot"});
  const nlohmann::json* back = button(held, "Put it back first", "End session?");
  ASSERT_NE(back, nullptr) << held["buttons"];
  EXPECT_TRUE((*back)["enabled"].get<bool>()) << *back;
  // The second time the gripper is empty: no offer, only the end.
  const nlohmann::json empty = checkScreenshot(folder / "empty.png", {"Robot"});
  EXPECT_EQ(button(empty, "Put it back first", "End session?"), nullptr);
  EXPECT_NE(button(empty, "End now", "End session?"), nullptr);
  // The log: the experimenter's put-back, finished, before the end.
  const auto log = folder / "out/log.jsonl";
  int put_back = 0;
  for (const nlohmann::json& c : logEvents(log, "robot_command"))
    put_back += c.value("by", "") == "experimenter" && c["command"] != "HOME" &&
                c["command"] != "RESET" && c["command"] != "STOP";
  EXPECT_EQ(put_back, 1);
  const nlohmann::json summary = readJson(folder / "out/summary.json");
  EXPECT_EQ(summary["ended"], "estop");
}

// The window as a study day starts: the EEG panel with every channel graded, the operator log,
// and the settings edited in the window, a bad value refused with the session file's message.
TEST(RecoveryWindow, SettingsAreEditedInTheWindowAndABadValueIsRefusedWithItsReason) {
  const auto folder = kArtefacts / "study_day";
  std::filesystem::remove_all(folder);
  const ProcessResult r = runScript(folder, R"(wait "calibration" 60
pause 3
screenshot )" + (folder / "eeg.png").string() + R"(
open "Settings"
click "find a setting"
type "min_sequences"
click "paradigm.min_sequences"
type "0"
pause 0.3
screenshot )" + (folder / "refused.png").string() +
                                                R"(
click "paradigm.min_sequences"
type "3"
pause 0.3
screenshot )" + (folder / "fixed.png").string() +
                                                R"(
key ctrl+q
)");
  EXPECT_EQ(r.exit_code, 3) << r.err;  // closed before the end
  // The EEG panel and the operator log are there from the start; the EEG's grade marks (green)
  // are drawn.
  const nlohmann::json eeg =
      checkScreenshot(folder / "eeg.png", {"Session", "EEG", "Operator log"});
  const cv::Mat image = cv::imread((folder / "eeg.png").string(), cv::IMREAD_COLOR);
  int marks = 0;
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) {
      const cv::Vec3b p = image.at<cv::Vec3b>(y, x);
      marks += std::abs(p[2] - 70) < 12 && std::abs(p[1] - 190) < 12 && std::abs(p[0] - 90) < 12;
    }
  EXPECT_GT(marks, 100) << "no quality marks in the EEG panel";
  // A bad value: Save is refused with the message a session file would get.
  const nlohmann::json refused = checkScreenshot(folder / "refused.png", {"Settings"});
  const nlohmann::json* save = button(refused, "Save", "Settings");
  ASSERT_NE(save, nullptr) << refused["buttons"];
  EXPECT_FALSE((*save)["enabled"].get<bool>());
  const std::string why = (*save)["why_disabled"].get<std::string>();
  EXPECT_NE(why.find("paradigm.min_sequences"), std::string::npos) << why;
  EXPECT_NE(why.find("must"), std::string::npos) << why;
  // Fixed, Save goes again.
  const nlohmann::json fixed = checkScreenshot(folder / "fixed.png", {"Settings"});
  EXPECT_TRUE((*button(fixed, "Save", "Settings"))["enabled"].get<bool>())
      << (*button(fixed, "Save", "Settings"));
}

// The start screen: subject, session, task and run given in the window before Start; with a
// BIDS root, Start waits for the subject, shows the run it will take, and runs are numbered one
// after the other.
TEST(RecoveryWindow, TheSubjectAndRunAreGivenOnTheStartScreenAndRunsAreNumbered) {
  const auto folder = kArtefacts / "start_screen";
  std::filesystem::remove_all(folder);
  const auto root = folder / "bids";
  const std::vector<std::string> bids = {"--wait-for-start", "--bids", root.string()};
  const std::string script = R"(pause 1
screenshot )" + (folder / "empty.png").string() +
                             R"(
click "subject"
type "07"
click "session"
type "01"
pause 0.3
screenshot )" + (folder / "named.png").string() +
                             R"(
click "Start"
wait "calibration" 60
pause 1
key ctrl+q
)";
  const ProcessResult first = runScript(folder, script, bids, "out1");
  EXPECT_EQ(first.exit_code, 3) << first.err;  // closed during the calibration
  // Before a subject: Start says why not; named, it shows where the run goes.
  const nlohmann::json empty = readJson(folder / "empty.json");
  const nlohmann::json* start = button(empty, "Start", "Session");
  ASSERT_NE(start, nullptr);
  EXPECT_FALSE((*start)["enabled"].get<bool>());
  EXPECT_NE((*start)["why_disabled"].get<std::string>().find("give the subject"), std::string::npos)
      << *start;
  const nlohmann::json named = readJson(folder / "named.json");
  EXPECT_TRUE((*button(named, "Start", "Session"))["enabled"].get<bool>());
  const nlohmann::json summary = readJson(folder / "out1/summary.json");
  EXPECT_EQ(summary["labels"]["subject"], "07");
  EXPECT_EQ(summary["labels"]["session"], "01");
  EXPECT_TRUE(
      std::filesystem::exists(root / "sub-07/ses-01/eeg/sub-07_ses-01_task-arbci_run-1_eeg.bdf"))
      << first.err;
  // The next run of the same subject and session takes run 2.
  const ProcessResult second = runScript(folder, script, bids, "out2");
  EXPECT_EQ(second.exit_code, 3) << second.err;
  EXPECT_TRUE(
      std::filesystem::exists(root / "sub-07/ses-01/eeg/sub-07_ses-01_task-arbci_run-2_eeg.bdf"))
      << second.err;
}

// Without a BIDS root, a subject's runs are numbered among the session folders beside one
// another: the start screen says which run it will be, and summary.json records it.
TEST(RecoveryWindow, WithoutABidsRootRunsAreNumberedAmongTheSessionFolders) {
  const auto folder = kArtefacts / "start_screen_folders";
  std::filesystem::remove_all(folder);
  const std::string script = R"(pause 1
click "subject"
type "07"
pause 0.3
screenshot )" + (folder / "named.png").string() +
                             R"(
click "Start"
wait "calibration" 60
key ctrl+q
)";
  for (const char* out : {"out1", "out2"}) {
    const ProcessResult r = runScript(folder, script, {"--wait-for-start"}, out);
    EXPECT_EQ(r.exit_code, 3) << r.err;  // closed during the calibration
  }
  EXPECT_EQ(readJson(folder / "out1/summary.json")["labels"]["run"], "1");
  const nlohmann::json second = readJson(folder / "out2/summary.json");
  EXPECT_EQ(second["labels"]["subject"], "07");
  EXPECT_EQ(second["labels"]["run"], "2");
}

// Ctrl+Q closes the window as the File menu says; the session ends there, its summary saved.
TEST(RecoveryWindow, CtrlQQuitsTheWindowAndTheSummarySaysItWasClosed) {
  const auto folder = kArtefacts / "recovery_quit";
  std::filesystem::remove_all(folder);
  const ProcessResult r = runScript(folder, "wait \"calibration\" 60\npause 1\nkey ctrl+q\n");
  EXPECT_EQ(r.exit_code, 3) << r.err;  // not finished
  const nlohmann::json summary = readJson(folder / "out/summary.json");
  EXPECT_EQ(summary["ended"], "aborted");
  EXPECT_EQ(summary["end_reason"], "closed");
  EXPECT_LT(summary["duration_s"].get<double>(), 30.0);
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

// A script that cannot go on says which line and why, and the run exits 4.
TEST(RecoveryWindow, AScriptClickOnADisabledButtonFailsNamingTheLineAndTheReason) {
  const auto folder = kArtefacts / "recovery_refused";
  std::filesystem::remove_all(folder);
  const ProcessResult r = runScript(folder, "pause 1\nclick \"Skip trial\" 2\n");
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_NE(r.err.find("script line 2: \"Skip trial\" stayed disabled: only after an emergency "
                       "stop or a robot fault"),
            std::string::npos)
      << r.err;
}

}  // namespace
}  // namespace arbci::test

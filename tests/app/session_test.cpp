// The simulated session end to end, headless, through the real executables: a calibration run,
// training, then online trials with given intentions; a subject without ERP (selections fail,
// the session says so and carries on); the robot backend killed during a grasp; and ErrPs
// stopping wrong robot actions.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "arbci/bci/recording.h"
#include "support/run_process.h"
#include "support/shared_data.h"
#include "support/test_files.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;
const std::string kSessions = ARBCI_TEST_SESSIONS;

std::filesystem::path fresh(const std::string& name) {
  return freshTempPath("session_test", name);
}

std::vector<nlohmann::json> readLog(const std::filesystem::path& path) {
  std::vector<nlohmann::json> lines;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

TEST(Session, CalibrationTrainingAndThreeTrialsAllRightEachObjectWithinACentimetre) {
  const auto folder = fresh("e2e");
  const ProcessResult r =
      runProcess(kArbci,
                 {"run", "--headless", "--session", kSessions + "/steady_head.json", "--seed", "3",
                  "--out", folder.string()},
                 600.0);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  const nlohmann::json summary = readJson(folder / "summary.json");
  EXPECT_EQ(summary["ended"], "finished");
  ASSERT_EQ(summary["trials"].size(), 3u);
  for (const auto& t : summary["trials"]) {
    EXPECT_EQ(t["selected_object"], t["intended_object"]) << t.dump();
    EXPECT_EQ(t["selected_cell"], t["intended_cell"]) << t.dump();
    ASSERT_TRUE(t["placement_error_m"].is_number()) << t.dump();
    EXPECT_LT(t["placement_error_m"].get<double>(), 0.01) << t.dump();
    EXPECT_EQ(t["outcome"], "placed");
  }
  // How long the run took and its overruns are the machine's, not the session's behaviour: they
  // are reported (summary, bench/), and here only checked to be logged one for one (below).
  EXPECT_DOUBLE_EQ(summary["objects"]["accuracy"].get<double>(), 1.0);
  EXPECT_GT(summary["objects"]["bits_per_minute"].get<double>(), 0.0);
  EXPECT_TRUE(summary["cycle"]["stages"].contains("eeg"));
  EXPECT_TRUE(summary["cycle"]["stages"].contains("tracking"));
  EXPECT_GT(summary["calibration"]["auc"].get<double>(), 0.7);

  // The folder is complete.
  for (const char* file :
       {"recording.bdf", "log.jsonl", "summary.json", "model.json", "session.json",
        "hmd_calibration.png", "hmd_trial1_1_objects_flashing.png", "hmd_trial2_3_grasping.png",
        "hmd_trial3_4_grid_flashing.png", "hmd_trial3_6_putting_down.png", "hmd_finished.png"}) {
    EXPECT_TRUE(std::filesystem::exists(folder / file)) << file;
  }
  // The recording is readable, with every flash and the selections.
  const bci::Recording recording = bci::readRecording(folder / "recording.bdf");
  EXPECT_EQ(recording.format, "BDF+");
  ASSERT_EQ(recording.info.channelCount(), 9);  // the montage and the virtual photodiode
  EXPECT_EQ(recording.info.channels.back(), "Photodiode");
  EXPECT_NEAR(recording.seconds(), summary["duration_s"].get<double>(), 0.1);
  // Calibration flashes are labelled by the cue; online flashes by the trial's intention: T
  // exactly when the code stands (StimulusCodeMap) for the intended object, row or column.
  std::int64_t online_from = -1;
  std::vector<std::int64_t> selected_at;
  for (const auto& a : recording.annotations) {
    if (a.text == "Phase training the classifier") online_from = a.sample;
    if (a.text.rfind("Selected", 0) == 0) selected_at.push_back(a.sample);
  }
  ASSERT_GE(online_from, 0);
  ASSERT_EQ(selected_at.size(), 6u);
  std::map<int, std::string> code_map;
  std::stringstream map_text(recording.parameters.at("StimulusCodeMap"));
  for (std::string entry; std::getline(map_text, entry, ';');)
    code_map[std::stoi(entry.substr(0, entry.find('=')))] = entry.substr(entry.find('=') + 1);
  int rows = 0;
  for (const auto& [code, what] : code_map) rows += what.rfind("row ", 0) == 0;
  int calibration_targets = 0, grid_flashes = 0, online_flashes = 0;
  for (const auto& s : recording.stimuli) {
    EXPECT_TRUE(s.known);  // the session knows every trial's intention
    grid_flashes += s.code > 100;
    if (s.sample < online_from) {
      calibration_targets += s.target;
      continue;
    }
    ++online_flashes;
    const auto selection = static_cast<size_t>(
        std::upper_bound(selected_at.begin(), selected_at.end(), s.sample) - selected_at.begin());
    ASSERT_LT(selection, 6u);
    const nlohmann::json& trial = summary["trials"][selection / 2];
    const bool expected =
        selection % 2 == 0
            ? code_map.at(s.code) == "object " + std::to_string(trial["intended_object"].get<int>())
            : s.code == 100 + trial["intended_cell"][0].get<int>() ||
                  s.code == 100 + rows + trial["intended_cell"][1].get<int>();
    EXPECT_EQ(s.target, expected) << "code " << s.code << " in online selection " << selection;
  }
  EXPECT_EQ(calibration_targets, 6 * 8);  // 6 cued selections of 8 sequences
  EXPECT_GT(grid_flashes, 0);
  EXPECT_GT(online_flashes, 0);
  int selections = 0;
  for (const auto& a : recording.annotations) selections += a.text.rfind("Selected", 0) == 0;
  EXPECT_EQ(selections, 6);
  // The log has the robot's commands and replies and per-cycle timings.
  int commands = 0, finished = 0, cycles = 0, overruns = 0;
  for (const auto& line : readLog(folder / "log.jsonl")) {
    commands += line["event"] == "robot_command";
    finished += line["event"] == "robot" && line["kind"] == "finished";
    cycles += line["event"] == "cycle";
    overruns += line["event"] == "overrun";
  }
  EXPECT_EQ(overruns, summary["overruns"].get<int>());  // each one logged
  EXPECT_EQ(commands, 9);  // per trial: grasp, drop, and home to clear the cameras' view
  EXPECT_EQ(finished, 9);
  EXPECT_GT(cycles, 100);
}

// The data records of a BDF (everything after the header: samples and annotations, Stim events
// among them) and its Stim events.
std::string dataRecords(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const int header = std::stoi(bytes.substr(184, 8));
  return bytes.substr(static_cast<size_t>(header));
}

std::vector<std::pair<std::int64_t, int>> stims(const std::filesystem::path& file) {
  std::vector<std::pair<std::int64_t, int>> out;
  for (const auto& s : bci::readRecording(file).stimuli) out.emplace_back(s.sample, s.code);
  return out;
}

// The default world (head motion, camera noise) and subject, with dynamic stopping, through a
// trial with the robot: the same seed gives the same recording. The paradigm is as short as
// still trains (16 target epochs) and reaches the robot. Another seed gives another recording from
// its first seconds on: that run is cut short (a calibration run too short to train ends it) and
// compared over the seconds it has.
TEST(Session, AHeadlessRunIsReproducibleForASeed) {
  const std::string paradigm = R"("calibration_sequences": 4, "sequences": 4, "min_sequences": 2,
    "trials": 1, "cue_s": 0.5, "pause_s": 0.5, "result_s": 0.5}, "robot": {"speed_factor": 20}})";
  const auto session = fresh("repro").string() + ".json";
  std::ofstream(session) << R"({"paradigm": {"calibration_selections": 4, )" + paradigm;
  const auto short_session = fresh("repro_short").string() + ".json";
  std::ofstream(short_session) << R"({"paradigm": {"calibration_selections": 2, )" + paradigm;
  auto run = [&](const std::string& name, const std::string& file, const std::string& seed) {
    const auto folder = fresh(name);
    const ProcessResult r = runProcess(
        kArbci, {"run", "--headless", "--session", file, "--seed", seed, "--out", folder.string()},
        400.0);
    return std::make_pair(r, folder / "recording.bdf");
  };
  const auto [ra, first] = run("repro_a", session, "4");
  const auto [rb, second] = run("repro_b", session, "4");
  const auto [rc, other] = run("repro_c", short_session, "5");
  ASSERT_EQ(ra.exit_code, 0) << ra.err;
  ASSERT_EQ(rb.exit_code, 0) << rb.err;
  ASSERT_EQ(rc.exit_code, 3) << rc.err;  // aborted: too few calibration epochs to train
  EXPECT_NE(rc.err.find("training failed"), std::string::npos) << rc.err;
  const std::string a = dataRecords(first), b = dataRecords(second), c = dataRecords(other);
  EXPECT_GT(a.size(), 250000u);  // about 40 s of 9 channels at 256 Hz, 3 bytes a sample
  EXPECT_TRUE(a == b) << "the same seed gave different data records";
  EXPECT_EQ(stims(first), stims(second));
  ASSERT_GT(c.size(), 50000u);  // about 9 s
  ASSERT_LT(c.size(), a.size());
  EXPECT_NE(a.substr(0, c.size()), c);
  auto first_stims = stims(first), other_stims = stims(other);
  ASSERT_GT(other_stims.size(), 10u);
  first_stims.resize(other_stims.size());
  EXPECT_NE(first_stims, other_stims);
  // The robot acted in it: the trial's grasp and put-down are in the recording.
  int robot_phases = 0;
  for (const auto& note : bci::readRecording(first).annotations)
    robot_phases += note.text.find("robot ") != std::string::npos;
  EXPECT_GE(robot_phases, 2);
}

TEST(Session, WithoutAnErpSelectionsFailAndTheSessionSaysSoAndCarriesOn) {
  const auto folder = fresh("weak");
  const auto session = folder.string() + ".json";
  std::ofstream(session)
      << R"({"eeg": {"erp_scale": 0.0}, "cameras": {"head_motion_m": 0.0, "head_motion_deg": 0.0},
    "paradigm": {"calibration_selections": 4, "calibration_sequences": 4, "sequences": 4,
                 "min_sequences": 2, "trials": 2, "cue_s": 0.5, "pause_s": 0.5, "result_s": 0.5},
    "robot": {"speed_factor": 20}})";
  const ProcessResult r = runProcess(
      kArbci, {"run", "--headless", "--session", session, "--seed", "5", "--out", folder.string()},
      300.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;  // finished, not hung
  const nlohmann::json summary = readJson(folder / "summary.json");
  ASSERT_EQ(summary["trials"].size(), 2u);
  int wrong = 0;
  for (const auto& t : summary["trials"]) {
    wrong += t["selected_object"] != t["intended_object"];
    wrong += t["selected_cell"] != t["intended_cell"];
    EXPECT_GE(t["selected_object"].get<int>(), 0);  // every trial made its selections
  }
  EXPECT_GT(wrong, 0);
  EXPECT_NE(r.err.find("differs from the intended one; carrying on"), std::string::npos) << r.err;
  int logged_wrong = 0;
  for (const auto& line : readLog(folder / "log.jsonl"))
    logged_wrong += line["event"] == "selection" && line["correct"] == false;
  EXPECT_EQ(logged_wrong, wrong);
}

// A short headless session in `folder` (seed 3): a clear responder (as steady_head.json), a
// still head, a quick calibration, one trial per `intended` item (a JSON array of {object, cell});
// `more` adds top-level keys (", \"robot\": {...}").
ProcessResult runQuickSession(const std::filesystem::path& folder, const std::string& intended,
                              const std::string& more = "") {
  const std::string session = folder.string() + ".json";
  const nlohmann::json trials = nlohmann::json::parse(intended);
  std::ofstream(session) << R"({"eeg": {"erp_scale": 2.0},
    "cameras": {"head_motion_m": 0.0, "head_motion_deg": 0.0},
    "paradigm": {"calibration_selections": 4, "calibration_sequences": 6, "sequences": 5,
      "certainty": 0, "cue_s": 0.5, "pause_s": 0.5, "result_s": 0.5, "trials": )"
                         << trials.size() << R"(, "intended": )" << trials.dump() << "}" << more
                         << "}";
  return runProcess(
      kArbci, {"run", "--headless", "--session", session, "--seed", "3", "--out", folder.string()},
      300.0);
}

// As the simulated arm comes down on the object, its fingertip lies over a corner of the object's
// marker (18 % of the side along both edges), and for the last half second its palm over the
// whole marker. The session keeps tracking the object through the fingertip: its pose grows old
// only under the palm (0.48 s of a 3.45 s descent at the default arm speed; 2.18 s with the
// occluded-corner pass switched off in the session file, tracker.passes.occluded_corners, which
// must reach the session's detector).
TEST(Session, TheGrippersFingertipOverTheGraspedObjectsMarkerDoesNotLoseIt) {
  const auto folder = fresh("fingertip");
  const ProcessResult r = runQuickSession(folder, R"([{"object": 30, "cell": [2, 2]}])");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json summary = readJson(folder / "summary.json");
  ASSERT_EQ(summary["trials"].size(), 1u);
  const nlohmann::json& robot = summary["trials"][0]["robot"];
  ASSERT_EQ(robot["object"], 30) << summary["trials"][0].dump();
  ASSERT_TRUE(robot["pose_age_max_s"].is_number()) << robot.dump();
  EXPECT_GE(robot["pose_age_max_s"].get<double>(), 0.0);
  EXPECT_LT(robot["pose_age_max_s"].get<double>(), 1.2);
  int views = 0;
  for (const auto& line : readLog(folder / "log.jsonl")) {
    if (line["event"] != "grasp_view") continue;
    ++views;
    EXPECT_EQ(line["object"], 30);
    EXPECT_GT(line["seconds"].get<double>(), 2.0);  // the whole descent was watched
  }
  EXPECT_EQ(views, 1);
  // The same with the occluded-corner pass switched off in the session file: the fingertip hides
  // the marker, and the setting reaches the session's detector.
  const auto without = fresh("fingertip-without-pass");
  const ProcessResult off =
      runQuickSession(without, R"([{"object": 30, "cell": [2, 2]}])",
                      R"(, "tracker": {"passes": {"occluded_corners": {"enabled": false}}})");
  ASSERT_EQ(off.exit_code, 0) << off.err;
  const nlohmann::json off_robot = readJson(without / "summary.json")["trials"][0]["robot"];
  ASSERT_TRUE(off_robot["pose_age_max_s"].is_number()) << off_robot.dump();
  EXPECT_GT(off_robot["pose_age_max_s"].get<double>(), 1.5);
}

TEST(Session, AnObjectIsNeverPutOnAnotherAndAMovedObjectIsGraspedWhereItNowStands) {
  const auto folder = fresh("taken");
  // The second intention is a cell already taken.
  const ProcessResult r = runQuickSession(folder,
                                          R"([{"object": 20, "cell": [2, 2]},
                                              {"object": 40, "cell": [2, 2]},
                                              {"object": 20, "cell": [1, 1]}])",
                                          R"(, "robot": {"speed_factor": 20})");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json summary = readJson(folder / "summary.json");
  ASSERT_EQ(summary["trials"].size(), 3u);
  for (const auto& t : summary["trials"]) {
    ASSERT_EQ(t["selected_object"], t["intended_object"]) << t.dump();
    ASSERT_EQ(t["selected_cell"], t["intended_cell"]) << t.dump();
  }
  EXPECT_EQ(summary["trials"][0]["outcome"], "placed");
  EXPECT_EQ(summary["trials"][1]["outcome"], "returned: cell 2,2 is taken by object 20");
  EXPECT_TRUE(summary["trials"][1]["placement_error_m"].is_null());
  // Object 20 was taken from where the robot had put it, and put down at its new cell.
  EXPECT_EQ(summary["trials"][2]["outcome"], "placed");
  EXPECT_LT(summary["trials"][2]["placement_error_m"].get<double>(), 0.01);
  std::vector<nlohmann::json> commands;
  for (const auto& line : readLog(folder / "log.jsonl")) {
    if (line["event"] == "robot_command") commands.push_back(line);
  }
  ASSERT_EQ(commands.size(), 9u);
  // Trial 2: object 40 goes back where it was grasped.
  const auto& grasp = commands[3];
  const auto& drop = commands[4];
  ASSERT_EQ(grasp["command"], "GRASP");
  ASSERT_EQ(drop["command"], "DROP");
  EXPECT_TRUE(drop["returning"].get<bool>());
  EXPECT_NEAR(drop["target"][0].get<double>(), grasp["target"][0].get<double>(), 1e-9);
  EXPECT_NEAR(drop["target"][1].get<double>(), grasp["target"][1].get<double>(), 1e-9);
  // Trial 3 grasps object 20 at cell 2,2 (0, 0.66), where trial 1 put it.
  const auto& regrasp = commands[6];
  ASSERT_EQ(regrasp["object"], 20);
  EXPECT_NEAR(regrasp["target"][0].get<double>(), 0.0, 0.005);
  EXPECT_NEAR(regrasp["target"][1].get<double>(), 0.66, 0.005);
}

TEST(Session, OnlyTheObjectsTheCamerasSeeFlash) {
  const auto folder = fresh("out_of_view");
  const auto session = folder.string() + ".json";
  // The four default objects and a fifth, 50, beside the robot where the cameras do not look.
  std::ofstream(session) << R"({"eeg": {"erp_scale": 2.0},
    "cameras": {"head_motion_m": 0.0, "head_motion_deg": 0.0},
    "world": {"objects": [
      {"id": 10, "position": [-0.27, 0.42, 0.06]}, {"id": 20, "position": [-0.09, 0.42, 0.06]},
      {"id": 30, "position": [0.09, 0.42, 0.06]}, {"id": 40, "position": [0.27, 0.42, 0.06]},
      {"id": 50, "position": [0.55, 0.15, 0.06]}]},
    "paradigm": {"calibration_selections": 4, "sequences": 8, "certainty": 0, "trials": 1,
      "intended": [{"object": 30, "cell": [2, 2]}]},
    "robot": {"speed_factor": 20}})";
  const ProcessResult r = runProcess(
      kArbci, {"run", "--headless", "--session", session, "--seed", "3", "--out", folder.string()},
      300.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<int> in_view;
  int calibration_targets = 0;
  for (const auto& line : readLog(folder / "log.jsonl")) {
    if (line["event"] == "objects_in_view") in_view = line["objects"].get<std::vector<int>>();
    if (line["event"] == "calibration_target") {
      EXPECT_NE(line["object"], 50);
      ++calibration_targets;
    }
  }
  EXPECT_EQ(in_view, (std::vector<int>{10, 20, 30, 40}));
  EXPECT_EQ(calibration_targets, 4);
  const nlohmann::json summary = readJson(folder / "summary.json");
  ASSERT_EQ(summary["trials"].size(), 1u);
  EXPECT_EQ(summary["trials"][0]["object_flashes"], 8 * 4);  // four objects a sequence, not five
  EXPECT_EQ(summary["trials"][0]["selected_object"], 30);
  EXPECT_EQ(summary["trials"][0]["outcome"], "placed");
  const bci::Recording recording = bci::readRecording(folder / "recording.bdf");
  for (const auto& stimulus : recording.stimuli) {
    EXPECT_TRUE(stimulus.code <= 4 || stimulus.code > 100) << stimulus.code;
  }
}

TEST(Session, KillingTheRobotBackendDuringAGraspIsReportedAndTheRecordingStaysIntact) {
  const auto folder = fresh("robot_fault");
  const auto session = folder.string() + ".json";
  std::ofstream(session) << R"({"cameras": {"head_motion_m": 0.0, "head_motion_deg": 0.0},
    "paradigm": {"calibration_selections": 4, "trials": 2}, "robot": {"speed_factor": 2}})";
  int out_pipe[2];
  ASSERT_EQ(pipe(out_pipe), 0);
  const pid_t child = fork();
  if (child == 0) {
    dup2(out_pipe[1], STDOUT_FILENO);
    dup2(out_pipe[1], STDERR_FILENO);
    close(out_pipe[0]);
    execl(kArbci.c_str(), kArbci.c_str(), "run", "--headless", "--session", session.c_str(),
          "--seed", "2", "--out", folder.c_str(), "--fault-wait", "5", nullptr);
    _exit(127);
  }
  close(out_pipe[1]);
  // Wait for the first GRASP, then kill the backend.
  bool killed = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(180);
  while (!killed && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    std::ifstream log(folder / "log.jsonl");
    std::stringstream text;
    text << log.rdbuf();
    if (text.str().find("\"command\":\"GRASP\"") == std::string::npos) continue;
    std::ifstream pid_file(folder / "robotd.pid");
    pid_t robotd = 0;
    ASSERT_TRUE(pid_file >> robotd);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // mid-motion
    ASSERT_EQ(kill(robotd, SIGKILL), 0);
    killed = true;
  }
  ASSERT_TRUE(killed) << "no grasp was commanded";
  std::string output;
  char buffer[4096];
  ssize_t n = 0;
  while ((n = read(out_pipe[0], buffer, sizeof buffer)) > 0)
    output.append(buffer, static_cast<size_t>(n));
  close(out_pipe[0]);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 3)
      << output;  // ended by the fault, after waiting for an experimenter
  bool fault_phase = false;
  for (const auto& line : readLog(folder / "log.jsonl")) {
    fault_phase |= line["event"] == "phase" &&
                   line["phase"].get<std::string>().find("robot fault") != std::string::npos;
  }
  EXPECT_TRUE(fault_phase);
  const nlohmann::json summary = readJson(folder / "summary.json");
  EXPECT_EQ(summary["ended"], "fault");
  EXPECT_NE(summary["end_reason"].get<std::string>().find("robot fault"), std::string::npos)
      << summary["end_reason"];
  EXPECT_NE(summary["trials"][0]["outcome"].get<std::string>().find("silent"), std::string::npos)
      << summary["trials"][0].dump();
  const bci::Recording recording = bci::readRecording(folder / "recording.bdf");
  EXPECT_NEAR(recording.seconds(), summary["duration_s"].get<double>(), 0.1);
  bool ended_note = false;
  for (const auto& a : recording.annotations)
    ended_note |= a.text.find("Session ended") != std::string::npos;
  EXPECT_TRUE(ended_note);
}

// Ctrl+C or a TERM ends a headless run like an abort: the summary is written, the recording
// closed, and the exit status says it did not finish.
TEST(Session, ATermSignalEndsAHeadlessRunWithItsSummarySaved) {
  const auto folder = fresh("term");
  const pid_t child = fork();
  if (child == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    dup2(null, STDOUT_FILENO);
    dup2(null, STDERR_FILENO);
    execl(kArbci.c_str(), kArbci.c_str(), "run", "--headless", "--session",
          (kSessions + "/steady_head.json").c_str(), "--out", folder.c_str(), nullptr);
    _exit(127);
  }
  // Once the recording has data, ask it to stop.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    std::error_code error;  // (file_size is -1 with an error: not there yet)
    const auto size = std::filesystem::file_size(folder / "recording.bdf", error);
    if (!error && size > 20000) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_EQ(kill(child, SIGTERM), 0);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by the signal instead of ending the session";
  EXPECT_EQ(WEXITSTATUS(status), 3);
  const nlohmann::json summary = readJson(folder / "summary.json");
  EXPECT_EQ(summary["ended"], "aborted");
  EXPECT_GT(bci::readRecording(folder / "recording.bdf").samples, 0);
}

// ErrP study end to end: a subject without P300 (so most selections are wrong) whose ErrPs are
// unmistakable (5 times the default's: the classifier is not what is tested here, the gating is;
// docs/errp.md has the default subject's numbers); the robot is only ever sent to the intended
// object and cell, every robot command comes
// after an ErrP verdict that accepted its selection, and the recording trains an ErrP classifier
// offline (arbci train --errp) into the session's model.
TEST(Session, WithErrPsTheRobotIsNeverSentToAWrongObjectOrCell) {
  const auto folder = fresh("errp");
  const auto session = folder.string() + ".json";
  std::ofstream(session) << R"({"eeg": {"erp_scale": 0.0, "errp_scale": 5.0},
    "cameras": {"head_motion_m": 0.0, "head_motion_deg": 0.0},
    "paradigm": {"calibration_selections": 4, "sequences": 3, "min_sequences": 3, "certainty": 0.0,
                 "trials": 2, "cue_s": 0.5, "pause_s": 0.5},
    "errp": {"enabled": true, "calibration_feedbacks": 60, "max_corrections": 8},
    "robot": {"speed_factor": 20}})";
  const ProcessResult r = runProcess(
      kArbci, {"run", "--headless", "--session", session, "--seed", "4", "--out", folder.string()},
      400.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json summary = readJson(folder / "summary.json");
  const nlohmann::json& errp = summary["errp"];
  ASSERT_TRUE(errp["classifier"].get<bool>()) << errp.dump();
  EXPECT_GE(errp["calibration_auc"].get<double>(), 0.85) << errp.dump();
  EXPECT_GT(errp["wrong_selections"].get<int>(), 0) << errp.dump();  // the P300 guessed wrong
  // The default ErrP classifier: latency-tolerant LDA on one xDAWN filter of the montage.
  const nlohmann::json model = readJson(folder / "model.json");
  EXPECT_EQ(model["errp"]["method"], "shift-lda");
  EXPECT_EQ(model["errp"]["classifier"]["spatial_filters"], 1);
  EXPECT_EQ(model["errp"]["classifier"]["shift_ms"], 94.0);
  EXPECT_EQ(model["errp"]["pipeline"]["channels"].size(), 8u) << model["errp"]["pipeline"].dump();
  EXPECT_EQ(errp["wrong_caught"], errp["wrong_selections"]) << errp.dump();

  std::map<int, nlohmann::json> intended;  // by trial
  for (const auto& t : summary["trials"]) intended[t["trial"].get<int>()] = t;
  int trial = 0, grasps = 0;
  bool accepted = false;  // the last ErrP verdict accepted the selection shown
  for (const auto& line : readLog(folder / "log.jsonl")) {
    if (line["event"] == "phase") trial = line["trial"].get<int>();
    if (line["event"] == "errp_decision") accepted = !line["veto"].get<bool>();
    if (line["event"] != "robot_command") continue;
    if (line["command"] == "GRASP") {
      ++grasps;
      EXPECT_TRUE(accepted) << line.dump();
      EXPECT_EQ(line["object"], intended[trial]["intended_object"]) << line.dump();
      accepted = false;
    } else if (line["command"] == "DROP" && !line["returning"].get<bool>()) {
      EXPECT_TRUE(accepted) << line.dump();
      EXPECT_EQ(line["cell"], intended[trial]["intended_cell"]) << line.dump();
      accepted = false;
    }
  }
  EXPECT_GT(grasps, 0);

  // The summary tells what the robot did, trial by trial: where it was sent (the session's
  // commands), how many of those motions went wrong, and as many motions as the robot's own log
  // says it ran. A selection the ErrP rejected is listed as vetoed, never as the one selected.
  // The session's commands by sequence number, with the trial each was sent in.
  struct Sent {
    nlohmann::json command;
    int trial = 0;
  };
  std::map<long, Sent> sent;
  trial = 0;
  for (const auto& line : readLog(folder / "log.jsonl")) {
    if (line["event"] == "phase") trial = line["trial"].get<int>();
    if (line["event"] == "robot_command" && line.contains("sequence"))
      sent[line["sequence"].get<long>()] = {line, trial};
  }
  // What the robot's own log says it ran ("ran GRASP 4272 at (x, y, z)"), each run motion matched
  // to the command of that sequence and its trial's intention; a motion ran where it was sent.
  int logged_wrong = 0, grasp_trials = 0, drop_trials = 0;
  std::ifstream robot_log(folder / "robotd.log");
  for (std::string l; std::getline(robot_log, l);) {
    char kind[8] = {};
    long sequence = 0;
    double x = 0.0, y = 0.0, z = 0.0;
    const auto at = l.find(": ran ");
    if (at == std::string::npos || std::sscanf(l.c_str() + at, ": ran %7s %ld at (%lf, %lf, %lf)",
                                               kind, &sequence, &x, &y, &z) != 5)
      continue;
    ASSERT_TRUE(sent.count(sequence)) << l;
    const Sent& s = sent[sequence];
    if (s.command.contains("by")) continue;  // the experimenter's, not the BCI's
    EXPECT_EQ(s.command["command"], kind) << l;
    EXPECT_NEAR(s.command["target"][0].get<double>(), x, 1e-3) << l;
    EXPECT_NEAR(s.command["target"][1].get<double>(), y, 1e-3) << l;
    if (std::string(kind) == "GRASP")
      logged_wrong += s.command["object"] != intended[s.trial]["intended_object"];
    if (std::string(kind) == "DROP" && !s.command["returning"].get<bool>())
      logged_wrong += s.command["cell"] != intended[s.trial]["intended_cell"];
  }
  int vetoed = 0;
  for (const auto& t : summary["trials"]) {
    grasp_trials += !t["robot"]["object"].is_null();
    drop_trials += !t["robot"]["cell"].is_null() || t["robot"]["returned"].get<bool>();
    std::map<std::string, std::pair<int, int>> made;  // kind: selections, vetoed
    for (const auto& s : t["selections"]) {
      const bool veto = s["vetoed"].is_boolean() && s["vetoed"].get<bool>();
      ++made[s["kind"]].first;
      made[s["kind"]].second += veto;
      vetoed += veto;
    }
    for (const auto& [kind, counts] : made) {
      if (counts.first > 0 && counts.first == counts.second) {  // every one rejected
        EXPECT_TRUE(t["selected_" + kind].is_null()) << t.dump();
      }
    }
  }
  EXPECT_EQ(vetoed, errp["wrong_caught"].get<int>() + errp["correct_vetoed"].get<int>());
  EXPECT_EQ(summary["wrong_robot_actions"], logged_wrong) << summary["trials"].dump();
  std::ifstream robotd(folder / "robotd.log");
  int ran_grasps = 0, ran_drops = 0;
  for (std::string l; std::getline(robotd, l);) {
    ran_grasps += l.find(": ran GRASP ") != std::string::npos;
    ran_drops += l.find(": ran DROP ") != std::string::npos;
  }
  EXPECT_EQ(ran_grasps, grasp_trials);
  EXPECT_EQ(ran_drops, drop_trials);

  // The recording says what was shown and what the ErrP classifier decided.
  const bci::Recording recording = bci::readRecording(folder / "recording.bdf");
  int feedback = 0, wrong = 0, verdicts = 0;
  for (const auto& a : recording.annotations) {
    if (a.text.rfind("Feedback ", 0) == 0) {
      ++feedback;
      wrong += a.text.ends_with(" error");
    }
    verdicts += a.text.rfind("ErrP ", 0) == 0;
  }
  EXPECT_EQ(feedback, 60 + errp["decisions"].get<int>());
  EXPECT_EQ(wrong, 15 + errp["wrong_selections"].get<int>());
  EXPECT_EQ(verdicts, errp["decisions"].get<int>());

  // Offline: the same classifier from the recording, written into the session's P300 model.
  const ProcessResult train = runProcess(
      kArbci, {"train", "--errp", (folder / "recording.bdf").string(), "--method", "slda",
               "--channels", "Fz,Cz", "--p300-model", (folder / "model.json").string(), "--out",
               (folder / "both.json").string()});
  ASSERT_EQ(train.exit_code, 0) << train.err << train.out;
  EXPECT_NE(train.out.find("error and"), std::string::npos) << train.out;
  EXPECT_NE(train.out.find("errors caught"), std::string::npos) << train.out;
  // The report speaks of feedbacks, not of flashes.
  EXPECT_NE(train.out.find(" correct feedbacks)"), std::string::npos) << train.out;
  EXPECT_EQ(train.out.find("non-target flashes"), std::string::npos) << train.out;
  const nlohmann::json both = readJson(folder / "both.json");
  EXPECT_EQ(both["format"], "arbci-p300-model");
  EXPECT_EQ(both["errp"]["pipeline"]["channels"], (nlohmann::json{"Fz", "Cz"}));
  // Options not given take the session's ErrP defaults, and say so.
  const ProcessResult defaults =
      runProcess(kArbci, {"train", "--errp", (folder / "recording.bdf").string(), "--out",
                          (folder / "errp_defaults.json").string()});
  ASSERT_EQ(defaults.exit_code, 0) << defaults.err << defaults.out;
  EXPECT_NE(defaults.out.find("--method shift-lda --xdawn-filters 1 --window-ms 0,800"),
            std::string::npos)
      << defaults.out;
  EXPECT_EQ(readJson(folder / "errp_defaults.json")["method"], "shift-lda");
  // Where the feedbacks come from is said; --calibration-only takes the calibration block alone.
  const std::string online = "online " + std::to_string(errp["decisions"].get<int>()) +
                             " feedbacks (" + std::to_string(errp["wrong_selections"].get<int>()) +
                             " error";
  EXPECT_NE(defaults.out.find("calibration block 60 feedbacks (15 error, 45 correct), " + online),
            std::string::npos)
      << defaults.out;
  const ProcessResult calibration = runProcess(
      kArbci, {"train", "--errp", "--calibration-only", (folder / "recording.bdf").string(),
               "--out", (folder / "errp_calibration.json").string()});
  ASSERT_EQ(calibration.exit_code, 0) << calibration.err << calibration.out;
  EXPECT_NE(calibration.out.find(
                "training on 15 error and 45 correct feedbacks, the calibration block's"),
            std::string::npos)
      << calibration.out;
  EXPECT_NE(calibration.out.find("15 error and 45 correct feedbacks)"), std::string::npos)
      << calibration.out;
  // A recording without feedback events is refused with the reason.
  const ProcessResult none =
      runProcess(kArbci, {"train", "--errp", sharedData("eeg/bci2000_samplefiles/eeg3_1.dat"),
                          "--out", (folder / "none.json").string()});
  EXPECT_NE(none.exit_code, 0);
  EXPECT_NE(none.err.find("no feedback events"), std::string::npos) << none.err;
}

}  // namespace
}  // namespace arbci::test

// The simulated session end to end, headless, through the real executables: where the whole
// session is the point. The default world through three trials with given intentions (a
// calibration run, training, the robot grasping and putting down, every object within a
// centimetre), run twice with one seed (the same recording, byte for byte); the arm in the physics
// engine (6 axes, three trials; 7 axes, twice for reproducibility); and a TERM signal that
// ends a run with its summary saved, as does a disk that fills mid-run; and a session without a
// calibration run that learns from its trials. Every other behaviour of a
// session is tested at its own level: each stage on hand-built records (tests/session/stages), the
// panels on hand-built records (tests/ui), the application's parts in process (tests/app/unit).
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
#include "support/file_size_limit.h"
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

TEST(Session, ThreeTrialsPlacedWithinACentimetreOrSaidUnsureAndTheSameSeedTheSameRecording) {
  auto run = [](const std::string& name) {
    const auto folder = fresh(name);
    const ProcessResult r =
        runProcess(kArbci,
                   {"run", "--headless", "--session", kSessions + "/steady_head.json", "--seed",
                    "3", "--out", folder.string()},
                   600.0);
    EXPECT_EQ(r.exit_code, 0) << r.err << r.out;
    return folder;
  };
  const auto folder = run("e2e");
  const auto again = run("e2e_again");
  // Stepped on the session's clock, the EEG, the cameras and the arm give the same run: the
  // recording's data records (samples, every annotation and flash) byte for byte.
  EXPECT_TRUE(dataRecords(folder / "recording.bdf") == dataRecords(again / "recording.bdf"))
      << "the same seed gave different data records";
  EXPECT_EQ(stims(folder / "recording.bdf"), stims(again / "recording.bdf"));
  const nlohmann::json summary = readJson(folder / "summary.json");
  EXPECT_EQ(summary["ended"], "finished");
  ASSERT_EQ(summary["trials"].size(), 3u);
  // A simulated subject is sometimes misread. What is asserted is what the arm does with it: a
  // selection decided at least paradigm.act_certainty (0.9 here) probable is acted on and right,
  // one below it is said and not acted on (the object goes back where it was taken).
  for (const auto& e : readLog(folder / "log.jsonl")) {
    if (e.value("event", "") != "selection" || !e.contains("correct")) continue;
    if (e["certainty"].get<double>() >= 0.9) {
      EXPECT_TRUE(e["correct"].get<bool>()) << e.dump();
    }
  }
  int placed = 0;
  for (const auto& t : summary["trials"]) {
    EXPECT_EQ(t["selected_object"], t["intended_object"]) << t.dump();
    if (t["selected_cell"] != t["intended_cell"]) {
      EXPECT_EQ(t["outcome"].get<std::string>().rfind("returned: the cell was chosen at", 0), 0u)
          << t.dump();
      continue;
    }
    ASSERT_TRUE(t["placement_error_m"].is_number()) << t.dump();
    EXPECT_LT(t["placement_error_m"].get<double>(), 0.01) << t.dump();
    EXPECT_EQ(t["outcome"], "placed");
    ++placed;
  }
  EXPECT_GE(placed, 2);
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
  // The summary's timing is the recording's: the median SOA of consecutive flashes (closer than
  // a second, so within a selection) read back from the file.
  std::vector<double> soa_ms;
  for (size_t i = 1; i < recording.stimuli.size(); ++i) {
    const double gap =
        (recording.stimuli[i].sample - recording.stimuli[i - 1].sample) * 1000.0 / 256.0;
    if (gap < 1000.0) soa_ms.push_back(gap);
  }
  ASSERT_FALSE(soa_ms.empty());
  std::nth_element(soa_ms.begin(), soa_ms.begin() + soa_ms.size() / 2, soa_ms.end());
  EXPECT_NEAR(soa_ms[soa_ms.size() / 2], summary["timing"]["soa_ms"]["median"].get<double>(), 2.0)
      << summary["timing"].dump(2);
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

// Ctrl+C or a TERM ends a headless run like an abort: the summary is written, the recording
// closed, and the exit status says it did not finish.
// The placements of a run as log.jsonl has them: the cameras' view and the robot's report.
std::vector<nlohmann::json> placements(const std::filesystem::path& folder) {
  std::vector<nlohmann::json> out;
  for (const auto& line : readLog(folder / "log.jsonl"))
    if (line["event"] == "placement") out.push_back(line);
  return out;
}

// A run of the physics-arm session (tests/sessions/physics_arm.json) with `arm` and `trials`,
// its classifier given (a model the simulated subject's calibration trained, so no calibration
// run: what is checked is the arm). Returns the session folder.
std::filesystem::path physicsRun(const std::string& name, const std::string& arm, int trials) {
  const auto folder = fresh(name);
  // One settings file per arm: its path is in the recording, which two runs compare.
  const auto settings = std::filesystem::temp_directory_path() /
                        ("arbci_session_test_" + std::to_string(::getpid()) + "_" + arm + ".json");
  std::ifstream in(kSessions + "/physics_arm.json");
  nlohmann::json file = nlohmann::json::parse(in);
  file["robot"]["model"] = arm;
  file["classifier"]["model"] = kSessions + "/simulated_subject_model.json";
  // What is checked is the arm: it acts on every selection, however sure the classifier is.
  file["paradigm"]["act_certainty"] = 0.0;
  std::ofstream(settings) << file.dump();
  const ProcessResult r = runProcess(kArbci,
                                     {"run", "--headless", "--session", settings.string(),
                                      "--trials", std::to_string(trials), "--out", folder.string()},
                                     600.0);
  EXPECT_EQ(r.exit_code, 0) << r.err << r.out;
  return folder;
}

// Every trial placed within 10 mm of its cell as the tracker sees it, the arm's own report beside.
void expectPlacedAsTheCamerasSee(const std::filesystem::path& folder, size_t trials) {
  const nlohmann::json summary = readJson(folder / "summary.json");
  EXPECT_EQ(summary["ended"], "finished") << summary["end_reason"];
  ASSERT_EQ(summary["trials"].size(), trials);
  for (const auto& t : summary["trials"]) {
    EXPECT_EQ(t["outcome"], "placed") << t.dump();
    ASSERT_TRUE(t["placement_error_m"].is_number()) << t.dump();
    EXPECT_LT(t["placement_error_m"].get<double>(), 0.010) << t.dump();
  }
  const auto placed = placements(folder);
  ASSERT_EQ(placed.size(), trials);
  for (const auto& p : placed) {
    EXPECT_TRUE(p["error_m"].is_number()) << p.dump();
    EXPECT_TRUE(p.contains("robot_reported")) << p.dump();
  }
}

// The arm in the physics engine (robot.driver mujoco): three of three objects placed, each within
// 10 mm of its cell as the tracker sees it.
TEST(Session, ThePhysicsArmPlacesThreeOfThreeAsTheCamerasSee) {
  expectPlacedAsTheCamerasSee(physicsRun("physics", "arm6", 3), 3);
}

// The project's second arm (7 axes, robot.model arm7) runs the session too, and the same seed
// gives the same run again: the recording's data records and the placements.
TEST(Session, TheSevenAxisPhysicsArmPlacesAndTheSameSeedGivesTheSameRun) {
  const auto folder = physicsRun("physics_arm7", "arm7", 1);
  const auto again = physicsRun("physics_arm7_again", "arm7", 1);
  expectPlacedAsTheCamerasSee(folder, 1);
  EXPECT_TRUE(dataRecords(folder / "recording.bdf") == dataRecords(again / "recording.bdf"))
      << "the same seed gave different data records";
  EXPECT_EQ(placements(folder), placements(again));
}

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

// A disk that fills mid-run (a file-size limit on the process fails its writes as a full disk
// does): the run ends as a fault with the file and the system's reason on the terminal and in
// the summary, every sample written before it reads back, screenshots that could not be written
// are counted, and the process exits, never aborts.
TEST(Session, ADiskThatFillsMidRunEndsItWithTheReasonAndKeepsTheRecording) {
  const auto folder = fresh("full_disk");
  const auto out = fresh("full_disk_terminal.txt");
  const pid_t child = fork();
  if (child == 0) {
    const int terminal = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(terminal, STDOUT_FILENO);
    dup2(terminal, STDERR_FILENO);
    const FileSizeLimit limit(120 * 1024);  // kept across exec (SIGXFSZ ignored with it)
    execl(kArbci.c_str(), kArbci.c_str(), "run", "--headless", "--session",
          (kSessions + "/steady_head.json").c_str(), "--out", folder.c_str(), nullptr);
    _exit(127);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  std::ifstream in(out);
  const std::string terminal((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
  ASSERT_TRUE(WIFEXITED(status)) << terminal;
  EXPECT_EQ(WEXITSTATUS(status), 3) << terminal;
  EXPECT_NE(terminal.find("ended: fault (the recording failed: " +
                          (folder / "recording.bdf").string() + ": write failed: File too large"),
            std::string::npos)
      << terminal;
  const nlohmann::json summary = readJson(folder / "summary.json");
  EXPECT_EQ(summary["ended"], "fault");
  EXPECT_NE(summary["eeg"]["recording_error"].get<std::string>().find("write failed"),
            std::string::npos);
  EXPECT_GT(summary["screenshots"]["failed"].get<int>(), 0);
  const bci::Recording recording = bci::readRecording(folder / "recording.bdf");
  EXPECT_GT(recording.samples, 256 * 5);
}

// No calibration run (paradigm.calibration none): the session starts at the trials, learns the
// P300 from them without labels, and sends the arm only once the model is trusted; the log and
// the summary keep each selection's online decision and the post-hoc one of the last fit.
TEST(Session, WithoutACalibrationRunItLearnsFromItsTrialsAndHoldsTheArmUntilTrusted) {
  const auto folder = fresh("learning");
  const auto settings = fresh("learning.json");
  std::ifstream in(kSessions + "/steady_head.json");
  nlohmann::json file = nlohmann::json::parse(in);
  file["paradigm"]["calibration"] = "none";
  // Enough trials for the model to be trusted (five selections learnt from) and the arm to go.
  constexpr int kTrials = 7;
  file["paradigm"]["trials"] = kTrials;
  std::ofstream(settings) << file.dump();
  const ProcessResult r = runProcess(
      kArbci, {"run", "--headless", "--session", settings.string(), "--out", folder.string()},
      600.0);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  const nlohmann::json summary = readJson(folder / "summary.json");
  EXPECT_EQ(summary["ended"], "finished");
  EXPECT_FALSE(summary.contains("calibration") && summary["calibration"].contains("auc"))
      << summary["calibration"].dump();  // no calibration run was trained
  const nlohmann::json& learning = summary["learning"];
  ASSERT_TRUE(learning.is_object()) << summary.dump();
  EXPECT_EQ(learning["mode"], "none");
  // The first selections have no model to decide with; every one is decoded post hoc (the last
  // fit is made as the run ends).
  const int made = learning["object_selections"].get<int>();
  EXPECT_GE(made, kTrials - 3);
  EXPECT_LT(made, kTrials);
  EXPECT_EQ(learning["post_hoc"]["decoded"], kTrials);
  ASSERT_EQ(summary["trials"].size(), static_cast<size_t>(kTrials));
  int held = 0;
  for (const auto& t : summary["trials"]) {
    // The arm went nowhere in a held trial (the first: no model to trust yet; a later one may be
    // held for its own decision, each outcome saying why), and only after the model was first
    // trusted.
    if (t["arm_held"].get<bool>()) {
      ++held;
      EXPECT_TRUE(t["robot"]["object"].is_null()) << t.dump();
      const std::string outcome = t["outcome"];
      if (t["trial"] == 1) {
        EXPECT_EQ(outcome, "learning: the model is not yet trusted, so the arm was not sent");
      }
      EXPECT_TRUE(outcome.starts_with("learning: ") && outcome.ends_with("the arm was not sent"))
          << outcome;
    } else {
      ASSERT_TRUE(learning["first_trusted_trial"].is_number()) << learning.dump();
      EXPECT_GE(t["trial"].get<int>(), learning["first_trusted_trial"].get<int>()) << t.dump();
    }
    EXPECT_TRUE(t["post_hoc_object"].is_number()) << t.dump();
  }
  EXPECT_EQ(learning["trials_arm_held"], held);
  // learning_min_selections: no arm before five selections are learnt from (the fifth's own fit
  // may send it).
  EXPECT_GE(held, 4);
  // A fit after each selection, off the cycle's thread, logged with its measures of trust.
  int fits = 0;
  for (const auto& line : readLog(folder / "log.jsonl")) {
    if (line["event"] != "learning_fit") continue;
    ++fits;
    EXPECT_TRUE(line.contains("consistency") && line.contains("beats_shuffled") &&
                line.contains("post_hoc") && line.contains("trusted"))
        << line.dump();
  }
  EXPECT_GE(fits, 4);
}

}  // namespace
}  // namespace arbci::test

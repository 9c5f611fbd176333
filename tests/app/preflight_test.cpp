// The pre-flight check before any flash, through the real executable headless: a camera whose
// video does not show the reference marker, and a remote robot that never answers, each end the
// run before the calibration run starts (exit 3), naming the session file's key; the default
// simulated session passes it. Tracking lost once the run is on: every object out of view, and a
// marker covered during the calibration run (its selection retaken).
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "arbci/bci/recording.h"
#include "support/run_process.h"
#include "support/test_files.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;

std::vector<nlohmann::json> logOf(const std::filesystem::path& folder) {
  std::vector<nlohmann::json> out;
  std::ifstream in(folder / "log.jsonl");
  std::string line;
  while (std::getline(in, line)) out.push_back(nlohmann::json::parse(line));
  return out;
}

// Nothing of the paradigm ran: no phase, no flash, no stimulus in the recording's log.
void expectNoFlash(const std::filesystem::path& folder) {
  for (const nlohmann::json& e : logOf(folder)) {
    EXPECT_NE(e["event"], "phase") << e.dump();
    EXPECT_NE(e["event"], "calibration_target") << e.dump();
  }
  const nlohmann::json summary = readJson(folder / "summary.json");
  EXPECT_EQ(summary["ended"], "aborted");
  EXPECT_NE(summary["end_reason"].get<std::string>().find("pre-flight failed"), std::string::npos);
}

// A session whose left camera is `video`, with a pinhole calibration for its frame size.
std::filesystem::path videoSession(const std::filesystem::path& folder,
                                   const std::filesystem::path& video, cv::Size size) {
  const auto calibration_file = folder / "camera.yml";
  cv::FileStorage calibration(calibration_file.string(), cv::FileStorage::WRITE);
  calibration << "image_width" << size.width << "image_height" << size.height;
  const double f = 1.25 * size.width;
  calibration << "camera_matrix"
              << cv::Mat(cv::Matx33d(f, 0, size.width / 2.0, 0, f, size.height / 2.0, 0, 0, 1));
  calibration << "distortion_coefficients" << cv::Mat(cv::Vec<double, 5>(0, 0, 0, 0, 0));
  const auto session = folder / "session.json";
  std::ofstream(session) << nlohmann::json{{"cameras",
                                            {{"source", "devices"},
                                             {"left",
                                              {{"video", video.string()},
                                               {"calibration", calibration_file.string()}}}}}}
                                .dump();
  return session;
}

TEST(Preflight, AVideoWithoutTheReferenceMarkerEndsTheRunBeforeAnyFlashNamingTheKey) {
  const auto folder = freshTempPath("preflight_test", "no_reference");
  std::filesystem::create_directories(folder);
  // A real ARToolKitPlus sample (marker 100, not the reference 0), as a 20 frames/s video.
  const cv::Mat image = cv::imread(std::string(ARBCI_SHARED_DATA_DIR) +
                                       "/vision/artoolkitplus_samples/"
                                       "image_320_240_8_marker_id_bch_nr0100.jpg",
                                   cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  const auto video = folder / "camera.avi";
  {
    cv::VideoWriter writer(video.string(), cv::CAP_OPENCV_MJPEG,
                           cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 20.0, image.size());
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < 200; ++i) writer.write(image);
  }
  const auto session = videoSession(folder, video, {320, 240});
  const auto out = folder / "out";
  const ProcessResult r = runProcess(
      kArbci, {"run", "--headless", "--session", session.string(), "--out", out.string()}, 120.0);
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("pre-flight failed: world.reference.id: the reference marker 0 was not "
                       "seen"),
            std::string::npos)
      << r.err;
  expectNoFlash(out);
}

// Every object out of the cameras' view once the session runs: no flash can be shown, so the
// selection can never be scored. Headless, the run ends after paradigm.no_view_pause_s (here 4 s
// of flashes all withheld) with the reason, instead of waiting out the hour.
TEST(NoObjectInView, AHeadlessRunEndsWithTheReasonAfterTheSetting) {
  const auto folder = freshTempPath("preflight_test", "no_object_in_view");
  std::filesystem::create_directories(folder);
  const ProcessResult settings = runProcess(kArbci, {"settings"});
  ASSERT_EQ(settings.exit_code, 0) << settings.err;
  nlohmann::json objects = nlohmann::json::parse(settings.out)["world"]["objects"];
  for (auto& o : objects) {
    o["position"][0] = o["position"][0].get<double>() + 3.0;  // 3 m off to the side
    o["position"][1] = o["position"][1].get<double>() + 3.0;
  }
  const auto session = folder / "session.json";
  std::ofstream(session) << nlohmann::json{{"world", {{"objects", objects}}},
                                           {"paradigm", {{"no_view_pause_s", 4}}}}
                                .dump();
  const auto out = folder / "out";
  const ProcessResult r = runProcess(
      kArbci, {"run", "--headless", "--session", session.string(), "--out", out.string()}, 300.0);
  EXPECT_EQ(r.exit_code, 3) << r.err;
  const nlohmann::json summary = readJson(out / "summary.json");
  EXPECT_EQ(summary["ended"], "aborted");
  const std::string reason = summary["end_reason"];
  EXPECT_EQ(reason.rfind("no object in view: the reference marker or objects (10, 20, 30, 40) "
                         "lost for 4 s (paradigm.no_view_pause_s)",
                         0),
            0u)
      << reason;
  EXPECT_LT(summary["duration_s"].get<double>(), 60.0);  // session time, not the wall clock
  bool logged = false;
  for (const nlohmann::json& e : logOf(out))
    logged |= e["event"] == "paused" && e["reason"].get<std::string>() == reason;
  EXPECT_TRUE(logged);
}

// The session's defaults with a hand over object 40's marker at `covered_s` (session seconds),
// a short calibration run and one trial.
std::filesystem::path coveredSession(const std::filesystem::path& folder,
                                     const std::vector<double>& covered_s, double pause_s) {
  std::filesystem::create_directories(folder);
  const ProcessResult settings = runProcess(kArbci, {"settings"});
  EXPECT_EQ(settings.exit_code, 0) << settings.err;
  nlohmann::json objects = nlohmann::json::parse(settings.out)["world"]["objects"];
  for (auto& o : objects)
    if (o["id"] == 40) o["covered_s"] = covered_s;
  const auto session = folder / "session.json";
  std::ofstream(session) << nlohmann::json{
      {"world", {{"objects", objects}}},
      {"paradigm",
       {{"calibration_selections", 4},
        {"trials", 1},
        {"no_view_pause_s", pause_s},
        {"intended", {{{"object", 20}, {"cell", {1, 3}}}}}}},
      {"robot",
       {{"speed_factor", 20}}}}.dump();
  return session;
}

// A hand over one marker for 3 s during the calibration run (longer than a cue and its pause, so
// it always meets flashes, and late enough for the run to have started): the selection it cuts
// is paused, retaken with the same target once the marker is seen again, and left out of
// training, which reports the selections it used; the run still trains on 4 whole selections.
TEST(TrackingLoss, ACalibrationSelectionCutByACoveredMarkerIsRetakenAndLeftOutOfTraining) {
  const auto folder = freshTempPath("preflight_test", "covered_in_calibration");
  const auto session = coveredSession(folder, {20.0, 23.0}, 10.0);
  const auto out = folder / "out";
  const ProcessResult r = runProcess(
      kArbci, {"run", "--headless", "--session", session.string(), "--out", out.string()}, 600.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json summary = readJson(out / "summary.json");
  EXPECT_EQ(summary["ended"], "finished");
  const nlohmann::json& calibration = summary["calibration"];
  ASSERT_EQ(calibration["retaken"].size(), 1u) << calibration.dump();
  const nlohmann::json& retake = calibration["retaken"][0];
  EXPECT_EQ(retake["reason"], "tracking lost: object 40");
  const int cut = retake["selection"].get<int>();
  EXPECT_EQ(retake["retaken_as"].get<int>(), cut + 1);
  EXPECT_EQ(calibration["selections"], 4);
  const auto used = calibration["selections_used"].get<std::vector<int>>();
  EXPECT_EQ(used.size(), 4u);
  EXPECT_EQ(std::count(used.begin(), used.end(), cut), 0);
  EXPECT_EQ(std::count(used.begin(), used.end(), cut + 1), 1);
  // The retake cues the same object; the log says why it paused, and training what it used.
  std::map<int, int> targets;  // selection number: its cued object
  int selection = 0;
  bool paused = false, trained = false;
  for (const nlohmann::json& e : logOf(out)) {
    if (e["event"] == "calibration_target") targets[++selection] = e["object"].get<int>();
    if (e["event"] == "paused")
      paused |=
          e["reason"].get<std::string>().find("object 40's flash withheld") != std::string::npos;
    if (e["event"] == "trained")
      trained = e["selections_used"].get<std::vector<int>>() == used &&
                e["selections_left_out"] == nlohmann::json{cut};
  }
  EXPECT_TRUE(paused);
  EXPECT_TRUE(trained);
  EXPECT_EQ(targets.at(cut), targets.at(cut + 1));
  EXPECT_EQ(targets.size(), 5u);
  // The recording keeps the interrupted flashes, and says they were left out.
  bool annotated = false;
  for (const auto& a : bci::readRecording(out / "recording.bdf").annotations)
    annotated |=
        a.text.rfind("Calibration selection " + std::to_string(cut) + " interrupted", 0) == 0;
  EXPECT_TRUE(annotated);
  // Trained offline from the recording, the interrupted flashes are left out there too.
  const ProcessResult train = runProcess(
      kArbci,
      {"train", (out / "recording.bdf").string(), "--out", (folder / "model.json").string()},
      300.0);
  ASSERT_EQ(train.exit_code, 0) << train.err;
  EXPECT_NE(train.out.find("flashes of calibration selections the session interrupted and retook "
                           "left out"),
            std::string::npos)
      << train.out;
}

// The marker stays covered: headless, nobody can uncover it, so the run ends with the reason
// after paradigm.no_view_pause_s.
TEST(TrackingLoss, AMarkerCoveredForGoodInCalibrationEndsAHeadlessRunWithTheReason) {
  const auto folder = freshTempPath("preflight_test", "covered_for_good");
  const auto session = coveredSession(folder, {20.0, 1e6}, 4.0);
  const auto out = folder / "out";
  const ProcessResult r = runProcess(
      kArbci, {"run", "--headless", "--session", session.string(), "--out", out.string()}, 600.0);
  EXPECT_EQ(r.exit_code, 3) << r.err;
  const nlohmann::json summary = readJson(out / "summary.json");
  EXPECT_EQ(summary["ended"], "aborted");
  EXPECT_EQ(summary["end_reason"],
            "tracking lost: the reference marker or objects (40) lost for 4 s "
            "(paradigm.no_view_pause_s), during calibration");
}

// A file that is not a video at all is refused as the camera opens, before the session starts.
TEST(Preflight, ACameraPointingAtANonVideoFileExitsBeforeAnyFlashNamingTheKey) {
  const auto folder = freshTempPath("preflight_test", "not_a_video");
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "camera.mp4") << "this is not a video\n";
  const auto session = videoSession(folder, folder / "camera.mp4", {640, 480});
  const auto out = folder / "out";
  const ProcessResult r = runProcess(
      kArbci, {"run", "--headless", "--session", session.string(), "--out", out.string()}, 120.0);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("cameras.left.video: cannot open video"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out / "recording.bdf"));  // nothing recorded, no flash
}

TEST(Preflight, ARemoteRobotThatNeverAnswersEndsTheRunBeforeAnyFlashNamingTheKey) {
  const auto folder = freshTempPath("preflight_test", "silent_robot");
  std::filesystem::create_directories(folder);
  // A UDP port on 127.0.0.1 that takes the datagrams and never answers.
  const int silent = ::socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(silent, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(silent, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  socklen_t length = sizeof address;
  ::getsockname(silent, reinterpret_cast<sockaddr*>(&address), &length);
  const int port = ntohs(address.sin_port);
  const auto key = folder / "robot.key";
  ASSERT_EQ(runProcess(kArbci, {"robot", "keygen", "--out", key.string()}).exit_code, 0);
  const auto session = folder / "session.json";
  std::ofstream(session) << nlohmann::json{{"robot",
                                            {{"backend", "remote"},
                                             {"host", "127.0.0.1"},
                                             {"port", port},
                                             {"key_file", key.string()}}}}
                                .dump();
  const auto out = folder / "out";
  const ProcessResult r = runProcess(
      kArbci, {"run", "--headless", "--session", session.string(), "--out", out.string()}, 120.0);
  ::close(silent);
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("pre-flight failed: robot.host, robot.port: the robot backend at "
                       "127.0.0.1:" +
                       std::to_string(port) + " did not answer STATUS in"),
            std::string::npos)
      << r.err;
  // Only the robot failed: the simulated cameras, the reference and the EEG passed.
  EXPECT_EQ(r.err.find("pre-flight failed: world"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("pre-flight failed: eeg"), std::string::npos) << r.err;
  expectNoFlash(out);
}

}  // namespace
}  // namespace arbci::test

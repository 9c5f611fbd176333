// The one camera and video reader (support/frame_source) through both of its users: `arbci detect
// --video` reads every frame in order, a session's CameraCapture plays the file at its own rate
// on a thread. The video is written here with OpenCV's built-in MJPEG writer from a real
// ARToolKitPlus sample image (marker 100).
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>
#include <thread>

#include "arbci/session/camera_capture.h"
#include "support/run_process.h"
#include "support/test_files.h"

namespace arbci::test {
namespace {

const std::string kSample =
    std::string(ARBCI_SHARED_DATA_DIR) +
    "/vision/artoolkitplus_samples/image_320_240_8_marker_id_bch_nr0100.jpg";

// Twenty frames of the sample at 20 frames a second.
std::filesystem::path sampleVideo() {
  const auto path = freshTempPath("camera_capture_test", "marker100.avi");
  const cv::Mat image = cv::imread(kSample, cv::IMREAD_COLOR);
  EXPECT_FALSE(image.empty()) << kSample;
  cv::VideoWriter writer(path.string(), cv::CAP_OPENCV_MJPEG,
                         cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 20.0, image.size());
  EXPECT_TRUE(writer.isOpened());
  for (int i = 0; i < 20; ++i) writer.write(image);
  return path;
}

TEST(CameraReader, DetectReadsEveryFrameOfAVideoInOrder) {
  const auto video = sampleVideo();
  const ProcessResult r = runProcess(ARBCI_EXECUTABLE, {"detect", "--video", video.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream lines(r.out);
  int frames = 0, found = 0;
  for (std::string line; std::getline(lines, line);) {
    const nlohmann::json frame = nlohmann::json::parse(line);
    EXPECT_EQ(frame["frame"], std::to_string(frames));
    for (const auto& marker : frame["markers"]) found += marker["id"] == 100 ? 1 : 0;
    ++frames;
  }
  EXPECT_EQ(frames, 20);
  EXPECT_EQ(found, 20);
}

TEST(CameraReader, ASessionsCaptureThreadPlaysTheFileAtItsOwnRate) {
  const auto video = sampleVideo();
  const auto start = std::chrono::steady_clock::now();
  session::CameraCapture capture(-1, video.string(), "cameras.left");
  while (!capture.finished() && std::chrono::steady_clock::now() - start < std::chrono::seconds(60))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const double took =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(capture.finished());
  const auto [frame, count] = capture.latest();
  EXPECT_EQ(count, 20u);
  EXPECT_EQ(frame.size(), cv::Size(320, 240));
  // 20 frames at 20 per second: paced, not read at once (load only makes it slower). That it
  // finished at all is asserted above; how fast is not this test's to judge.
  EXPECT_GT(took, 0.9);
  try {
    session::CameraCapture missing(-1, "/nonexistent/video.avi", "cameras.left");
    FAIL() << "a missing video must be refused";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("cameras.left: cannot open video"), std::string::npos)
        << error.what();
  }
}

// A file that is not a video at all is refused as the camera opens, naming the session file's key
// (the session then ends before it starts: no flash, nothing recorded).
TEST(CameraReader, AFileThatIsNotAVideoIsRefusedNamingTheKey) {
  const auto file = freshTempPath("camera_capture_test", "camera.mp4");
  std::ofstream(file) << "this is not a video\n";
  try {
    session::CameraCapture capture(-1, file.string(), "cameras.left.video");
    FAIL() << "a file that is not a video was opened";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("cameras.left.video: cannot open video"),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace arbci::test

// `arbci detect` and `arbci marker`: one JSON line per frame in the documented form, errors on
// stderr without stopping, printable markers that detect as their ids.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "support/run_process.h"
#include "support/shared_data.h"
#include "support/test_files.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;

const std::string kScratch = "arbci_marker_cli_test";

std::vector<nlohmann::json> jsonLines(const std::string& text) {
  std::vector<nlohmann::json> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

TEST(DetectCommand, PrintsOneJsonObjectPerFrameWithMarkersAndStageTimes) {
  const std::string samples = sharedData("vision/artoolkitplus_samples/");
  const ProcessResult result = runProcess(
      kArbci, {"detect", "--kind", "simple", "--border", "0.25", "--threshold", "150", "--raw",
               "320x240", "--repeat", "3", samples + "image_320_240_8_marker_id_simple_nr031.raw",
               samples + "image_320_240_8_marker_id_simple_nr321.raw"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto lines = jsonLines(result.out);
  ASSERT_EQ(lines.size(), 2u);
  const int expected_ids[] = {31, 321};
  for (size_t i = 0; i < 2; ++i) {
    const nlohmann::json& frame = lines[i];
    EXPECT_EQ(frame["width"], 320);
    EXPECT_EQ(frame["height"], 240);
    EXPECT_EQ(frame["threshold"], 150);
    ASSERT_EQ(frame["markers"].size(), 1u);
    const nlohmann::json& marker = frame["markers"][0];
    EXPECT_EQ(marker["id"], expected_ids[i]);
    EXPECT_EQ(marker["kind"], "simple");
    ASSERT_EQ(marker["corners"].size(), 4u);
    EXPECT_GT(marker["confidence"].get<double>(), 0.9);
    // Every stage, and (--repeat reports one whole run, the median's) they add up to the total.
    double parts = 0.0;
    for (const char* stage : {"convert", "smooth", "threshold", "label", "quads", "retry", "edges",
                              "refine", "decode", "other"}) {
      ASSERT_TRUE(frame["timing_us"].contains(stage)) << stage;
      parts += frame["timing_us"][stage].get<double>();
    }
    const double total = frame["timing_us"]["total"].get<double>();
    EXPECT_GT(total, 0.0);
    EXPECT_NEAR(parts, total, 1.0) << frame["timing_us"].dump();  // each rounded to 0.1 us
  }
  // nr031's printed top-left corner comes first.
  EXPECT_NEAR(lines[0]["markers"][0]["corners"][0][0].get<double>(), 215.9, 1.0);
  EXPECT_NEAR(lines[0]["markers"][0]["corners"][0][1].get<double>(), 148.4, 1.0);
}

TEST(DetectCommand, ReportsUnreadableInputsAndGoesOn) {
  const auto corrupt = scratchPath(kScratch, "corrupt.png");
  std::ofstream(corrupt) << "not a png";
  const auto short_raw = scratchPath(kScratch, "short.raw");
  std::ofstream(short_raw) << "too short";
  const ProcessResult result =
      runProcess(kArbci, {"detect", "/nonexistent/frame.png", corrupt.string(),
                          sharedData("vision/opencv_contrib_aruco_tutorial/board.png")});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_EQ(jsonLines(result.out).size(), 1u) << "the readable frame is still processed";
  EXPECT_NE(result.err.find("/nonexistent/frame.png"), std::string::npos);
  EXPECT_NE(result.err.find("corrupt.png"), std::string::npos);
  const ProcessResult raw = runProcess(kArbci, {"detect", "--raw", "320x240", short_raw.string()});
  EXPECT_EQ(raw.exit_code, 1);
  EXPECT_NE(raw.err.find("76800 bytes"), std::string::npos) << raw.err;
  const ProcessResult bad = runProcess(kArbci, {"detect", "--threshold", "300", corrupt.string()});
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.err.find("--threshold"), std::string::npos) << bad.err;
}

TEST(DetectCommand, DictionaryKindsAndAnnotation) {
  const auto folder = scratchPath(kScratch, "annotated");
  std::filesystem::remove_all(folder);
  const ProcessResult result = runProcess(
      kArbci, {"detect", "--kind", "aruco", "--annotate", folder.string(),
               sharedData("vision/opencv_contrib_aruco_tutorial/singlemarkersoriginal.jpg")});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(jsonLines(result.out)[0]["markers"].size(), 6u);
  const cv::Mat annotated = cv::imread((folder / "singlemarkersoriginal.png").string());
  EXPECT_EQ(annotated.cols, 640);
}

TEST(MarkerCommand, WritesPrintScaleMarkersThatDetectAsTheirIds) {
  const auto base = scratchPath(kScratch, "bch_0042");
  const ProcessResult make = runProcess(kArbci, {"marker", "make", "--kind", "bch", "--id", "42",
                                                 "--size-mm", "50", "--out", base.string()});
  ASSERT_EQ(make.exit_code, 0) << make.err;
  const cv::Mat png = cv::imread(base.string() + ".png", cv::IMREAD_GRAYSCALE);
  // 50 mm + two 6.25 mm quiet zones at 300 dpi.
  EXPECT_NEAR(png.cols, (50.0 + 2 * 6.25) / 25.4 * 300, 1.0);
  std::ifstream svg(base.string() + ".svg");
  const std::string text((std::istreambuf_iterator<char>(svg)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("width=\"62.5mm\""), std::string::npos);
  const ProcessResult detect = runProcess(kArbci, {"detect", base.string() + ".png"});
  ASSERT_EQ(detect.exit_code, 0) << detect.err;
  const auto markers = jsonLines(detect.out)[0]["markers"];
  ASSERT_EQ(markers.size(), 1u);
  EXPECT_EQ(markers[0]["id"], 42);
}

// marker make's defaults, then marker train's: the pattern trains (at the border the marker was
// printed with, which it says) and finds the marker again as a template; a simple marker is
// printed with the border detect --kind simple expects.
TEST(MarkerCommand, APatternTrainsFromAMarkerMadeWithTheDefaults) {
  const auto base = scratchPath(kScratch, "made_default");
  ASSERT_EQ(runProcess(kArbci, {"marker", "make", "--id", "9", "--out", base.string()}).exit_code,
            0);
  const auto pattern = scratchPath(kScratch, "made_default.patt");
  const ProcessResult train = runProcess(
      kArbci, {"marker", "train", "--image", base.string() + ".png", "--out", pattern.string()});
  ASSERT_EQ(train.exit_code, 0) << train.err;
  EXPECT_NE(train.err.find("--border 0.125"), std::string::npos) << train.err;
  const ProcessResult found =
      runProcess(kArbci, {"detect", "--kind", "template", "--border", "0.125", "--pattern",
                          "9=" + pattern.string(), base.string() + ".png"});  // not swallowed
  ASSERT_EQ(found.exit_code, 0) << found.err;
  const auto markers = jsonLines(found.out)[0]["markers"];
  ASSERT_EQ(markers.size(), 1u);
  EXPECT_EQ(markers[0]["id"], 9);

  const auto simple = scratchPath(kScratch, "simple_default");
  ASSERT_EQ(runProcess(kArbci, {"marker", "make", "--kind", "simple", "--id", "77", "--out",
                                simple.string()})
                .exit_code,
            0);
  const ProcessResult read =
      runProcess(kArbci, {"detect", "--kind", "simple", simple.string() + ".png"});
  ASSERT_EQ(read.exit_code, 0) << read.err;
  const auto simple_markers = jsonLines(read.out)[0]["markers"];
  ASSERT_EQ(simple_markers.size(), 1u);
  EXPECT_EQ(simple_markers[0]["id"], 77);
}

// A still marker under sensor noise: its corners wander from frame to frame by the noise alone.
// --smooth (One-Euro) must cut that wander, and the average corner must stay where it was.
TEST(DetectCommand, SmoothingStillsTheCornersOfAStillMarker) {
  const auto base = scratchPath(kScratch, "bch_0007");
  ASSERT_EQ(runProcess(kArbci, {"marker", "make", "--kind", "bch", "--id", "7", "--size-mm", "8",
                                "--dpi", "150", "--out", base.string()})
                .exit_code,
            0);
  cv::Mat marker = cv::imread(base.string() + ".png", cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(marker.empty());
  cv::Mat frame(240, 320, CV_8UC1, cv::Scalar(150));
  marker.copyTo(frame(cv::Rect(100, 60, marker.cols, marker.rows)));
  std::vector<std::string> files;
  cv::RNG random(3);
  for (int f = 0; f < 40; ++f) {
    cv::Mat noise(frame.size(), CV_16SC1), noisy;
    random.fill(noise, cv::RNG::NORMAL, 0, 20);
    frame.convertTo(noisy, CV_16SC1);
    noisy += noise;
    noisy.convertTo(noisy, CV_8UC1);
    files.push_back(scratchPath(kScratch, "still_" + std::to_string(100 + f) + ".png").string());
    cv::imwrite(files.back(), noisy);
  }
  // The spread of corner 0's x over the last 30 frames, and its mean.
  auto spread = [&](const std::vector<std::string>& extra) {
    std::vector<std::string> args{"detect"};
    args.insert(args.end(), extra.begin(), extra.end());
    args.insert(args.end(), files.begin(), files.end());
    const ProcessResult r = runProcess(kArbci, args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    std::vector<double> x;
    for (const auto& line : jsonLines(r.out)) {
      if (line["markers"].size() == 1) x.push_back(line["markers"][0]["corners"][0][0]);
    }
    EXPECT_EQ(x.size(), files.size());
    double mean = 0.0, square = 0.0;
    for (size_t i = 10; i < x.size(); ++i) mean += x[i] / (x.size() - 10);
    for (size_t i = 10; i < x.size(); ++i)
      square += (x[i] - mean) * (x[i] - mean) / (x.size() - 10);
    return std::pair{std::sqrt(square), mean};
  };
  const auto [raw_sd, raw_mean] = spread({"--track"});
  const auto [smooth_sd, smooth_mean] = spread({"--smooth"});
  EXPECT_GT(raw_sd, 0.01);  // the noise moves the corners: 0.019 px (SD)
  EXPECT_LT(smooth_sd, 0.5 * raw_sd) << raw_sd << " px raw";  // measured 0.005 px
  EXPECT_NEAR(smooth_mean, raw_mean, 0.1);
}

// The real photo of a bent board of simple-ID markers (SOURCES.md: ids 480-499, several cut by the
// image's edge): the search on the frame averaged over 2x2 pixels reads the same markers as the
// full one (15), their corners refined on the frame to within 0.3 px of the full search's.
TEST(DetectCommand, TheDecimatedSearchReadsARealBoardAsTheFullOne) {
  const std::string board = sharedData("vision/artoolkitplus_samples/markerboard_480-499.raw");
  auto detect = [&](const std::string& decimate) {
    const ProcessResult r = runProcess(kArbci, {"detect", "--kind", "simple", "--border", "0.125",
                                                "--raw", "320x240", "--decimate", decimate, board});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    std::map<int, nlohmann::json> corners;
    for (const auto& line : jsonLines(r.out))
      for (const auto& m : line["markers"]) corners[m["id"].get<int>()] = m["corners"];
    return corners;
  };
  const auto full = detect("1"), half = detect("2");
  EXPECT_GE(full.size(), 15u);
  ASSERT_EQ(half.size(), full.size());
  for (const auto& [id, corners] : full) {
    ASSERT_TRUE(half.count(id)) << id;
    for (int k = 0; k < 4; ++k) {
      const double dx = half.at(id)[k][0].get<double>() - corners[k][0].get<double>();
      const double dy = half.at(id)[k][1].get<double>() - corners[k][1].get<double>();
      EXPECT_LT(std::hypot(dx, dy), 0.3) << "marker " << id << " corner " << k;
    }
  }
  const ProcessResult refused = runProcess(kArbci, {"detect", "--decimate", "3", board});
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.err.find("--decimate"), std::string::npos) << refused.err;
}

TEST(MarkerCommand, ASheetHoldsEveryIdAndHazardousIdsAreWarnedAbout) {
  const auto base = scratchPath(kScratch, "sheet");
  const ProcessResult make =
      runProcess(kArbci, {"marker", "make", "--kind", "simple", "--border", "0.25", "--id",
                          "3,7,10-12", "--size-mm", "40", "--sheet", "--out", base.string()});
  ASSERT_EQ(make.exit_code, 0) << make.err;
  const ProcessResult detect =
      runProcess(kArbci, {"detect", "--kind", "simple", base.string() + ".png"});
  const auto lines = jsonLines(detect.out);
  ASSERT_EQ(lines.size(), 1u) << detect.err;
  std::vector<int> ids;
  for (const auto& m : lines[0]["markers"]) ids.push_back(m["id"]);
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(ids, (std::vector<int>{3, 7, 10, 11, 12}));
  const ProcessResult hazard =
      runProcess(kArbci, {"marker", "make", "--kind", "bch", "--id", "1550", "--out",
                          scratchPath(kScratch, "h").string()});
  EXPECT_EQ(hazard.exit_code, 0);
  EXPECT_NE(hazard.err.find("1550"), std::string::npos);
  const ProcessResult out_of_range =
      runProcess(kArbci, {"marker", "make", "--kind", "simple", "--id", "512", "--out",
                          scratchPath(kScratch, "x").string()});
  EXPECT_NE(out_of_range.exit_code, 0);
  EXPECT_NE(out_of_range.err.find("512"), std::string::npos);
}

}  // namespace
}  // namespace arbci::test

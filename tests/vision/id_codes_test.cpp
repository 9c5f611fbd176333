// Simple and BCH IDs exactly as ARToolKitPlus: every marker image it ships decodes to the id in
// its name, our encoder and printer draw the same cells, and error correction behaves as its
// notes describe.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "arbci/vision/id_codes.h"
#include "arbci/vision/marker_printer.h"
#include "support/shared_data.h"

namespace arbci::vision {
namespace {

struct MarkerImage {
  std::filesystem::path path;
  MarkerKind kind;
  double border;
  int id;
};

std::vector<MarkerImage> shippedMarkerImages() {
  std::vector<MarkerImage> images;
  const std::pair<const char*, std::pair<MarkerKind, double>> folders[] = {
      {"bch", {MarkerKind::Bch, 0.125}},
      {"simple_std", {MarkerKind::Simple, 0.25}},
      {"simple_thin", {MarkerKind::Simple, 0.125}}};
  for (const auto& [folder, kind] : folders) {
    for (const auto& entry : std::filesystem::directory_iterator(
             test::sharedData(std::string("vision/artoolkitplus_markers/") + folder))) {
      const std::string stem = entry.path().stem().string();
      images.push_back(
          {entry.path(), kind.first, kind.second, std::stoi(stem.substr(stem.find('_') + 1))});
    }
  }
  return images;
}

CodeGrid cellsOf(const cv::Mat& image) {
  const int offset = (image.cols - 6) / 2;
  CodeGrid grid{};
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c)
      grid[r * 6 + c] = image.at<std::uint8_t>(r + offset, c + offset) > 127;
  }
  return grid;
}

TEST(IdCodes, EveryShippedMarkerImageDecodesToTheIdInItsName) {
  const auto images = shippedMarkerImages();
  ASSERT_EQ(images.size(), 36u);
  for (const MarkerImage& m : images) {
    const cv::Mat image = cv::imread(m.path.string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(image.empty()) << m.path;
    const CodeWord word = gridToWord(cellsOf(image));
    const auto decoded =
        m.kind == MarkerKind::Bch ? BchCode::decode(word) : SimpleIdCode::decode(word);
    ASSERT_TRUE(decoded.has_value()) << m.path;
    EXPECT_EQ(decoded->id, m.id) << m.path;
    EXPECT_EQ(decoded->corrected_bits, 0) << m.path;
    EXPECT_EQ(decoded->confidence, 1.0f) << m.path;
  }
}

TEST(IdCodes, ThePrinterDrawsTheSameCellsAsArToolKitPlus) {
  for (const MarkerImage& m : shippedMarkerImages()) {
    const cv::Mat shipped = cv::imread(m.path.string(), cv::IMREAD_GRAYSCALE);
    const cv::Mat ours = markerCells(m.kind, m.id, m.border);
    ASSERT_EQ(ours.size(), shipped.size()) << m.path;
    cv::Mat shipped_binary = shipped > 127, ours_binary = ours > 127;
    EXPECT_EQ(cv::countNonZero(shipped_binary != ours_binary), 0) << m.path;
  }
}

// Every id with every pattern of one, two and three wrong cells (2.7 M correctable words, 29 M
// uncorrectable ones): the decoder's syndrome table must hold every correctable pattern once.
TEST(IdCodes, BchCorrectsEveryOneAndTwoBitErrorAndNoThreeBitErrorDecodesBack) {
  int wrong_corrections = 0, three_decoded_back = 0;
  for (int id = 0; id <= BchCode::kMaxId; ++id) {
    const CodeWord word = BchCode::encode(id);
    const auto clean = BchCode::decode(word);
    ASSERT_TRUE(clean.has_value());
    ASSERT_EQ(clean->id, id);
    ASSERT_EQ(clean->corrected_bits, 0);
    for (int first = 0; first < 36; ++first) {
      const CodeWord one = word ^ (CodeWord{1} << first);
      const auto decoded_one = BchCode::decode(one);
      if (!decoded_one || decoded_one->id != id || decoded_one->confidence != 0.75f)
        ++wrong_corrections;
      for (int second = first + 1; second < 36; ++second) {
        const CodeWord two = one ^ (CodeWord{1} << second);
        const auto decoded_two = BchCode::decode(two);
        if (!decoded_two || decoded_two->id != id || decoded_two->confidence != 0.5f)
          ++wrong_corrections;
        // Three errors never decode back to the id (distance 9 leaves them 6 bits from any other).
        for (int third = second + 1; third < 36; ++third) {
          const auto three = BchCode::decode(two ^ (CodeWord{1} << third));
          if (three && three->id == id) ++three_decoded_back;
        }
      }
    }
  }
  EXPECT_EQ(wrong_corrections, 0);
  EXPECT_EQ(three_decoded_back, 0);
}

TEST(IdCodes, SimpleIdAcceptsOneSplitVoteAndRejectsTwoOrATie) {
  const CodeWord word = SimpleIdCode::encode(321);
  const CodeWord one = word ^ 1;  // bit 0 of the first copy
  ASSERT_TRUE(SimpleIdCode::decode(one).has_value());
  EXPECT_EQ(SimpleIdCode::decode(one)->id, 321);
  EXPECT_NEAR(SimpleIdCode::decode(one)->confidence, 17.0f / 18.0f, 1e-6);
  EXPECT_FALSE(SimpleIdCode::decode(one ^ (CodeWord{1} << 1)).has_value());  // two 3:1 votes
  EXPECT_FALSE(SimpleIdCode::decode(one ^ (CodeWord{1} << 9)).has_value());  // a 2:2 tie
}

TEST(IdCodes, RotationHazardsMatchTheArToolKitPlusNotes) {
  EXPECT_LE(BchCode::rotationMargin(1550), 2);
  EXPECT_LE(BchCode::rotationMargin(3080), 2);
  EXPECT_LE(BchCode::rotationMargin(2098), 3);
  EXPECT_LE(BchCode::rotationMargin(2522), 3);
  EXPECT_GE(BchCode::rotationMargin(100), 5);
  // The notes: 1550/3080 within 2 bits, 2098/2492 and 2522/3192 within 3, 60 more within 4.
  std::array<int, 5> by_margin{};
  for (int id = 0; id <= BchCode::kMaxId; ++id) {
    const int margin = BchCode::rotationMargin(id);
    if (margin <= 4) ++by_margin[margin];
  }
  EXPECT_EQ(by_margin[2], 2);
  EXPECT_EQ(by_margin[3], 4);
  EXPECT_EQ(by_margin[4], 60);
}

TEST(IdCodes, RotationsOfAGridComeBackAfterFourTurns) {
  const CodeGrid grid = wordToGrid(BchCode::encode(1234));
  EXPECT_EQ(rotateClockwise(grid, 4), grid);
  EXPECT_NE(rotateClockwise(grid, 1), grid);
  // A clockwise turn moves the top-left cell to the top-right.
  EXPECT_EQ(rotateClockwise(grid, 1)[5], grid[0]);
}

}  // namespace
}  // namespace arbci::vision

// The timing check's arithmetic on a recording made here: each onset paired with the nearest
// rising edge, offsets in ms, and whatever stays unpaired counted.
#include <gtest/gtest.h>

#include "arbci/bci/photodiode_check.h"

namespace arbci::bci {
namespace {

Recording withDiode(const std::vector<std::int64_t>& onsets, int delay_samples,
                    const std::vector<std::int64_t>& extra_edges) {
  Recording r;
  r.source = "made in the test";
  r.info.rate_hz = 256.0;
  r.info.channels = {"Cz", "Diode"};
  r.samples = 2560;
  r.data.assign(static_cast<size_t>(2 * r.samples), 0.0f);
  auto light = [&](std::int64_t from) {
    for (std::int64_t s = from; s < from + 15 && s < r.samples; ++s)
      r.data[static_cast<size_t>(r.samples + s)] = 900.0f;
  };
  for (std::int64_t onset : onsets) {
    r.stimuli.push_back({onset, 1, false, 15});
    light(onset + delay_samples);
  }
  for (std::int64_t e : extra_edges) light(e);
  return r;
}

TEST(PhotodiodeCheck, PairsEachOnsetWithItsEdgeAndMeasuresTheDelay) {
  const Recording r = withDiode({100, 147, 194, 241, 1000}, 2, {});
  const PhotodiodeReport report = checkPhotodiode(r, "Diode", 0.09);
  EXPECT_EQ(report.flashes, 5);
  EXPECT_EQ(report.edges, 5);
  EXPECT_EQ(report.count, 5);
  EXPECT_NEAR(report.mean_ms, 2 * 1000.0 / 256.0, 1e-9);
  EXPECT_NEAR(report.sd_ms, 0.0, 1e-9);
  EXPECT_EQ(report.unmatched_flashes, 0);
}

TEST(PhotodiodeCheck, AnEdgeWithoutAFlashAndAFlashWithoutAnEdgeAreCounted) {
  Recording r = withDiode({100, 400}, 0, {1500});
  r.stimuli.push_back({2000, 2, false, 15});  // never shown
  const PhotodiodeReport report = checkPhotodiode(r, "Diode", 0.09);
  EXPECT_EQ(report.count, 2);
  EXPECT_EQ(report.unmatched_flashes, 1);
  EXPECT_EQ(report.unmatched_edges, 1);
}

TEST(PhotodiodeCheck, NamesAMissingOrDeadChannel) {
  const Recording r = withDiode({100}, 0, {});
  EXPECT_THROW(checkPhotodiode(r, "Photodiode", 0.09), std::invalid_argument);
  Recording dead = r;
  std::fill(dead.data.begin(), dead.data.end(), 0.0f);
  try {
    checkPhotodiode(dead, "Diode", 0.09);
    FAIL() << "a flat channel was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("never changes"), std::string::npos);
  }
}

// A diode on a trigger input: the amplifier records a marker at each edge (RDA's "Stimulus/S  1"),
// paired the same way; a marker the recording never has is named.
TEST(PhotodiodeCheck, MarkersFromATriggerInputAreTheEdgesWhereTheDiodeHasNoChannel) {
  Recording r = withDiode({100, 147, 194, 241, 1000}, 0, {});
  for (std::int64_t onset : {103, 150, 197, 244, 1003, 1800})
    r.annotations.push_back({onset, "Stimulus/S  1", 0});
  r.annotations.push_back({500, "Response/R  8", 0});
  const PhotodiodeReport report = checkPhotodiodeMarkers(r, "Stimulus/S  1", 0.09);
  EXPECT_EQ(report.channel, "marker Stimulus/S  1");
  EXPECT_EQ(report.edges, 6);
  EXPECT_EQ(report.count, 5);
  EXPECT_NEAR(report.mean_ms, 3 * 1000.0 / 256.0, 1e-9);
  EXPECT_EQ(report.unmatched_edges, 1);
  try {
    checkPhotodiodeMarkers(r, "Stimulus/S  2", 0.09);
    FAIL() << "a marker the recording lacks was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no marker \"Stimulus/S  2\""), std::string::npos);
  }
}

}  // namespace
}  // namespace arbci::bci

// Markers over frames: identities stay put when a decode fails or misreads once, and corner
// smoothing removes jitter without lagging a moving marker.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "arbci/vision/marker_tracker.h"

namespace arbci::vision {
namespace {

SquareCorners square(float x, float y, float side) {
  return {{{x, y}, {x + side, y}, {x + side, y + side}, {x, y + side}}};
}

MarkerDetection detection(int id, const SquareCorners& corners) {
  MarkerDetection m;
  m.id = id;
  m.corners = corners;
  m.confidence = 1.0f;
  return m;
}

TEST(MarkerTracker, KeepsAnIdentityOnASquareThatFailedToDecode) {
  MarkerTracker tracker;
  tracker.update({detection(7, square(100, 100, 50))}, {square(100, 100, 50)}, 0.0);
  tracker.update({detection(7, square(101, 100, 50))}, {square(101, 100, 50)}, 1 / 30.0);
  // Frame 3: the square is there (moved a little) but did not decode.
  const auto kept = tracker.update({}, {square(103, 101, 50)}, 2 / 30.0);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].id, 7);
  EXPECT_TRUE(kept[0].from_history);
  EXPECT_LT(kept[0].confidence, 1.0f);
  EXPECT_NEAR(kept[0].corners[0].x, 103.0f, 1e-3);
  // No square, no marker: nothing is invented.
  EXPECT_TRUE(tracker.update({}, {}, 3 / 30.0).empty());
  // A square elsewhere is not this marker.
  EXPECT_TRUE(tracker.update({}, {square(300, 300, 50)}, 4 / 30.0).empty());
}

TEST(MarkerTracker, AnotherIdMustRepeatBeforeItReplacesAConfirmedOne) {
  MarkerTracker tracker;
  for (int f = 0; f < 3; ++f) tracker.update({detection(7, square(100, 100, 50))}, {}, f / 30.0);
  const auto once = tracker.update({detection(9, square(100, 100, 50))}, {}, 3 / 30.0);
  ASSERT_EQ(once.size(), 1u);
  EXPECT_EQ(once[0].id, 7);
  const auto twice = tracker.update({detection(9, square(100, 100, 50))}, {}, 4 / 30.0);
  ASSERT_EQ(twice.size(), 1u);
  EXPECT_EQ(twice[0].id, 9);
}

TEST(MarkerTracker, SmoothingRemovesJitterWithoutLaggingMotion) {
  TrackerOptions options;
  options.smooth_corners = true;
  std::mt19937 random(3);
  std::normal_distribution<float> jitter(0.0f, 0.5f);
  // A still marker with 0.5 px corner jitter, 60 frames per second.
  MarkerTracker still(options);
  double raw_variance = 0.0, smoothed_variance = 0.0;
  for (int f = 0; f < 300; ++f) {
    const float dx = jitter(random);
    const auto out = still.update({detection(1, square(200 + dx, 200, 60))}, {}, f / 60.0);
    if (f >= 30) {
      raw_variance += dx * dx;
      smoothed_variance += std::pow(out[0].corners[0].x - 200.0f, 2.0f);
    }
  }
  EXPECT_LT(smoothed_variance, raw_variance / 4.0) << "jitter std should drop by half or more";
  // A marker moving at 300 px/s: after the filter settles, the lag stays under 1.5 px.
  MarkerTracker moving(options);
  float lag = 0.0f;
  for (int f = 0; f < 60; ++f) {
    const float x = 100.0f + 5.0f * static_cast<float>(f);
    const auto out = moving.update({detection(1, square(x, 200, 60))}, {}, f / 60.0);
    if (f >= 20) lag = std::max(lag, x - out[0].corners[0].x);
  }
  EXPECT_LT(lag, 1.5f);
}

}  // namespace
}  // namespace arbci::vision

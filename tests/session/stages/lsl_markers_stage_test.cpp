// The LSL Markers stage on hand-built records, received by an inlet on this machine: the last
// cycle's notes, each flash with its label and the feedback shown go out as strings in the order
// they happened, a flash stamped at the instant its frame reached the screen, and the end.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "arbci/bci/lsl/inlet.h"
#include "arbci/bci/lsl/resolver.h"
#include "arbci/session/stages/lsl_markers_stage.h"
#include "support/lsl_scope.h"
#include "support/stage_bench.h"

namespace arbci::session {
namespace {

std::vector<bci::lsl::Sample> pull(bci::lsl::Inlet& inlet, size_t count) {
  std::vector<bci::lsl::Sample> got;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (got.size() < count && std::chrono::steady_clock::now() < deadline) {
    if (inlet.pull(got, count - got.size()) == 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return got;
}

TEST(LslMarkersStage, NotesFlashesFeedbackAndTheEndGoOutAsTheyHappen) {
  test::StageBench bench("lsl_markers", Clock::Mode::RealTime);
  const std::string name = "markers-" + std::to_string(::getpid());
  LslMarkersStage stage(
      LslMarkersSettings{name, test::machineScope(), 256.0, "test.json", {{"Paradigm", "single"}}},
      bench.services());
  const auto found = bci::lsl::resolveStreams(
      test::machineScope(), bci::lsl::buildQuery("default", name, "Markers"), 3.0);
  ASSERT_EQ(found.size(), 1u);
  bci::lsl::Inlet inlet(found[0], test::machineScope());
  // The inlet connects before anything is sent (a marker pushed before is not kept).
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  bench.previous.annotations.push_back({0, "Phase calibration: flashing", 0});
  const double shown_at = bench.clock().hostOf(1.0);
  bench.record.presentation.host_s = shown_at;
  bench.record.presentation.onsets.push_back({Flash{3, true, true, true, 1}, 256});
  bench.record.presentation.onsets.push_back({Flash{2, false, false, false, 1}, 260});
  bench.record.presentation.feedback = FeedbackShown{{1}, true, false};
  bench.step(stage);
  bench.next();
  Cycle end = bench.cycle();
  stage.stop(end, "finished");
  const auto got = pull(inlet, 5);
  ASSERT_EQ(got.size(), 5u);
  EXPECT_EQ(got[0].strings[0], "Phase calibration: flashing");
  EXPECT_EQ(got[1].strings[0], "flash 3 target");
  EXPECT_DOUBLE_EQ(got[1].timestamp, shown_at);
  EXPECT_EQ(got[2].strings[0], "flash 102 unknown");
  EXPECT_EQ(got[3].strings[0], "Feedback 1 correct");
  EXPECT_EQ(got[4].strings[0], "Session ended: finished");
  EXPECT_EQ(bench.logged("lsl_markers").size(), 1u);
}

}  // namespace
}  // namespace arbci::session

// Tracking health on a live simulated session (in process, headless EGL, the real tracker on
// the simulated cameras' frames with head motion): a threshold that finds no marker makes every
// pose stale after tracker.max_pose_age_s; the objects' flashes are then withheld (not lit, not
// recorded; the cued selection pauses and is retaken once they are seen again), the alarm names the
// reference and each object, and the recording says when tracking was lost and regained. Restoring
// the threshold brings the flashes back.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "arbci/bci/recording.h"
#include "arbci/render/gl_context.h"
#include "arbci/session/session.h"
#include "hmd/open_session.h"
#include "support/test_files.h"
#include "workstation/session_model.h"

namespace arbci::test {
namespace {

TEST(TrackingHealth, StalePosesWithholdFlashesAndRaiseTheAlarmUntilTrackingReturns) {
  session::SessionConfig config = session::SessionConfig::load(std::nullopt);
  session::SessionOptions options;
  options.folder = freshTempPath("tracking_health_test", "session");
  options.flashes_only_s = 30.0;  // cued flashing of the objects, nothing else
  auto context = render::createHeadlessContext({64, 64});
  nlohmann::json alarm_while_lost;
  {
    app::OpenedSession opened = app::openSession(config, options, *context);
    session::Session& session = *opened.session;
    auto runTo = [&](double t) {
      while (session.time() < t && session.step()) {
      }
    };
    runTo(6.0);
    EXPECT_EQ(app::trackingAlarm(session), "");
    // Everything but pure white is dark: no marker square is found from here on.
    vision::ThresholdSettings blind;
    blind.mode = vision::ThresholdMode::Constant;
    blind.value = 254;
    session.request(session::ThresholdRequest{blind});
    runTo(12.0);
    const std::string alarm = app::trackingAlarm(session);
    EXPECT_NE(alarm.find("tracking lost: reference 0"), std::string::npos) << alarm;
    for (const auto& o : config.world.objects)
      EXPECT_NE(alarm.find("object " + std::to_string(o.id)), std::string::npos) << alarm;
    session.request(session::ThresholdRequest{vision::ThresholdSettings{}});
    runTo(18.0);
    EXPECT_EQ(app::trackingAlarm(session), "");
    session.request(session::AbortRequest{});
    session.step();
  }
  // The log: flashes shown before and after, withheld only while blind (from 0.5 s after the
  // threshold changed, the allowed pose age, until tracking returned). The first withheld flash
  // of a cued selection pauses it; once every object has been in view for a second it is retaken.
  int withheld = 0, withheld_outside = 0, paused = 0, retaken = 0;
  std::ifstream log(options.folder / "log.jsonl");
  std::string line;
  while (std::getline(log, line)) {
    const nlohmann::json e = nlohmann::json::parse(line);
    paused += e["event"] == "paused" &&
              e["reason"].get<std::string>().find("flash withheld") != std::string::npos;
    retaken += e["event"] == "calibration_retake" && e["t"].get<double>() > 12.0;
    if (e["event"] != "flash_withheld") continue;
    ++withheld;
    const double t = e["t"].get<double>();
    withheld_outside += t < 6.4 || t > 12.5;
  }
  EXPECT_GE(withheld, 1);
  EXPECT_EQ(withheld_outside, 0);
  EXPECT_EQ(paused, 1);
  EXPECT_EQ(retaken, 1);
  // The recording: no object flash stamped while blind; flashes before and after; the
  // annotations.
  const bci::Recording recording = bci::readRecording(options.folder / "recording.bdf");
  const double rate = recording.info.rate_hz;
  int before = 0, during = 0, after = 0;
  for (const auto& s : recording.stimuli) {
    const double t = s.sample / rate;
    before += t < 6.0;
    during += t > 6.6 && t < 12.0;
    after += t > 13.0;
  }
  EXPECT_GT(before, 10);
  EXPECT_EQ(during, 0);
  EXPECT_GT(after, 10);
  int lost = 0, regained = 0;
  for (const auto& a : recording.annotations) {
    lost += a.text.rfind("Tracking lost object", 0) == 0;
    regained += a.text.rfind("Tracking regained object", 0) == 0;
  }
  EXPECT_EQ(lost, static_cast<int>(config.world.objects.size()));
  EXPECT_EQ(regained, static_cast<int>(config.world.objects.size()));
}

}  // namespace
}  // namespace arbci::test

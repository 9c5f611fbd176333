// The averages behind the session's own classifiers, as the Training panel shows them beside each
// other: after the calibration run (in process, headless EGL, the simulated subject with ErrPs),
// the P300 averages count the calibration run's target and non-target flashes and the ErrP ones
// its feedback block's error and correct feedback, as the recording annotates them; the ErrP
// difference at Cz is the simulated response: negative about 250 ms after the feedback, then
// positive about 100 ms later. A model loaded over it drops them (they were not its data).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iostream>

#include "arbci/bci/recording.h"
#include "arbci/render/gl_context.h"
#include "arbci/session/session.h"
#include "hmd/open_session.h"
#include "support/test_files.h"
#include "workstation/session_model.h"

namespace arbci::test {
namespace {

TEST(SessionErps, TheTrainingPanelGetsTheAveragesOfBothClassifiers) {
  const auto folder = freshTempPath("session_erps_test", "session");
  const auto file = folder.string() + ".json";
  // A short cued P300 run (its averages are counted, not judged): 4 selections of 4 sequences;
  // then the feedback block at its default length, whose ErrP averages are judged.
  std::ofstream(file) << R"({"errp": {"enabled": true},
    "paradigm": {"calibration_selections": 4, "calibration_sequences": 4, "cue_s": 0.5,
                 "pause_s": 0.5},
    "cameras": {"head_motion_m": 0.0, "head_motion_deg": 0.0}, "robot": {"speed_factor": 20}})";
  const session::SessionConfig config = session::SessionConfig::load(file);
  session::SessionOptions options;
  options.folder = folder;
  options.trials = 1;
  auto context = render::createHeadlessContext({64, 64});
  std::optional<bci::ErpCurves> p300, errp;
  {
    app::OpenedSession opened = app::openSession(config, options, *context);
    session::Session& session = *opened.session;
    app::SessionModel model(session);
    EXPECT_FALSE(model.sessionErrpErp());
    for (int i = 0; i < 60 * 1200 && session.last().paradigm.phase != bci::Phase::ObjectFlashing &&
                    session.step();
         ++i) {
    }
    ASSERT_EQ(session.last().paradigm.phase, bci::Phase::ObjectFlashing);
    p300 = model.sessionErp();
    errp = model.sessionErrpErp();
    ASSERT_TRUE(p300);
    ASSERT_TRUE(errp);
    // A model loaded in its place (here the same one, from its JSON) was not trained on them.
    model.useModel(*model.model());
    session.step();  // the request is acted on in the next cycle
    EXPECT_FALSE(model.sessionErp());
    EXPECT_FALSE(model.sessionErrpErp());
    session.request(session::AbortRequest{});
    session.step();
  }
  // Counted independently from the recording: flashes up to the first feedback are the
  // calibration run's P300 flashes; the feedback block's annotations say error or correct.
  const bci::Recording recording = bci::readRecording(folder / "recording.bdf");
  int errors = 0, corrects = 0;
  for (const auto& a : recording.annotations) {
    if (a.text.rfind("Feedback ", 0) != 0) continue;
    (a.text.ends_with(" error") ? errors : corrects) += 1;
  }
  EXPECT_EQ(errp->targets, errors);
  EXPECT_EQ(errp->others, corrects);
  EXPECT_EQ(errors + corrects, config.paradigm.errp_calibration_feedbacks);
  EXPECT_GT(p300->targets, 0);
  EXPECT_EQ(p300->others, 3 * p300->targets);  // four objects: one target, three others per round

  const auto cz = std::find(errp->channels.begin(), errp->channels.end(), "Cz");
  ASSERT_NE(cz, errp->channels.end());
  const std::vector<double> difference =
      bci::ErpCurves::row(errp->difference(), static_cast<int>(cz - errp->channels.begin()));
  // The simulated ErrP's shape: a negativity, then a later positivity. Its latency is the
  // simulated subject's own (Ne at 220-290 ms, Pe 100 ms later), and over about 20 error epochs a
  // fixed window's mean is as much noise as response: the extremes are compared instead.
  int trough = -1, peak = -1;
  for (int i = 0; i < errp->samples(); ++i) {
    const double t = errp->timeS(i);
    if (t >= 0.15 && t < 0.35 && (trough < 0 || difference[i] < difference[trough])) trough = i;
    if (t >= 0.25 && t < 0.55 && (peak < 0 || difference[i] > difference[peak])) peak = i;
  }
  ASSERT_GE(trough, 0);
  ASSERT_GE(peak, 0);
  std::cout << "ErrP difference at Cz: " << difference[trough] << " uV at "
            << errp->timeS(trough) * 1000 << " ms, " << difference[peak] << " uV at "
            << errp->timeS(peak) * 1000 << " ms\n";
  EXPECT_LT(difference[trough], -1.0);
  EXPECT_GT(difference[peak], 1.0);
  EXPECT_GT(errp->timeS(peak), errp->timeS(trough));
}

}  // namespace
}  // namespace arbci::test

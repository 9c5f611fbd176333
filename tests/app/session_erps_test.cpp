// The averages behind the session's own classifiers, as the Training panel shows them beside each
// other: after the calibration run (in process, headless EGL, the simulated subject with ErrPs),
// the P300 averages count the calibration run's target and non-target flashes and the ErrP ones
// its feedback block's error and correct feedback, as the recording annotates them; the ErrP
// difference at Cz is the simulated response: negative about 250 ms after the feedback, then
// positive about 100 ms later. A model loaded over it drops them (they were not its data).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "arbci/bci/recording.h"
#include "arbci/render/gl_context.h"
#include "arbci/session/session.h"
#include "hmd/open_session.h"
#include "support/test_files.h"
#include "workstation/session_model.h"

namespace arbci::test {
namespace {

// The mean of `row` over [from_s, to_s) after the stimulus.
double meanBetween(const bci::ErpCurves& erp, const std::vector<double>& row, double from_s,
                   double to_s) {
  double sum = 0.0;
  int n = 0;
  for (int s = 0; s < erp.samples(); ++s) {
    if (erp.timeS(s) >= from_s && erp.timeS(s) < to_s) {
      sum += row[static_cast<size_t>(s)];
      ++n;
    }
  }
  return n ? sum / n : 0.0;
}

TEST(SessionErps, TheTrainingPanelGetsTheAveragesOfBothClassifiers) {
  const auto folder = freshTempPath("session_erps_test", "session");
  const auto file = folder.string() + ".json";
  // A short calibration run (the averages are counted, not judged): 4 cued selections of 4
  // sequences, then 80 feedbacks (a fifth of them errors: the ErrP classifier
  // needs at least 10 of each kind).
  std::ofstream(file) << R"({"errp": {"enabled": true, "calibration_feedbacks": 80},
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
  // Measured -2.0 and +0.85 uV (the 1-10 Hz band and Cz, not FCz, shrink the positivity).
  const double negativity = meanBetween(*errp, difference, 0.20, 0.30);
  const double positivity = meanBetween(*errp, difference, 0.32, 0.42);
  EXPECT_LT(negativity, -1.0);
  EXPECT_GT(positivity, 0.0);
}

}  // namespace
}  // namespace arbci::test

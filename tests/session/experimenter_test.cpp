// What the experimenter may do in each state, and why not: the buttons' reasons come from here.
#include <gtest/gtest.h>

#include "arbci/session/experimenter.h"

namespace arbci::session {
namespace {

CycleRecord stoppedIn(bci::Phase phase, int trial) {
  CycleRecord last;
  last.paradigm.phase = bci::Phase::EmergencyStop;
  last.paradigm.interrupted = phase;
  last.paradigm.trial = trial;
  return last;
}

TEST(Experimenter, AfterAStopInSetUpRetryAndSkipSayThereIsNothingToActOn) {
  const CycleRecord last = stoppedIn(bci::Phase::Setup, 0);
  EXPECT_EQ(whyNot(Action::RetryStep, last),
            "nothing to retry: the session had not started (Resume returns to set-up)");
  EXPECT_EQ(whyNot(Action::SkipTrial, last),
            "no trial to skip: the stop came before the first trial; Resume goes on");
  EXPECT_EQ(whyNot(Action::Resume, last), "");
}

TEST(Experimenter, AStopDuringCalibrationCannotSkipATrialButCanRetry) {
  const CycleRecord last = stoppedIn(bci::Phase::CalibrationFlashing, 0);
  EXPECT_NE(whyNot(Action::SkipTrial, last), "");
  EXPECT_EQ(whyNot(Action::RetryStep, last), "");
}

TEST(Experimenter, AStopInATrialCanSkipIt) {
  const CycleRecord last = stoppedIn(bci::Phase::ObjectFlashing, 2);
  EXPECT_EQ(whyNot(Action::SkipTrial, last), "");
}

TEST(Experimenter, OnceEndedTheEmergencyStopAndResetAreRefusedWithTheReason) {
  CycleRecord last;
  EXPECT_EQ(whyNot(Action::EmergencyStop, last), "");
  last.ended = true;
  for (const Action action : {Action::EmergencyStop, Action::ResetRobot}) {
    const std::string why = whyNot(action, last);
    EXPECT_NE(why.find("the session has ended"), std::string::npos) << why;
    EXPECT_NE(why.find("emergency switch"), std::string::npos) << why;
  }
  EXPECT_EQ(whyNot(Action::Abort, last), "the session has ended");
}

}  // namespace
}  // namespace arbci::session

namespace arbci::session {
namespace {

TEST(Experimenter, APauseTheSessionMadeForViewResumesByItselfNotByResume) {
  CycleRecord last;
  last.paradigm.phase = bci::Phase::Paused;
  last.paradigm.waiting_for = "every object in view for 1 s (not seen: 10, 20)";
  EXPECT_EQ(whyNot(Action::Resume, last),
            "it resumes by itself once every object in view for 1 s (not seen: 10, 20), in the "
            "same selection");
  last.paradigm.waiting_for.clear();  // the experimenter's own pause
  EXPECT_EQ(whyNot(Action::Resume, last), "");
}

}  // namespace
}  // namespace arbci::session

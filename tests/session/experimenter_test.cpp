// What the experimenter may do in each state, and why not: the buttons' reasons come from here.
#include <gtest/gtest.h>

#include "arbci/session/experimenter.h"
#include "arbci/session/record_text.h"

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

// After an E-STOP the next step is said as long as the run waits: where the arm is, and what Retry
// step, Skip trial and Resume each do (Resume after a robot step ends that trial).
TEST(Experimenter, AfterAStopTheNextStepIsSaidWithWhereTheArmIs) {
  CycleRecord last = stoppedIn(bci::Phase::Grasping, 2);
  last.robot.at_home = true;
  const std::string next = recoveryText(last);
  EXPECT_NE(next.find("Stopped in trial 2 (robot grasping). The arm is at home, holding nothing."),
            std::string::npos)
      << next;
  EXPECT_NE(next.find("Retry step does the grasp again; Skip trial or Resume ends this trial here "
                      "and starts the next"),
            std::string::npos)
      << next;
  last.robot.at_home = false;
  EXPECT_NE(recoveryText(last).find("Home (Robot panel) first"), std::string::npos);
  const CycleRecord flashing = stoppedIn(bci::Phase::CellFlashing, 1);
  EXPECT_NE(recoveryText(flashing).find("Resume (or Retry step) goes on with phase 2"),
            std::string::npos)
      << recoveryText(flashing);
  CycleRecord running;
  running.paradigm.phase = bci::Phase::ObjectFlashing;
  EXPECT_EQ(recoveryText(running), "");
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

// The paradigm, frame by frame: flash timing in frames, every stimulus once per sequence and never
// twice in a row, the calibration run, a whole trial with the robot, dynamic stopping, and pause,
// abort, emergency stop and robot faults; with ErrPs, the calibration's feedback block, the robot
// waiting for the verdict, the runner-up, repeats, and the object put back.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <set>

#include "arbci/bci/decision.h"
#include "arbci/bci/paradigm.h"

namespace arbci::bci {
namespace {

using Kind = ParadigmEvent::Kind;

ParadigmSettings fast() {
  ParadigmSettings s;
  s.sequences = 3;
  s.calibration_sequences = 3;
  s.calibration_selections = 2;
  s.trials = 2;
  return s;
}

// Runs frames until `until` holds or `limit` frames pass; collects the events.
template <typename Condition>
std::vector<ParadigmEvent> runUntil(Paradigm& p, std::int64_t& frame, Condition until,
                                    int limit = 5000) {
  std::vector<ParadigmEvent> events;
  for (int i = 0; i < limit && !until(); ++i) {
    p.frame(frame++);
    for (auto& e : p.takeEvents()) events.push_back(e);
  }
  for (auto& e : p.takeEvents()) events.push_back(e);
  return events;
}

Decision choose(int choice, const std::set<int>& codes) {
  Decision d;
  d.choice = choice;
  d.codes = codes;
  d.certainty = 0.99;
  return d;
}

TEST(Paradigm, FlashesLastFourFramesEveryElevenFramesEachCodeOncePerSequence) {
  Paradigm p(fast(), 4, 3, 3, 1);
  std::int64_t frame = 0;
  p.start(false);
  std::vector<std::set<int>> lit;
  std::vector<ParadigmEvent> flashes;
  for (int i = 0; i < 200 && !p.awaitingDecision(); ++i) {
    lit.push_back(p.frame(frame++).lit);
    for (auto& e : p.takeEvents()) {
      if (e.kind == Kind::Flash) flashes.push_back(e);
    }
  }
  ASSERT_EQ(flashes.size(), 12u);  // 3 sequences of 4 objects
  for (size_t i = 0; i < flashes.size(); ++i) {
    if (i > 0) {
      EXPECT_EQ(flashes[i].frame - flashes[i - 1].frame, 11);  // 183 ms at 60 Hz
      EXPECT_NE(flashes[i].code, flashes[i - 1].code);         // never twice in a row
    }
    const auto onset = static_cast<size_t>(flashes[i].frame);
    for (size_t f = onset; f < onset + 11; ++f)
      EXPECT_EQ(lit[f].count(flashes[i].code) > 0, f < onset + 4) << "frame " << f;
  }
  for (int s = 0; s < 3; ++s) {
    std::set<int> codes;
    for (int i = 0; i < 4; ++i) codes.insert(flashes[static_cast<size_t>(s * 4 + i)].code);
    EXPECT_EQ(codes, (std::set<int>{1, 2, 3, 4}));
  }
}

TEST(Paradigm, CalibrationRunCuesTargetsThenAsksForTraining) {
  Paradigm p(fast(), 4, 3, 3, 2);
  std::int64_t frame = 0;
  p.start(true);
  auto events = p.takeEvents();
  ASSERT_TRUE(p.calibrationTarget().has_value());
  EXPECT_EQ(p.phase(), Phase::CalibrationCue);
  EXPECT_EQ(p.frame(frame++).cued_object, p.calibrationTarget());
  for (int selection = 0; selection < 2; ++selection) {
    events = runUntil(p, frame, [&] { return p.awaitingDecision(); });
    EXPECT_EQ(p.phase(), Phase::CalibrationFlashing);
    int flashes = 0;
    for (const auto& e : events) flashes += e.kind == Kind::Flash;
    EXPECT_EQ(flashes, 12);
    p.decide(Decision{});
  }
  events = p.takeEvents();
  EXPECT_EQ(p.phase(), Phase::Training);
  EXPECT_TRUE(std::any_of(events.begin(), events.end(),
                          [](const ParadigmEvent& e) { return e.kind == Kind::TrainModel; }));
  p.modelTrained(true, "");
  EXPECT_EQ(p.phase(), Phase::ObjectFlashing);
  EXPECT_EQ(p.trial(), 1);
}

// A calibration selection interrupted part-way (a pause, an emergency stop) goes on where it
// stopped: the interrupted sequence is shown again (its flashes before the interruption kept and
// counted as re-flashed), never the whole selection. One whose flashes were withheld is retaken
// when the session asks: the same target cued again and every sequence flashed anew.
TEST(Paradigm, AnInterruptedCalibrationSelectionGoesOnOrIsRetakenWhenAsked) {
  Paradigm p(fast(), 4, 3, 3, 2);
  std::int64_t frame = 0;
  p.start(true);
  p.takeEvents();
  const int target = *p.calibrationTarget();
  int flashes = 0;
  auto count = [&] {
    for (auto& e : p.takeEvents()) flashes += e.kind == Kind::Flash;
    return flashes >= 5;
  };
  for (int i = 0; i < 500 && !count(); ++i) p.frame(frame++);
  ASSERT_EQ(p.phase(), Phase::CalibrationFlashing);
  p.pause();
  for (int i = 0; i < 30; ++i) EXPECT_TRUE(p.frame(frame++).lit.empty());
  p.takeEvents();
  p.resume();
  EXPECT_EQ(p.phase(), Phase::CalibrationFlashing);
  EXPECT_EQ(p.calibrationRetakes(), 0);
  EXPECT_EQ(p.reflashedSequences(), 1);
  // The second sequence (interrupted after its first flash) again, then the third: 5 + 8 shown.
  auto events = runUntil(p, frame, [&] { return p.awaitingDecision(); });
  EXPECT_EQ(std::count_if(events.begin(), events.end(),
                          [](const ParadigmEvent& e) { return e.kind == Kind::Flash; }),
            8);
  p.decide(Decision{});
  // The second selection stopped mid-way by an emergency stop, then retried: it goes on too.
  flashes = 0;
  for (int i = 0; i < 500 && !count(); ++i) p.frame(frame++);
  p.emergencyStop();
  p.retryStep();
  EXPECT_EQ(p.phase(), Phase::CalibrationFlashing);
  EXPECT_EQ(p.calibrationRetakes(), 0);
  // Paused again with flashes withheld: the session asks for a retake.
  for (int i = 0; i < 3; ++i) p.frame(frame++);
  p.pause();
  p.takeEvents();
  p.resume(true);
  EXPECT_EQ(p.phase(), Phase::CalibrationCue);
  EXPECT_EQ(p.calibrationRetakes(), 1);
  events = p.takeEvents();
  const auto started = std::find_if(events.begin(), events.end(), [](const ParadigmEvent& e) {
    return e.kind == Kind::SelectionStarted;
  });
  ASSERT_NE(started, events.end());
  EXPECT_TRUE(started->retake);
  EXPECT_NE(started->codes, std::set<int>{});
  // The retake flashes all three sequences from the start.
  events = runUntil(p, frame, [&] { return p.awaitingDecision(); });
  EXPECT_EQ(std::count_if(events.begin(), events.end(),
                          [](const ParadigmEvent& e) { return e.kind == Kind::Flash; }),
            12);
  p.decide(Decision{});
  EXPECT_EQ(p.phase(), Phase::Training);  // two selections, as set
  (void)target;
}

TEST(Paradigm, ATrialSelectsAnObjectGraspsItSelectsACellAndPutsItDown) {
  Paradigm p(fast(), 4, 3, 3, 3);
  std::int64_t frame = 0;
  p.start(false);
  for (int trial = 1; trial <= 2; ++trial) {
    runUntil(p, frame, [&] { return p.awaitingDecision(); });
    p.decide(choose(2, {3}));
    EXPECT_EQ(p.phase(), Phase::ObjectSelected);
    EXPECT_EQ(p.frame(frame++).selected_object, 3);
    auto events = runUntil(p, frame, [&] { return p.phase() == Phase::Grasping; });
    const auto grasp = std::find_if(events.begin(), events.end(), [](const ParadigmEvent& e) {
      return e.kind == Kind::RobotGrasp;
    });
    ASSERT_NE(grasp, events.end());
    EXPECT_EQ(grasp->object, 3);
    p.robotFinished(true, "holding");
    EXPECT_EQ(p.phase(), Phase::CellFlashing);
    std::vector<ParadigmEvent> flashes;
    for (int i = 0; i < 1000 && !p.awaitingDecision(); ++i) {
      EXPECT_TRUE(p.frame(frame++).grid_visible);
      for (auto& e : p.takeEvents()) {
        if (e.kind == Kind::Flash) flashes.push_back(e);
      }
    }
    EXPECT_EQ(flashes.size(), 18u);  // 3 sequences of 3 rows and 3 columns
    EXPECT_FALSE(flashes.front().objects_layout);
    p.decide(choose(5, {2, 6}));  // row 2, column 3
    EXPECT_EQ(p.phase(), Phase::CellSelected);
    events = runUntil(p, frame, [&] { return p.phase() == Phase::Dropping; });
    const auto drop = std::find_if(events.begin(), events.end(), [](const ParadigmEvent& e) {
      return e.kind == Kind::RobotDrop;
    });
    ASSERT_NE(drop, events.end());
    EXPECT_EQ(drop->cell, std::make_pair(2, 3));
    p.robotFinished(true, "released");
    events = p.takeEvents();
    EXPECT_TRUE(std::any_of(events.begin(), events.end(),
                            [](const ParadigmEvent& e) { return e.kind == Kind::TrialDone; }));
  }
  EXPECT_EQ(p.phase(), Phase::Finished);
}

// Three trials learning from use: no calibration run, started with the arm held ("learning").
std::unique_ptr<Paradigm> learningFromUse() {
  ParadigmSettings settings = fast();
  settings.trials = 3;
  auto p = std::make_unique<Paradigm>(settings, 4, 3, 3, 3);
  p->holdArm(true, "learning");
  p->start(false);
  return p;
}

TEST(Paradigm, WhileTheArmIsHeldASelectionEndsItsTrialWithoutTheRobot) {
  // Learning from use: the first selection has no model (no choice), the second is made but the
  // model is not trusted; neither sends the arm. Trusted, the third trial grasps.
  const std::unique_ptr<Paradigm> learning = learningFromUse();
  Paradigm& p = *learning;
  std::int64_t frame = 0;
  EXPECT_EQ(p.phase(), Phase::ObjectFlashing);  // no calibration run
  runUntil(p, frame, [&] { return p.awaitingDecision(); });
  p.decide(Decision{});
  auto events = p.takeEvents();
  const auto done = [](const std::vector<ParadigmEvent>& list) {
    return std::find_if(list.begin(), list.end(),
                        [](const ParadigmEvent& e) { return e.kind == Kind::TrialDone; });
  };
  ASSERT_NE(done(events), events.end());
  EXPECT_EQ(done(events)->text, "learning");
  EXPECT_EQ(p.trial(), 2);
  runUntil(p, frame, [&] { return p.awaitingDecision(); });
  p.decide(choose(1, {2}));
  EXPECT_EQ(p.phase(), Phase::ObjectSelected);
  p.holdArm(false, "");  // trusted now: the selection already shown keeps the arm held
  events = runUntil(p, frame, [&] { return p.trial() == 3; });
  EXPECT_TRUE(std::none_of(events.begin(), events.end(),
                           [](const ParadigmEvent& e) { return e.kind == Kind::RobotGrasp; }));
  ASSERT_NE(done(events), events.end());
  EXPECT_EQ(done(events)->text, "learning");
  runUntil(p, frame, [&] { return p.awaitingDecision(); });
  p.decide(choose(3, {4}));
  events = runUntil(p, frame, [&] { return p.phase() == Phase::Grasping; });
  EXPECT_EQ(p.phase(), Phase::Grasping);
}

TEST(Paradigm, AHeldSelectionWaitsForItsFitAndGoesToTheArmWhenThatFitTrustsIt) {
  const std::unique_ptr<Paradigm> learning = learningFromUse();
  Paradigm& p = *learning;
  std::int64_t frame = 0;
  const auto grasps = [](const std::vector<ParadigmEvent>& list) {
    return std::count_if(list.begin(), list.end(),
                         [](const ParadigmEvent& e) { return e.kind == Kind::RobotGrasp; });
  };
  // Trial 1: its fit is running; the selection stays shown well past result_s, then the fit
  // comes back not trusted and the trial ends held.
  runUntil(p, frame, [&] { return p.awaitingDecision(); });
  p.decide(choose(1, {2}));
  p.judgeHeldSelection(true, false, "learning");
  const std::int64_t shown_from = frame;
  auto events = runUntil(p, frame, [&] { return frame >= shown_from + 200; });
  EXPECT_EQ(p.phase(), Phase::ObjectSelected);
  EXPECT_EQ(p.trial(), 1);
  p.judgeHeldSelection(false, false, "not as shown");
  events = runUntil(p, frame, [&] { return p.trial() == 2; });
  EXPECT_EQ(grasps(events), 0);
  const auto done = std::find_if(events.begin(), events.end(),
                                 [](const ParadigmEvent& e) { return e.kind == Kind::TrialDone; });
  ASSERT_NE(done, events.end());
  EXPECT_EQ(done->text, "not as shown");
  // Trial 2: the fit with it in is trusted and decodes it as shown: it goes on to the arm.
  runUntil(p, frame, [&] { return p.awaitingDecision(); });
  p.decide(choose(2, {3}));
  p.judgeHeldSelection(true, false, "learning");
  const std::int64_t second_from = frame;
  runUntil(p, frame, [&] { return frame >= second_from + 200; });
  EXPECT_EQ(p.phase(), Phase::ObjectSelected);
  p.judgeHeldSelection(false, true, "");
  events = runUntil(p, frame, [&] { return p.phase() == Phase::Grasping; });
  EXPECT_EQ(grasps(events), 1);
  EXPECT_EQ(p.trial(), 2);
}

// Learning from use's paradigm: 3 sequences (fast()), a trusted selection up to 5.
ParadigmSettings learningSettings() {
  ParadigmSettings s = fast();
  s.trials = 3;
  s.learning_max_sequences = 5;
  return s;
}

// Starts `p` as learning from use does, the arm held, its object selections flashing as `mode`.
void startLearning(Paradigm& p, Paradigm::ObjectSequences mode) {
  p.holdArm(true, "learning");
  p.setObjectSequences(mode);
  p.start(false);
}

// The flashes until the paradigm awaits its decision.
long flashesToDecision(Paradigm& p, std::int64_t& frame) {
  const std::vector<ParadigmEvent> list = runUntil(p, frame, [&] { return p.awaitingDecision(); });
  return std::count_if(list.begin(), list.end(),
                       [](const ParadigmEvent& e) { return e.kind == Kind::Flash; });
}

TEST(Paradigm, ATrustedLearningObjectSelectionFlashesUpToTheLearningMostUntilStopped) {
  Paradigm p(learningSettings(), 4, 3, 3, 4);
  startLearning(p, Paradigm::ObjectSequences::Trusted);
  std::int64_t frame = 0;
  // Never certain enough: all five sequences of four objects.
  EXPECT_EQ(flashesToDecision(p, frame), 20);
  // Certain after the minimum (3 here, the default): dynamic stopping ends it as ever.
  p.decide(choose(1, {2}));
  p.judgeHeldSelection(false, false, "learning");
  runUntil(p, frame, [&] { return p.trial() == 2 && p.phase() == Phase::ObjectFlashing; });
  p.requestStopFlashing();
  EXPECT_EQ(flashesToDecision(p, frame), 12);
  // Trusted without dynamic stopping's certainty: `sequences`.
  p.decide(choose(2, {3}));
  p.judgeHeldSelection(false, false, "learning");
  p.setObjectSequences(Paradigm::ObjectSequences::Usual);
  runUntil(p, frame, [&] { return p.phase() == Phase::ObjectFlashing; });
  EXPECT_EQ(flashesToDecision(p, frame), 12);
}

TEST(Paradigm, AnUntrustedLearningObjectSelectionFlashesAllTheLearningSequences) {
  // learning_sequences 0: as many as a trusted selection may flash (five of four objects).
  Paradigm p(learningSettings(), 4, 3, 3, 4);
  startLearning(p, Paradigm::ObjectSequences::Learning);
  std::int64_t frame = 0;
  EXPECT_EQ(flashesToDecision(p, frame), 20);
  // Set: that many.
  ParadigmSettings four = learningSettings();
  four.learning_sequences = 4;
  Paradigm q(four, 4, 3, 3, 4);
  startLearning(q, Paradigm::ObjectSequences::Learning);
  frame = 0;
  EXPECT_EQ(flashesToDecision(q, frame), 16);
}

TEST(Paradigm, DynamicStoppingEndsFlashingAfterTheMinimumSequences) {
  ParadigmSettings s = fast();
  s.sequences = 10;
  s.min_sequences = 2;
  Paradigm p(s, 4, 3, 3, 4);
  std::int64_t frame = 0;
  p.start(false);
  p.requestStopFlashing();
  const auto events = runUntil(p, frame, [&] { return p.awaitingDecision(); });
  EXPECT_EQ(std::count_if(events.begin(), events.end(),
                          [](const ParadigmEvent& e) { return e.kind == Kind::Flash; }),
            8);
}

TEST(Paradigm, PauseAbortEmergencyStopAndRobotFaults) {
  Paradigm p(fast(), 4, 3, 3, 5);
  std::int64_t frame = 0;
  p.start(false);
  runUntil(p, frame, [&] { return frame >= 20; });
  p.pause();
  EXPECT_EQ(p.phase(), Phase::Paused);
  for (int i = 0; i < 50; ++i) EXPECT_TRUE(p.frame(frame++).lit.empty());
  p.resume();
  EXPECT_EQ(p.phase(), Phase::ObjectFlashing);
  runUntil(p, frame, [&] { return p.awaitingDecision(); });
  p.decide(choose(0, {1}));
  runUntil(p, frame, [&] { return p.phase() == Phase::Grasping; });
  // The grasp fails: the paradigm waits for the experimenter, then goes on with the next trial.
  p.robotFinished(false, "nothing to grasp");
  EXPECT_EQ(p.phase(), Phase::RobotFault);
  runUntil(p, frame, [&] { return frame >= 400; });
  EXPECT_EQ(p.phase(), Phase::RobotFault);
  p.resume();
  EXPECT_EQ(p.phase(), Phase::ObjectFlashing);
  EXPECT_EQ(p.trial(), 2);
  p.emergencyStop();
  auto events = p.takeEvents();
  EXPECT_TRUE(std::any_of(events.begin(), events.end(),
                          [](const ParadigmEvent& e) { return e.kind == Kind::RobotStop; }));
  EXPECT_EQ(p.phase(), Phase::EmergencyStop);
  EXPECT_TRUE(p.frame(frame++).lit.empty());
  p.abort();
  EXPECT_EQ(p.phase(), Phase::Aborted);
}

// After an emergency stop during a grasp: Retry step asks for the same grasp again (no new
// trial); after a stop during the put-down, Skip trial ends the trial and the next one starts.
TEST(Paradigm, RetryStepAsksForTheInterruptedGraspAgainAndSkipTrialEndsTheTrial) {
  Paradigm p(fast(), 4, 3, 3, 6);
  std::int64_t frame = 0;
  p.start(false);
  runUntil(p, frame, [&] { return p.awaitingDecision(); });
  p.decide(choose(2, {3}));
  runUntil(p, frame, [&] { return p.phase() == Phase::Grasping; });
  p.emergencyStop();
  p.takeEvents();
  ASSERT_EQ(p.interrupted(), Phase::Grasping);
  p.retryStep();
  auto events = p.takeEvents();
  EXPECT_EQ(p.phase(), Phase::Grasping);
  EXPECT_EQ(p.trial(), 1);
  const auto grasp = std::find_if(events.begin(), events.end(), [](const ParadigmEvent& e) {
    return e.kind == Kind::RobotGrasp;
  });
  ASSERT_NE(grasp, events.end());
  EXPECT_EQ(grasp->object, 3);  // the object selected before the stop
  p.robotFinished(true, "");
  runUntil(p, frame, [&] { return p.awaitingDecision(); });
  p.decide(choose(4, {2, 5}));
  runUntil(p, frame, [&] { return p.phase() == Phase::Dropping; });
  p.robotFinished(false, "stopped");
  ASSERT_EQ(p.interrupted(), Phase::Dropping);
  p.skipTrial();
  events = p.takeEvents();
  const auto done = std::find_if(events.begin(), events.end(),
                                 [](const ParadigmEvent& e) { return e.kind == Kind::TrialDone; });
  ASSERT_NE(done, events.end());
  EXPECT_NE(done->text.find("skipped"), std::string::npos) << done->text;
  EXPECT_EQ(p.trial(), 2);
  EXPECT_EQ(p.phase(), Phase::ObjectFlashing);
  // Neither acts outside a stop or a fault.
  p.skipTrial();
  p.retryStep();
  EXPECT_EQ(p.trial(), 2);
  EXPECT_EQ(p.phase(), Phase::ObjectFlashing);
}

// A display that manages a frame every 28 ms, not the 16.7 ms of its nominal 60 Hz: no frame shows
// two flashes, every flash is shown, and each comes at least one SOA after the previous onset and
// the dark gap after its end; a flash lasting a frame longer (84 ms) and its successor waiting for
// the next frame, the SOA is under two frames more than the paradigm's (the schedule slips rather
// than squeezes).
TEST(Paradigm, OnASlowDisplayEachSoaIsAtLeastTheParadigmsAndUnderTwoFramesMore) {
  ParadigmSettings s = fast();
  Paradigm p(s, 4, 3, 3, 5);
  p.start(false);
  const double period = 0.028;
  std::vector<double> onsets;
  int frames_with_two = 0, lit_frames = 0;
  for (std::int64_t frame = 0; frame < 200; ++frame) {
    const double due = frame * period;
    const FrameStimulus shown = p.frame(frame, due);
    frames_with_two += shown.lit.size() > 1;
    lit_frames += !shown.lit.empty();
    for (const ParadigmEvent& e : p.takeEvents())
      if (e.kind == Kind::Flash) onsets.push_back(due);
  }
  ASSERT_EQ(onsets.size(), 12u);  // 3 sequences of 4 objects
  const double soa = s.soaSeconds();
  // Flashing starts a nominal frame after start() (frame 0, at 0 s).
  EXPECT_GE(onsets[0], 1.0 / s.display_hz - 1e-9);
  EXPECT_LT(onsets[0], 1.0 / s.display_hz + period);
  for (size_t i = 1; i < onsets.size(); ++i) {
    EXPECT_GE(onsets[i] - onsets[i - 1], soa - 1e-9) << i;
    EXPECT_LT(onsets[i] - onsets[i - 1], soa + 2 * period) << i;
  }
  EXPECT_EQ(frames_with_two, 0);
  // 66.7 ms of flash on 28 ms frames: 2 or 3 frames each.
  EXPECT_GE(lit_frames, 24);
  EXPECT_LE(lit_frames, 36);
}

// Frames late at random (a loaded machine, a slow display: 0.1 to 5 periods late, a fifth of
// them), over a whole calibration run: no two stimuli are ever lit together, a flash never starts
// on the frame right after a lit one, and every flash follows the previous one by at least the
// SOA and at least the configured dark gap after it went dark; the schedule slips instead.
TEST(Paradigm, OnLateFramesFlashesNeverSqueezeTheirSoaOrGap) {
  ParadigmSettings s = fast();
  s.calibration_selections = 4;
  Paradigm p(s, 4, 3, 3, 5);
  p.start(true);
  const double period = 1.0 / s.display_hz;
  const double gap = s.soaSeconds() - s.flashSeconds();  // the dark gap, in whole frames
  std::uint32_t state = 77;
  auto unit = [&] {
    state = state * 1664525u + 1013904223u;
    return (state >> 8) / 16777216.0;
  };
  double due = 0.0, last_onset = -1.0, last_dark = -1.0;
  bool was_lit = false;
  int onsets = 0, two_lit = 0, gapless = 0, short_soa = 0, short_gap = 0, slipped = 0;
  std::set<int> lit_before;
  for (std::int64_t frame = 0; frame < 4000 && p.phase() != Phase::Training; ++frame) {
    due += period + (unit() < 0.2 ? period * (0.1 + 4.9 * unit()) : 0.0);
    const FrameStimulus shown = p.frame(frame, due);
    if (p.awaitingDecision()) p.decide(Decision{});  // calibration: the next cue
    two_lit += shown.lit.size() > 1;
    if (!shown.lit.empty() && !was_lit) {
      ++onsets;
      gapless += last_dark >= 0.0 && last_dark == due;  // never: a dark frame comes between
      if (last_onset >= 0.0) {
        short_soa += due - last_onset < s.soaSeconds() - 1e-9;
        slipped += due - last_onset > s.soaSeconds() + period / 2;
      }
      if (last_dark >= 0.0) short_gap += due - last_dark < gap - 1e-9;
      last_onset = due;
    }
    if (shown.lit.empty() && was_lit) last_dark = due;
    // Lit on the frame right after another stimulus was lit: two flashes run together.
    for (int code : shown.lit) gapless += !lit_before.empty() && !lit_before.count(code);
    lit_before = shown.lit;
    was_lit = !shown.lit.empty();
    p.takeEvents();
  }
  EXPECT_EQ(p.phase(), Phase::Training);
  EXPECT_EQ(onsets, 4 * 3 * 4);  // 4 selections, 3 sequences, 4 stimuli
  EXPECT_EQ(two_lit, 0);
  EXPECT_EQ(gapless, 0);
  EXPECT_EQ(short_soa, 0);
  EXPECT_EQ(short_gap, 0);
  EXPECT_GT(slipped, 0);  // the late frames did make the schedule slip
}

// A frame can reach the screen later than it was due (the process or the display held up). The
// screen's own SOA and dark gap, measured on the frames as presented, are never shorter than the
// paradigm's: a late dark frame or onset moves the next flash with it.
TEST(Paradigm, OnFramesPresentedLateTheScreenNeverShowsAShorterSoaOrGap) {
  ParadigmSettings s = fast();
  s.calibration_selections = 4;
  Paradigm p(s, 4, 3, 3, 5);
  p.start(true);
  const double period = 1.0 / s.display_hz;
  const double gap = s.soaSeconds() - s.flashSeconds();
  std::uint32_t state = 91;
  auto unit = [&] {
    state = state * 1664525u + 1013904223u;
    return (state >> 8) / 16777216.0;
  };
  double clock = 0.0, last_shown = -1.0, last_onset = -1.0, last_dark = -1.0;
  bool was_lit = false;
  int onsets = 0, short_soa = 0, short_gap = 0;
  for (std::int64_t frame = 0; frame < 6000 && p.phase() != Phase::Training; ++frame) {
    // Due a period after the last frame was shown (as the window's session has it); shown then,
    // or, one frame in five, up to three periods later.
    clock += period;
    const double due = last_shown < 0.0 ? clock : std::max(clock, last_shown + period);
    const FrameStimulus shown = p.frame(frame, due);
    if (p.awaitingDecision()) p.decide(Decision{});
    const double at = due + (unit() < 0.2 ? period * 3.0 * unit() : 0.0);
    p.presented(frame, at);
    last_shown = clock = at;
    if (!shown.lit.empty() && !was_lit) {
      ++onsets;
      if (last_onset >= 0.0) short_soa += at - last_onset < s.soaSeconds() - 1e-9;
      if (last_dark >= 0.0) short_gap += at - last_dark < gap - 1e-9;
      last_onset = at;
    }
    if (shown.lit.empty() && was_lit) last_dark = at;
    was_lit = !shown.lit.empty();
    p.takeEvents();
  }
  EXPECT_EQ(p.phase(), Phase::Training);
  EXPECT_EQ(onsets, 4 * 3 * 4);
  EXPECT_EQ(short_soa, 0);
  EXPECT_EQ(short_gap, 0);
}

// The timing check's paradigm: cued calibration selections that go on, never to training.
TEST(Paradigm, FlashesOnlyNeverEndsTheCalibrationRun) {
  ParadigmSettings s = fast();  // 2 calibration selections
  s.flashes_only = true;
  Paradigm p(s, 4, 3, 3, 9);
  p.start(false);  // even when a model exists
  std::int64_t frame = 0;
  int selections = 0, flashes = 0;
  for (; frame < 60 * 60 && p.phase() != Phase::Training; ++frame) {
    p.frame(frame);
    for (const ParadigmEvent& e : p.takeEvents()) flashes += e.kind == Kind::Flash;
    if (p.awaitingDecision()) {
      p.decide(choose(0, {1}));
      ++selections;
    }
  }
  EXPECT_NE(p.phase(), Phase::Training);
  EXPECT_GE(selections, 5);
  EXPECT_GE(flashes, selections * 3 * 4);  // every decided selection had its 3 sequences of 4
}

ParadigmSettings withErrp() {
  ParadigmSettings s = fast();
  s.errp = true;
  s.errp_calibration_feedbacks = 8;
  s.errp_wrong_rate = 0.25;
  return s;
}

// The calibration run ends with its ErrP block: each feedback shows the cued object or, for the
// planned share, another one; the feedback is an event of its own, and training comes after.
TEST(ParadigmErrp, TheCalibrationRunEndsWithFeedbacksAQuarterOfThemWrong) {
  Paradigm p(withErrp(), 4, 3, 3, 7);
  std::int64_t frame = 0;
  p.start(true);
  std::vector<ParadigmEvent> events;
  for (int i = 0; i < 20000 && p.phase() != Phase::Training; ++i) {
    const FrameStimulus shown = p.frame(frame++);
    if (shown.phase == Phase::CalibrationFeedback) {
      EXPECT_TRUE(shown.selected_object.has_value());
      EXPECT_FALSE(shown.cued_object.has_value());  // the cue is gone while the feedback shows
    }
    for (auto& e : p.takeEvents()) events.push_back(e);
    if (p.awaitingDecision()) p.decide(choose(0, {1}));
  }
  ASSERT_EQ(p.phase(), Phase::Training);
  int feedbacks = 0, wrong = 0;
  std::optional<int> cued;
  for (const ParadigmEvent& e : events) {
    if (e.kind == Kind::SelectionStarted && !e.codes.empty()) cued = *e.codes.begin();
    if (e.kind != Kind::Feedback) continue;
    ++feedbacks;
    ASSERT_TRUE(e.error.has_value());
    ASSERT_TRUE(cued.has_value());
    EXPECT_EQ(*e.error, e.codes != std::set<int>{*cued});
    wrong += *e.error;
  }
  EXPECT_EQ(feedbacks, 8);
  EXPECT_EQ(wrong, 2);
}

// Online, the robot waits for the ErrP verdict however long the selection has been shown.
TEST(ParadigmErrp, NoGraspBeforeTheVerdictAndARejectedSelectionTakesTheRunnerUp) {
  Paradigm p(withErrp(), 4, 3, 3, 1);
  std::int64_t frame = 0;
  p.start(false);
  runUntil(p, frame, [&] { return p.awaitingDecision(); });
  Decision d = choose(1, {2});
  d.certainty = 0.5;
  d.runner_up_codes = {3};
  d.runner_up_choice = 2;
  d.runner_up_certainty = 0.4;  // 0.8 of what the rejected choice leaves
  p.decide(d);
  auto events = runUntil(
      p, frame, [] { return false; }, 300);  // 5 s, well past result_s
  EXPECT_TRUE(p.awaitingErrpVerdict());
  EXPECT_EQ(std::count_if(events.begin(), events.end(),
                          [](const ParadigmEvent& e) { return e.kind == Kind::RobotGrasp; }),
            0);
  EXPECT_EQ(std::count_if(events.begin(), events.end(),
                          [](const ParadigmEvent& e) { return e.kind == Kind::Feedback; }),
            1);
  p.errpVerdict(true);
  // The rejected choice is cleared at once, and for pause_s nothing is shown as selected (so the
  // runner-up's ErrP epoch starts clear of the rejected one's response).
  const std::int64_t rejected_at = frame;
  EXPECT_FALSE(p.frame(frame++).selected_object.has_value());
  const auto is_made = [](const ParadigmEvent& e) { return e.kind == Kind::SelectionMade; };
  events = p.takeEvents();
  EXPECT_EQ(std::count_if(events.begin(), events.end(), is_made), 0);
  const int pause_frames =
      static_cast<int>(std::lround(p.settings().pause_s * p.settings().display_hz));
  events = runUntil(
      p, frame, [&] { return frame - rejected_at >= pause_frames - 2; }, 200);
  EXPECT_EQ(std::count_if(events.begin(), events.end(), is_made), 0);
  EXPECT_FALSE(p.awaitingErrpVerdict());  // nothing to judge while nothing is shown
  events = runUntil(
      p, frame, [] { return false; }, 4);
  auto made = std::find_if(events.begin(), events.end(), is_made);
  ASSERT_NE(made, events.end());
  EXPECT_EQ(made->object, 3);
  EXPECT_EQ(made->text, "runner-up");
  EXPECT_EQ(p.corrections(), 1);
  // The runner-up is shown as feedback and judged in turn; accepted, the robot grasps it.
  EXPECT_TRUE(p.awaitingErrpVerdict());
  p.errpVerdict(false);
  events = runUntil(
      p, frame, [&] { return p.phase() == Phase::Grasping; }, 200);
  auto grasp = std::find_if(events.begin(), events.end(),
                            [](const ParadigmEvent& e) { return e.kind == Kind::RobotGrasp; });
  ASSERT_NE(grasp, events.end());
  EXPECT_EQ(grasp->object, 3);
}

// A runner-up without enough evidence: the selection is made again, with more sequences; after
// the most corrections the trial is skipped and the robot never moves.
TEST(ParadigmErrp, WithoutACloseRunnerUpTheSelectionIsRepeatedThenTheTrialSkipped) {
  ParadigmSettings s = withErrp();
  s.errp_max_corrections = 1;
  Paradigm p(s, 4, 3, 3, 1);
  std::int64_t frame = 0;
  p.start(false);
  runUntil(p, frame, [&] { return p.awaitingDecision(); });
  Decision d = choose(1, {2});
  d.certainty = 0.6;
  d.runner_up_codes = {3};
  d.runner_up_choice = 2;
  d.runner_up_certainty = 0.1;  // 0.25 of the rest: not close
  p.decide(d);
  runUntil(
      p, frame, [] { return false; }, 2);
  p.errpVerdict(true);
  int flashes = 0;
  auto events = runUntil(p, frame, [&] { return p.awaitingDecision(); });
  for (const ParadigmEvent& e : events) flashes += e.kind == Kind::Flash;
  EXPECT_EQ(flashes, 4 * 6);  // twice the 3 sequences, all of them
  EXPECT_EQ(p.phase(), Phase::ObjectFlashing);
  p.decide(d);
  runUntil(
      p, frame, [] { return false; }, 2);
  p.errpVerdict(true);
  events = runUntil(
      p, frame, [] { return false; }, 2);
  EXPECT_TRUE(std::any_of(events.begin(), events.end(), [](const ParadigmEvent& e) {
    return e.kind == Kind::ErrpCorrection && e.text == "skip";
  }));
  EXPECT_TRUE(std::none_of(events.begin(), events.end(),
                           [](const ParadigmEvent& e) { return e.kind == Kind::RobotGrasp; }));
  EXPECT_EQ(p.trial(), 2);
}

// The runner-up of a row/column selection differs in the less certain of row and column; the
// ErrP posterior follows the score model and the prior.
TEST(ParadigmErrp, TheRunnerUpCellAndTheErrorPosterior) {
  const ParadigmLayout grid = ParadigmLayout::matrix(3, 3, 0.18);
  ScoreModel model{1.0, -1.0, 1.0};
  SelectionAccumulator a(grid, model);
  for (int code = 1; code <= 6; ++code) a.add(code, -1.0);
  a.add(2, 3.0);  // row 2, very sure
  a.add(6, 1.0);  // column 3, less sure than row 2
  a.add(5, 0.6);  // column 2, close behind
  const Decision d = a.decide();
  EXPECT_EQ(d.codes, (std::set<int>{2, 6}));
  EXPECT_EQ(d.runner_up_codes, (std::set<int>{2, 5}));
  EXPECT_EQ(d.runner_up_choice, 1 * 3 + 1);
  EXPECT_LT(d.runner_up_certainty, d.certainty);
  // A score at the error class's mean with an even prior: the likelihood ratio decides.
  const ScoreModel errp{2.0, 0.0, 1.0};
  EXPECT_NEAR(errorPosterior(errp, 1.0, 0.5), 0.5, 1e-12);
  EXPECT_NEAR(errorPosterior(errp, 2.0, 0.5), 1.0 / (1.0 + std::exp(-2.0)), 1e-12);
  EXPECT_LT(errorPosterior(errp, 2.0, 0.05), errorPosterior(errp, 2.0, 0.5));
  EXPECT_NEAR(errorPosterior(errp, 1.0, 0.0), 0.01, 1e-12);  // the prior is kept off 0
}

// In phase 2 the arm holds the object: when no cell is accepted it is put back, never left in
// the gripper for the next trial.
TEST(ParadigmErrp, WhenNoCellIsAcceptedTheObjectGoesBackWhereItWasTaken) {
  ParadigmSettings s = withErrp();
  s.errp_max_corrections = 0;
  Paradigm p(s, 4, 3, 3, 1);
  std::int64_t frame = 0;
  p.start(false);
  runUntil(p, frame, [&] { return p.awaitingDecision(); });
  p.decide(choose(0, {1}));
  runUntil(
      p, frame, [] { return false; }, 2);
  p.errpVerdict(false);
  runUntil(p, frame, [&] { return p.phase() == Phase::Grasping; });
  p.robotFinished(true, "");
  runUntil(p, frame, [&] { return p.awaitingDecision(); });
  p.decide(choose(4, {2, 5}));
  runUntil(
      p, frame, [] { return false; }, 2);
  p.errpVerdict(true);
  const auto events = runUntil(
      p, frame, [] { return false; }, 2);
  auto drop = std::find_if(events.begin(), events.end(),
                           [](const ParadigmEvent& e) { return e.kind == Kind::RobotDrop; });
  ASSERT_NE(drop, events.end());
  EXPECT_TRUE(drop->give_back);
  EXPECT_EQ(p.phase(), Phase::Dropping);
}

}  // namespace
}  // namespace arbci::bci

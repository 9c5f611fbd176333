// The paradigm stage on hand-built records: the other stages' parts (tracking's world, the P300
// stage's counts and decision, the robot's notes, the ErrP's scores, the EEG source's fault) are
// written by the test, and what the stage writes and posts is checked — the calibration run with
// its cues and training, a trial from selection to put-down, a grasp the robot refuses and its
// retry, flashes withheld for objects out of view (and the calibration selection retaken), the
// pauses for the EEG and for view, an occupied cell, the experimenter's stop and end, the ErrP's
// veto.
#include <gtest/gtest.h>

#include <functional>
#include <utility>

#include "arbci/session/record_text.h"
#include "arbci/session/stages/p300_stage.h"
#include "arbci/session/stages/paradigm_stage.h"
#include "arbci/session/trial_intents.h"
#include "support/flash_driver.h"
#include "support/stage_bench.h"

namespace arbci::session {
namespace {

using Kind = RobotPart::Note::Kind;

// A model the P300 stage trained on a simulated subject's calibration (once for all tests).
std::shared_ptr<const bci::P300Model> trainedModel() {
  static const std::shared_ptr<const bci::P300Model> model = [] {
    test::StageBench bench("paradigm_model");
    test::FlashDriver eeg(bench, 4);
    P300Settings s;
    s.info = eeg.info();
    s.flash_s = 4.0 / 60.0;
    s.object_stimuli = 4;
    P300Stage stage(s, bench.services());
    for (int n = 1; n <= 3; ++n) eeg.selection(stage, n, n, true, 5);
    bench.record.requests.push_back(TrainRequest{"slda"});
    eeg.step(stage);
    return bench.previous.p300.model;
  }();
  return model;
}

SessionConfig shortSession() {
  SessionConfig c;
  c.gates.review = false;  // the review has its own tests
  bci::ParadigmSettings& p = c.paradigm;
  p.calibration_selections = 2;
  p.calibration_sequences = 1;
  p.sequences = 2;
  p.certainty = 0.0;
  p.cue_s = 0.3;
  p.result_s = 0.3;
  p.pause_s = 0.2;
  p.trials = 1;
  p.no_view_pause_s = 2.0;
  return c;
}

class ParadigmStageTest : public ::testing::Test {
 protected:
  explicit ParadigmStageTest(SessionConfig config = shortSession(), bool experimenter = true)
      : config_(std::move(config)),
        bench_("paradigm"),
        stage_(
            ParadigmStageSettings{config_.paradigm, config_.world, "slda", intendedTrials(config_),
                                  11, 0.5, bench_.folder() / "model.json", experimenter, 0.5,
                                  config_.gates.review && experimenter, config_.gates.min_auc,
                                  config_.gates.max_retakes, config_.learnsFromUse()},
            bench_.services()) {}

  // The objects the cameras see now (all but `hidden`), at their places; the reference seen.
  void see(CycleRecord& r) {
    vision::WorldModel world;
    std::map<int, vision::PoseEstimate> poses;
    vision::PoseEstimate reference;
    // The camera 1 m above the reference (its default place: (0, 0.90, 0) in the robot's frame).
    reference.pose = {cv::Matx33d::eye(), cv::Vec3d(0.0, 0.0, 1.0)};
    if (!reference_hidden_) poses[0] = reference;
    for (const WorldObjectSettings& o : config_.world.objects) {
      if (hidden_.count(o.id)) continue;
      vision::PoseEstimate p;
      p.pose = {cv::Matx33d::eye(),
                cv::Vec3d(o.position[0], o.position[1] - 0.9, 1.0 + o.position[2])};
      poses[o.id] = p;
    }
    world_.update(r.time_s, poses);
    r.tracking.world = std::make_shared<const vision::WorldModel>(world_);
    r.tracking.max_pose_age_s = 0.5;
  }
  // One cycle: the world seen, the P300 stage's counts for the current selection (every flash
  // scored, deciding `decide` when given), the robot's `notes`; then the next.
  void cycle(const std::function<void(CycleRecord&)>& more = {}) {
    CycleRecord& r = bench_.record;
    see(r);
    r.p300.selection = selection_;
    r.p300.presented = r.p300.scored = flashes_;
    r.p300.model = model_;
    r.p300.decision.codes = {decide_};
    r.p300.decision.choice = decide_ - 1;
    r.p300.decision.certainty = certainty_;
    r.robot.status = robot_;
    r.errp.model = errp_model_;
    if (more) more(r);
    bench_.step(stage_);
    const ParadigmPart& p = bench_.record.paradigm;
    if (p.selection_started) {
      selection_ = p.selection_started->selection;
      flashes_ = 0;
    }
    flashes_ += static_cast<int>(p.first_shown.size());
    for (const Request& posted : bench_.record.posted) posted_.push_back(posted);
    bench_.next();
  }
  // Cycles until the paradigm reaches `phase` (at most `seconds`); whether it did.
  bool until(bci::Phase phase, double seconds = 30.0) {
    for (int i = 0; i < seconds * 60 && bench_.previous.paradigm.phase != phase; ++i) cycle();
    return bench_.previous.paradigm.phase == phase;
  }
  template <class T>
  std::vector<T> postedOf() const {
    std::vector<T> out;
    for (const Request& r : posted_)
      if (const T* t = std::get_if<T>(&r)) out.push_back(*t);
    return out;
  }
  void note(Kind kind, bool success, const std::string& text = "") {
    cycle([&](CycleRecord& r) { r.robot.notes.push_back({kind, success, text}); });
  }
  bool annotated(const std::string& prefix) const {
    for (const bci::Annotation& a : annotations_)
      if (a.text.rfind(prefix, 0) == 0) return true;
    return false;
  }
  void begin() {
    bench_.record.requests.push_back(BeginRequest{});
    cycle();
  }

  SessionConfig config_;
  test::StageBench bench_;
  ParadigmStage stage_;
  vision::WorldModel world_;
  std::set<int> hidden_;
  bool reference_hidden_ = false;
  std::shared_ptr<const bci::P300Model> model_, errp_model_;
  std::optional<robot::StatusPayload> robot_;
  int selection_ = 0, flashes_ = 0, decide_ = 1;
  double certainty_ = 0.9;  // of every decision
  std::vector<Request> posted_;
  std::vector<bci::Annotation> annotations_;
};

TEST_F(ParadigmStageTest, TheCalibrationCuesEachTargetLabelsItsFlashesAndIsTrainedOn) {
  begin();
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::CalibrationCue);
  const auto& started = bench_.previous.paradigm.selection_started;
  ASSERT_TRUE(started.has_value());
  ASSERT_TRUE(started->target.has_value());
  const int target = *started->target;
  ASSERT_TRUE(until(bci::Phase::CalibrationFlashing));
  int targets = 0, others = 0;
  for (int i = 0; i < 120 && targets + others < 4; ++i) {
    cycle();
    for (const Flash& f : bench_.previous.paradigm.first_shown) {
      EXPECT_TRUE(f.known);
      EXPECT_EQ(f.target, f.code == target);
      (f.target ? targets : others) += 1;
    }
  }
  EXPECT_EQ(targets, 1);
  EXPECT_EQ(others, 3);
  ASSERT_TRUE(until(bci::Phase::Training));
  cycle();  // the paradigm's event is taken the cycle after its decision
  ASSERT_EQ(postedOf<TrainRequest>().size(), 1u);
  EXPECT_EQ(postedOf<TrainRequest>()[0].method, "slda");
  // The P300 stage's training comes in: the model is saved and the first trial begins.
  model_ = trainedModel();
  cycle([](CycleRecord& r) {
    r.p300.trained = bci::EvaluationReport{};
    r.p300.trained->auc = 0.9;
    r.p300.trained_on = {1, 2};
  });
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::ObjectFlashing);
  EXPECT_EQ(bench_.previous.paradigm.trial, 1);
  EXPECT_TRUE(std::filesystem::exists(bench_.folder() / "model.json"));
  EXPECT_EQ(bench_.logged("trained").size(), 1u);
  EXPECT_TRUE(bench_.toldOf("classifier trained (slda)"));
}

TEST_F(ParadigmStageTest, AFailedTrainingAbortsWithTheReason) {
  begin();
  ASSERT_TRUE(until(bci::Phase::Training));
  cycle();
  cycle([](CycleRecord& r) { r.p300.training_error = "too few epochs"; });
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::Aborted);
  EXPECT_EQ(bench_.previous.paradigm.status, "training failed: too few epochs");
  EXPECT_TRUE(bench_.toldOf("training failed: too few epochs"));
}

TEST_F(ParadigmStageTest, ATrialSelectsGraspsPutsDownAndEndsTheRun) {
  model_ = trainedModel();  // a model from the start: no calibration
  const TrialIntent intent = intendedTrials(config_)[0];
  // The intended object's code, as offered.
  for (size_t k = 0; k < config_.world.objects.size(); ++k)
    if (config_.world.objects[k].id == intent.object) decide_ = static_cast<int>(k) + 1;
  begin();
  ASSERT_EQ(bench_.previous.paradigm.phase, bci::Phase::ObjectFlashing);
  // Online flashes are labelled by the intention (the simulated subject's).
  ASSERT_TRUE(until(bci::Phase::ObjectSelected));
  ASSERT_TRUE(until(bci::Phase::Grasping));
  ASSERT_EQ(postedOf<GraspRequest>().size(), 1u);
  const GraspRequest grasp = postedOf<GraspRequest>()[0];
  EXPECT_EQ(grasp.object, intent.object);
  ASSERT_TRUE(grasp.at.has_value());
  EXPECT_LT(grasp.pose_age_s, 0.1);
  EXPECT_FALSE(grasp.retry);
  // The robot's answer, on the record: the grid's flashing.
  note(Kind::Finished, true);
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::CellFlashing);
  decide_ = 0;  // no such code: the decision below is the cell's
  cycle([&](CycleRecord& r) {
    r.p300.decision.codes = {intent.row, config_.world.grid.rows + intent.column};
    r.p300.decision.choice = (intent.row - 1) * config_.world.grid.columns + intent.column - 1;
  });
  for (int i = 0; i < 60 * 20 && bench_.previous.paradigm.phase != bci::Phase::Dropping; ++i) {
    cycle([&](CycleRecord& r) {
      r.p300.decision.codes = {intent.row, config_.world.grid.rows + intent.column};
      r.p300.decision.choice = (intent.row - 1) * config_.world.grid.columns + intent.column - 1;
    });
  }
  ASSERT_EQ(bench_.previous.paradigm.phase, bci::Phase::Dropping);
  ASSERT_EQ(postedOf<DropRequest>().size(), 1u);
  const DropRequest drop = postedOf<DropRequest>()[0];
  EXPECT_EQ(drop.cell, std::make_pair(intent.row, intent.column));
  EXPECT_FALSE(drop.give_back);
  note(Kind::Outcome, true, "placed");
  cycle([](CycleRecord& r) {
    RobotPart::Note placed{Kind::Placement, true, ""};
    placed.trial = 1;
    placed.error_m = 0.0012;
    r.robot.notes.push_back(placed);
  });
  note(Kind::PutDownEnded, true);
  ASSERT_TRUE(until(bci::Phase::Finished, 2.0));
  const auto& trials = *bench_.previous.paradigm.trials;
  ASSERT_EQ(trials.size(), 1u);
  EXPECT_EQ(trials[0].selected_object, intent.object);
  EXPECT_EQ(trials[0].selected_cell, std::make_pair(intent.row, intent.column));
  EXPECT_EQ(trials[0].outcome, "placed");
  EXPECT_NEAR(trials[0].placement_error_m, 0.0012, 1e-12);
  EXPECT_EQ(trials[0].robot_object, intent.object);
  nlohmann::json summary;
  stage_.report(summary);
  EXPECT_EQ(summary["objects"]["accuracy"], 1.0);
  EXPECT_EQ(summary["cells"]["accuracy"], 1.0);
  EXPECT_EQ(bench_.logged("selection").size(), 2u);
}

TEST_F(ParadigmStageTest, AWrongSelectionIsSaidAndTheTrialCarriesOnWithIt) {
  model_ = trainedModel();
  const TrialIntent intent = intendedTrials(config_)[0];
  // Decide an object that is not the intended one.
  for (size_t k = 0; k < config_.world.objects.size(); ++k)
    if (config_.world.objects[k].id != intent.object) decide_ = static_cast<int>(k) + 1;
  begin();
  ASSERT_TRUE(until(bci::Phase::Grasping));
  EXPECT_NE(postedOf<GraspRequest>()[0].object, intent.object);
  EXPECT_TRUE(
      bench_.toldOf("selection of the object in trial 1 differs from the intended one; "
                    "carrying on"));
  const auto selections = bench_.logged("selection");
  ASSERT_EQ(selections.size(), 1u);
  EXPECT_FALSE(selections[0]["correct"].get<bool>());
}

TEST_F(ParadigmStageTest, OnlyTheObjectsTheCamerasSeeAreOffered) {
  model_ = trainedModel();
  const int unseen = config_.world.objects[1].id;
  hidden_ = {unseen};
  begin();
  const std::vector<size_t>& slots = bench_.previous.paradigm.slots;
  EXPECT_EQ(slots.size(), config_.world.objects.size() - 1);
  for (size_t slot : slots) EXPECT_NE(config_.world.objects[slot].id, unseen);
  // The recording says what each code now stands for.
  bool mapped = false;
  for (const bci::Annotation& a : bench_.previous.annotations)
    mapped |= a.text.rfind("StimulusCodeMap ", 0) == 0 &&
              a.text.find("object " + std::to_string(unseen)) == std::string::npos;
  EXPECT_TRUE(mapped);
  EXPECT_EQ(bench_.logged("objects_in_view").size(), 1u);
}

TEST_F(ParadigmStageTest, HowFreshTheGraspedObjectsPoseStayedIsFiledWithTheTrial) {
  model_ = trainedModel();
  begin();
  ASSERT_TRUE(until(bci::Phase::Grasping));
  const int object = postedOf<GraspRequest>()[0].object;
  // The arm comes down on it for a second while the cameras keep seeing it, then holds it.
  robot::StatusPayload status;
  status.current_command = robot::MessageType::Grasp;
  robot_ = status;
  for (int i = 0; i < 60; ++i) cycle([&](CycleRecord& r) { r.robot.grasped = object; });
  status.holding = object;
  robot_ = status;
  cycle([&](CycleRecord& r) { r.robot.grasped = object; });
  const auto sights = bench_.logged("grasp_view");
  ASSERT_EQ(sights.size(), 1u);
  EXPECT_EQ(sights[0]["object"], object);
  EXPECT_NEAR(sights[0]["seconds"].get<double>(), 1.0, 0.05);
  EXPECT_FALSE(sights[0]["never_seen"].get<bool>());
  const TrialRecord& trial = (*bench_.previous.paradigm.trials)[0];
  ASSERT_TRUE(trial.grasp_pose_age_max_s.has_value());
  EXPECT_LT(*trial.grasp_pose_age_max_s, 0.05);
}

TEST_F(ParadigmStageTest, AGraspTheRobotRefusesIsAFaultWithItsReasonAndRetryAsksAgain) {
  model_ = trainedModel();
  begin();
  ASSERT_TRUE(until(bci::Phase::Grasping));
  const std::string why =
      "object 20: tracking lost (pose 1.2 s old), not grasped; Retry step once it is seen again";
  cycle([&](CycleRecord& r) {
    r.robot.notes.push_back({Kind::Outcome, false, why});
    r.robot.notes.push_back({Kind::Finished, false, why});
  });
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::RobotFault);
  EXPECT_EQ(bench_.previous.paradigm.interrupted, bci::Phase::Grasping);
  EXPECT_EQ(bench_.previous.paradigm.status, why);
  EXPECT_EQ((*bench_.previous.paradigm.trials)[0].outcome, why);
  bench_.record.requests.push_back(RetryStepRequest{});
  cycle();
  ASSERT_EQ(postedOf<GraspRequest>().size(), 2u);
  EXPECT_TRUE(postedOf<GraspRequest>()[1].retry);
  EXPECT_EQ(postedOf<RobotResetIfLatchedRequest>().size(), 1u);
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::Grasping);
  EXPECT_EQ(bench_.previous.paradigm.status, "");
  // The fault is on the trial's record, from when it came to when the retry went on.
  const auto& interruptions = (*bench_.previous.paradigm.trials)[0].interruptions;
  ASSERT_EQ(interruptions.size(), 1u);
  EXPECT_EQ(interruptions[0].kind, "robot fault");
  EXPECT_GT(interruptions[0].resumed_s, interruptions[0].at_s);
}

TEST_F(ParadigmStageTest, AnObjectOutOfViewIsNotFlashedAndTheCalibrationSelectionIsRetaken) {
  begin();
  ASSERT_TRUE(until(bci::Phase::CalibrationFlashing));
  const int first = selection_;
  hidden_ = {config_.world.objects[0].id, config_.world.objects[1].id};
  const double hidden_at = bench_.record.time_s;
  for (int i = 0; i < 120 && bench_.previous.paradigm.phase != bci::Phase::Paused; ++i) {
    cycle();
    for (const bci::Annotation& a : bench_.previous.annotations) annotations_.push_back(a);
    // Their poses stale after the allowed age: the hidden objects' codes no longer flash.
    if (bench_.previous.time_s <= hidden_at + 0.5) continue;
    for (const Flash& f : bench_.previous.paradigm.first_shown) {
      EXPECT_NE(f.code, 1);
      EXPECT_NE(f.code, 2);
    }
  }
  ASSERT_EQ(bench_.previous.paradigm.phase, bci::Phase::Paused);
  EXPECT_TRUE(annotated("Tracking lost object"));
  EXPECT_FALSE(bench_.logged("flash_withheld").empty());
  EXPECT_NE(bench_.previous.paradigm.status.find("retaken once every object has been in view"),
            std::string::npos)
      << bench_.previous.paradigm.status;
  // In view again for a second: the same target cued again, as a new selection.
  hidden_.clear();
  std::optional<SelectionStart> retake;
  for (int i = 0; i < 180 && !retake; ++i) {
    cycle();
    for (const bci::Annotation& a : bench_.previous.annotations) annotations_.push_back(a);
    retake = bench_.previous.paradigm.selection_started;
  }
  ASSERT_TRUE(retake.has_value());
  EXPECT_EQ(retake->retake_of, first);
  EXPECT_EQ(retake->selection, first + 1);
  EXPECT_TRUE(annotated("Tracking regained object"));
  EXPECT_TRUE(annotated("Calibration selection " + std::to_string(first) + " interrupted"));
  EXPECT_EQ(bench_.logged("calibration_retake").size(), 1u);
}

TEST_F(ParadigmStageTest, EveryMarkerLostAtOnceIsAStallThatHoldsTheFlashesWithoutARetake) {
  begin();
  ASSERT_TRUE(until(bci::Phase::CalibrationFlashing));
  const int first = selection_;
  // The machine stalls: the reference and every object gone together.
  for (const WorldObjectSettings& o : config_.world.objects) hidden_.insert(o.id);
  reference_hidden_ = true;
  ASSERT_TRUE(until(bci::Phase::Paused, 2.0));
  EXPECT_NE(bench_.previous.paradigm.status.find("held: every marker vanished at once"),
            std::string::npos)
      << bench_.previous.paradigm.status;
  // Back: the flashes go on at once, in the same selection.
  hidden_.clear();
  reference_hidden_ = false;
  bool retaken = false;
  for (int i = 0; i < 10 && bench_.previous.paradigm.phase != bci::Phase::CalibrationFlashing;
       ++i) {
    cycle();
    retaken |= bench_.previous.paradigm.selection_started.has_value();
  }
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::CalibrationFlashing);
  EXPECT_FALSE(retaken);
  EXPECT_EQ(selection_, first);
  EXPECT_EQ(bench_.previous.paradigm.calibration_retakes, 0);
  EXPECT_EQ(bench_.logged("stall_ended").size(), 1u);
  nlohmann::json summary;
  stage_.report(summary);
  EXPECT_EQ(summary["stalls"]["count"], 1);
}

class RetakeCapTest : public ParadigmStageTest {
 protected:
  static SessionConfig capped() {
    SessionConfig c = shortSession();
    c.gates.max_retakes = 1;
    c.paradigm.calibration_selections = 8;
    return c;
  }
  RetakeCapTest() : ParadigmStageTest(capped()) {}
};

// gates.max_retakes is a hard cap: past it an object out of view has its calibration flashes
// withheld and the selection goes on, said once; the run never loops on retakes nor waits.
TEST_F(RetakeCapTest, PastTheRetakesAllowedSelectionsGoOnWithTheFlashesWithheld) {
  begin();
  // Object 1 leaves the view (a pause, then a retake once it is back).
  ASSERT_TRUE(until(bci::Phase::CalibrationFlashing));
  hidden_ = {config_.world.objects[0].id};
  ASSERT_TRUE(until(bci::Phase::Paused, 5.0));
  hidden_.clear();
  ASSERT_TRUE(until(bci::Phase::CalibrationCue, 5.0));
  EXPECT_EQ(bench_.previous.paradigm.calibration_retakes, 1);
  // It leaves again: no pause now, the selection goes on without its flashes.
  ASSERT_TRUE(until(bci::Phase::CalibrationFlashing));
  hidden_ = {config_.world.objects[0].id};
  bool paused = false;
  for (int i = 0; i < 300; ++i) {
    cycle();
    paused |= bench_.previous.paradigm.phase == bci::Phase::Paused;
  }
  EXPECT_FALSE(paused);
  EXPECT_EQ(bench_.previous.paradigm.calibration_retakes, 1);
  EXPECT_EQ(bench_.logged("retakes_capped").size(), 1u);
  EXPECT_TRUE(bench_.toldOf("no more retakes"));
  nlohmann::json summary;
  stage_.report(summary);
  EXPECT_TRUE(summary["retakes_capped"].get<bool>());
}

class HeadlessParadigmStageTest : public ParadigmStageTest {
 protected:
  HeadlessParadigmStageTest() : ParadigmStageTest(shortSession(), false) {}
};

// Nobody to ask after a grasp that failed (the arm could not follow its path): the arm goes home
// and the run goes on with the next trial, the trial saying what happened; never a stalled run.
TEST_F(HeadlessParadigmStageTest, AFailedGraspWithoutExperimenterSendsTheArmHomeAndGoesOn) {
  model_ = trainedModel();
  begin();
  ASSERT_TRUE(until(bci::Phase::Grasping));
  const std::string why =
      "no joint motion reaches (0.000, 0.727, 0.451) (joint limit or singularity)";
  cycle([&](CycleRecord& r) {
    r.robot.notes.push_back({Kind::Outcome, false, why});
    r.robot.notes.push_back({Kind::Finished, false, why});
  });
  // The next trial, or the end after the last.
  EXPECT_EQ(bench_.previous.paradigm.phase,
            config_.paradigm.trials > 1 ? bci::Phase::ObjectFlashing : bci::Phase::Finished);
  EXPECT_EQ(postedOf<RobotHomeRequest>().size(), 1u);
  const TrialRecord& first = (*bench_.previous.paradigm.trials)[0];
  EXPECT_NE(first.outcome.find("the arm went home and the run went on"), std::string::npos)
      << first.outcome;
  EXPECT_EQ(bench_.logged("recovery").size(), 1u);
  EXPECT_TRUE(bench_.record.end_reason.empty());
}

TEST_F(HeadlessParadigmStageTest, WithNoObjectInViewARunWithoutExperimenterEndsWithTheReason) {
  model_ = trainedModel();
  for (const WorldObjectSettings& o : config_.world.objects) hidden_.insert(o.id);
  begin();
  std::string ended;
  for (int i = 0; i < 60 * 10 && ended.empty(); ++i) {
    cycle();
    ended = bench_.previous.end_reason;
  }
  EXPECT_NE(ended.find("no object in view"), std::string::npos) << ended;
  EXPECT_NE(ended.find("paradigm.no_view_pause_s"), std::string::npos) << ended;
  EXPECT_EQ(bench_.previous.end_kind, "aborted");
}

TEST_F(HeadlessParadigmStageTest, AMarkerCoveredForGoodInCalibrationEndsTheRunWithTheReason) {
  begin();
  ASSERT_TRUE(until(bci::Phase::CalibrationFlashing));
  hidden_ = {config_.world.objects[0].id};
  std::string ended;
  for (int i = 0; i < 60 * 10 && ended.empty(); ++i) {
    cycle();
    ended = bench_.previous.end_reason;
  }
  EXPECT_NE(ended.find("tracking lost"), std::string::npos) << ended;
  EXPECT_NE(ended.find("during calibration"), std::string::npos) << ended;
  EXPECT_NE(ended.find(std::to_string(config_.world.objects[0].id)), std::string::npos) << ended;
}

TEST_F(ParadigmStageTest, AnEegFaultPausesAndTwoSecondsOfSignalResume) {
  model_ = trainedModel();
  begin();
  for (int i = 0; i < 30; ++i) cycle();
  cycle([](CycleRecord& r) { r.eeg.fault = "the LSL stream EEG is gone"; });
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::Paused);
  EXPECT_EQ(bench_.previous.paradigm.status, "paused: the LSL stream EEG is gone");
  for (int i = 0; i < 60; ++i) cycle([](CycleRecord& r) { r.eeg.fault = "still gone"; });
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::Paused);
  for (int i = 0; i < 115; ++i) cycle();
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::Paused);
  ASSERT_TRUE(until(bci::Phase::ObjectFlashing, 0.2));
  EXPECT_EQ(bench_.previous.paradigm.status, "");
  EXPECT_TRUE(bench_.toldOf("resumed: the EEG source delivers again"));
}

TEST_F(ParadigmStageTest, AnObjectOnTheChosenCellSendsTheGraspedObjectBack) {
  model_ = trainedModel();
  const TrialIntent intent = intendedTrials(config_)[0];
  begin();
  ASSERT_TRUE(until(bci::Phase::Grasping));
  note(Kind::Finished, true);
  // Another object stands on the intended cell.
  const cv::Vec3d cell = config_.world.grid.cellCentre(intent.row, intent.column);
  const int grasped = postedOf<GraspRequest>()[0].object;
  for (WorldObjectSettings& o : config_.world.objects) {
    if (o.id != grasped) {
      o.position = {cell[0], cell[1], o.position[2]};
      break;
    }
  }
  for (int i = 0; i < 60 * 20 && bench_.previous.paradigm.phase != bci::Phase::Dropping; ++i) {
    cycle([&](CycleRecord& r) {
      r.robot.grasped = grasped;
      r.p300.decision.codes = {intent.row, config_.world.grid.rows + intent.column};
      r.p300.decision.choice = (intent.row - 1) * config_.world.grid.columns + intent.column - 1;
    });
  }
  ASSERT_EQ(postedOf<DropRequest>().size(), 1u);
  EXPECT_TRUE(postedOf<DropRequest>()[0].give_back);
  const TrialRecord& trial = (*bench_.previous.paradigm.trials)[0];
  EXPECT_EQ(trial.outcome.rfind("returned: cell ", 0), 0u) << trial.outcome;
  EXPECT_TRUE(trial.robot_returned);
  EXPECT_FALSE(trial.robot_cell.has_value());
}

TEST_F(ParadigmStageTest, TheEmergencyStopPostsARobotStopAndEndSessionEndsWithTheReason) {
  model_ = trainedModel();
  begin();
  ASSERT_TRUE(until(bci::Phase::Grasping));
  bench_.record.requests.push_back(EmergencyStopRequest{});
  cycle();
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::EmergencyStop);
  EXPECT_EQ(bench_.previous.paradigm.interrupted, bci::Phase::Grasping);
  EXPECT_EQ(postedOf<RobotStopRequest>().size(), 1u);
  const auto& interruptions = (*bench_.previous.paradigm.trials)[0].interruptions;
  ASSERT_EQ(interruptions.size(), 1u);
  EXPECT_EQ(interruptions[0].kind, "emergency stop");
  EXPECT_LT(interruptions[0].resumed_s, 0.0);  // not over
  bench_.record.requests.push_back(EndSessionRequest{});
  cycle();
  EXPECT_EQ(bench_.previous.end_reason, "ended by the experimenter in: EMERGENCY STOP");
  EXPECT_EQ(bench_.previous.end_kind, "estop");
}

class LearningParadigmStageTest : public ParadigmStageTest {
 protected:
  static SessionConfig learning() {
    SessionConfig c = shortSession();
    c.paradigm.calibration = "none";
    c.paradigm.trials = 2;
    return c;
  }
  explicit LearningParadigmStageTest(SessionConfig config = learning())
      : ParadigmStageTest(std::move(config)) {}
  // The P300 stage's learning as the record carries it: a fit over selections up to `fitted`,
  // one up to `awaited` running, the last fit's decodings and trust.
  void learn(int fitted, int awaited, bool trusted, std::map<int, int> post_hoc,
             const std::string& error = "") {
    auto state = std::make_shared<LearningState>();
    state->error = error;
    state->fitted_through = fitted;
    state->awaited_through = awaited;
    state->fitting = awaited > fitted;
    state->trusted = trusted;
    state->post_hoc = std::move(post_hoc);
    learning_ = state;
  }
  void step() {
    cycle([&](CycleRecord& r) { r.p300.learning = learning_; });
  }
  std::shared_ptr<const LearningState> learning_;
};

// Untrusted, nothing is acted on: the selection flashes the learning's sequences, all of them
// (paradigm.learning_sequences 0: twice `sequences`, as a trusted one may), evidence for the fit.
TEST_F(LearningParadigmStageTest, AnUntrustedSelectionFlashesAllTheLearningSequences) {
  model_ = trainedModel();
  learn(0, 0, false, {});
  begin();
  ASSERT_EQ(bench_.previous.paradigm.phase, bci::Phase::ObjectFlashing);
  for (int i = 0; i < 60 * 30 && bench_.previous.paradigm.phase != bci::Phase::ObjectSelected; ++i)
    step();
  ASSERT_EQ(bench_.previous.paradigm.phase, bci::Phase::ObjectSelected);
  const int objects = static_cast<int>(config_.world.objects.size());
  EXPECT_EQ(flashes_, objects * 2 * config_.paradigm.sequences);
}

TEST_F(LearningParadigmStageTest,
       ASelectionWaitsForItsFitAndTheArmActsOnlyIfThatFitTrustsItAsShown) {
  model_ = trainedModel();  // the model of an earlier fit, not trusted
  learn(0, 0, false, {});
  begin();
  ASSERT_EQ(bench_.previous.paradigm.phase, bci::Phase::ObjectFlashing);
  decide_ = 2;
  for (int i = 0; i < 60 * 30 && bench_.previous.paradigm.phase != bci::Phase::ObjectSelected; ++i)
    step();
  ASSERT_EQ(bench_.previous.paradigm.phase, bci::Phase::ObjectSelected);
  const int first = selection_;
  // Its fit is running: shown far past result_s.
  learn(0, first, false, {});
  for (int i = 0; i < 60 * 3; ++i) step();
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::ObjectSelected);
  // Trusted, but decoding it as another object than was shown: the trial ends held.
  learn(first, first, true, {{first, 3}});
  for (int i = 0; i < 60 * 3 && bench_.previous.paradigm.trial == 1; ++i) step();
  EXPECT_EQ(bench_.previous.paradigm.trial, 2);
  EXPECT_TRUE(postedOf<GraspRequest>().empty());
  ASSERT_TRUE(bench_.previous.paradigm.trials);
  EXPECT_EQ(bench_.previous.paradigm.trials->at(0).outcome, kArmHeldUnconfirmed);
  EXPECT_TRUE(bench_.previous.paradigm.trials->at(0).arm_held);
  // Trial 2: the fit with it in trusts it and decodes it as shown: the arm goes.
  learn(first, first, false, {{first, 3}});
  for (int i = 0; i < 60 * 30 && bench_.previous.paradigm.phase != bci::Phase::ObjectSelected; ++i)
    step();
  ASSERT_EQ(bench_.previous.paradigm.phase, bci::Phase::ObjectSelected);
  const int second = selection_;
  learn(first, second, false, {{first, 3}});
  step();
  learn(second, second, true, {{first, 3}, {second, 2}});
  for (int i = 0; i < 60 * 3 && bench_.previous.paradigm.phase != bci::Phase::Grasping; ++i) step();
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::Grasping);
  ASSERT_EQ(postedOf<GraspRequest>().size(), 1u);
  EXPECT_EQ(postedOf<GraspRequest>()[0].object, config_.world.objects[1].id);
  EXPECT_EQ(bench_.previous.paradigm.trial, 2);
  nlohmann::json summary;
  stage_.report(summary);
  EXPECT_EQ(summary["learning"]["first_trusted_trial"], 2);
  EXPECT_EQ(summary["learning"]["trials_arm_held"], 1);
}

TEST_F(LearningParadigmStageTest, ASelectionWhoseFitFailedIsHeldAndSaysSo) {
  model_ = trainedModel();
  learn(0, 0, true, {});  // an earlier fit, trusted
  begin();
  for (int i = 0; i < 60 * 30 && bench_.previous.paradigm.phase != bci::Phase::ObjectSelected; ++i)
    step();
  ASSERT_EQ(bench_.previous.paradigm.phase, bci::Phase::ObjectSelected);
  const int first = selection_;
  learn(first, first, true, {}, "training failed");
  for (int i = 0; i < 60 * 3 && bench_.previous.paradigm.trial == 1; ++i) step();
  EXPECT_TRUE(postedOf<GraspRequest>().empty());
  ASSERT_TRUE(bench_.previous.paradigm.trials);
  EXPECT_EQ(bench_.previous.paradigm.trials->at(0).outcome, kArmHeldFitFailed);
  EXPECT_TRUE(bench_.previous.paradigm.trials->at(0).arm_held);
}

class CertainLearningParadigmStageTest : public LearningParadigmStageTest {
 protected:
  static SessionConfig certain() {
    SessionConfig c = learning();
    c.paradigm.certainty = 0.95;
    return c;
  }
  CertainLearningParadigmStageTest() : LearningParadigmStageTest(certain()) {}
  // Trial `trial`'s object selection (deciding object code 2 with certainty_) and the fit with it
  // in, trusted and decoding it as shown.
  void selectAndConfirm(int trial) {
    for (int i = 0; i < 60 * 30 && bench_.previous.paradigm.phase != bci::Phase::ObjectSelected;
         ++i)
      step();
    ASSERT_EQ(bench_.previous.paradigm.phase, bci::Phase::ObjectSelected);
    ASSERT_EQ(bench_.previous.paradigm.trial, trial);
    confirmed_[selection_] = 2;
    learn(selection_, selection_, true, confirmed_);
    for (int i = 0; i < 60 * 3 && bench_.previous.paradigm.phase == bci::Phase::ObjectSelected; ++i)
      step();
  }
  std::map<int, int> confirmed_;
};

TEST_F(CertainLearningParadigmStageTest, AnUncertainSelectionIsHeldThoughItsTrustedFitAgrees) {
  model_ = trainedModel();
  learn(0, 0, true, {});  // an earlier fit, trusted
  begin();
  decide_ = 2;
  certainty_ = 0.9;  // all sequences shown, and still below paradigm.certainty
  selectAndConfirm(1);
  EXPECT_EQ(bench_.previous.paradigm.trial, 2);
  EXPECT_TRUE(postedOf<GraspRequest>().empty());
  ASSERT_TRUE(bench_.previous.paradigm.trials);
  EXPECT_EQ(bench_.previous.paradigm.trials->at(0).outcome, kArmHeldUncertain);
  EXPECT_TRUE(bench_.previous.paradigm.trials->at(0).arm_held);
  certainty_ = 0.99;  // as certain as dynamic stopping asks: the arm goes
  selectAndConfirm(2);
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::Grasping);
  ASSERT_EQ(postedOf<GraspRequest>().size(), 1u);
  EXPECT_EQ(postedOf<GraspRequest>()[0].object, config_.world.objects[1].id);
}

TEST_F(CertainLearningParadigmStageTest, ASelectionDynamicStoppingEndedAsCertainGoesToTheArm) {
  model_ = trainedModel();
  learn(0, 0, true, {});
  begin();
  decide_ = 2;
  certainty_ = 0.9;
  // Three sequences (of four objects) shown and scored, the decision then certain enough:
  // dynamic stopping ends the selection. The flashes still being scored lower its certainty
  // below paradigm.certainty; it goes to the arm all the same, as decided when it stopped.
  for (int i = 0; i < 60 * 30 && flashes_ < 12; ++i) step();
  cycle([&](CycleRecord& r) {
    r.p300.learning = learning_;
    r.p300.sequences = 3;
    r.p300.decision.certainty = 0.99;
  });
  selectAndConfirm(1);
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::Grasping);
  ASSERT_EQ(postedOf<GraspRequest>().size(), 1u);
  ASSERT_TRUE(bench_.previous.paradigm.trials);
  EXPECT_LT(bench_.previous.paradigm.trials->at(0).object_certainty, 0.95);
}

class ErrpParadigmStageTest : public ParadigmStageTest {
 protected:
  static SessionConfig withErrp() {
    SessionConfig c = shortSession();
    c.paradigm.errp = true;
    return c;
  }
  ErrpParadigmStageTest() : ParadigmStageTest(withErrp()) {}
};

// An ErrP classifier whose scores are N(+1, 1) after an error and N(-1, 1) after a right one.
std::shared_ptr<const bci::P300Model> errpModel() {
  auto m = std::make_shared<bci::P300Model>();
  m->score_model = {1.0, -1.0, 1.0};
  return m;
}

TEST_F(ErrpParadigmStageTest, AFeedbackTheErrpRejectsIsNotExecutedAndTheRunnerUpOrARepeatFollows) {
  model_ = trainedModel();
  errp_model_ = errpModel();
  begin();
  ASSERT_TRUE(until(bci::Phase::ObjectSelected));
  EXPECT_TRUE(bench_.previous.paradigm.errp_awaited);
  // The feedback's epoch scored far on the error side.
  for (int i = 0; i < 60 && postedOf<GraspRequest>().empty() &&
                  bench_.previous.paradigm.phase == bci::Phase::ObjectSelected;
       ++i) {
    cycle([](CycleRecord& r) { r.errp.score = std::make_pair(std::int64_t{0}, 4.0); });
  }
  cycle();  // the correction's event is taken the cycle after the verdict
  EXPECT_TRUE(postedOf<GraspRequest>().empty());
  const auto decisions = bench_.logged("errp_decision");
  ASSERT_EQ(decisions.size(), 1u);
  EXPECT_TRUE(decisions[0]["veto"].get<bool>());
  const auto corrections = bench_.logged("errp_correction");
  ASSERT_EQ(corrections.size(), 1u);
  const std::string action = corrections[0]["action"];
  EXPECT_TRUE(action == "runner-up" || action == "repeat") << action;
  const TrialRecord& trial = (*bench_.previous.paradigm.trials)[0];
  ASSERT_EQ(trial.selections.size(), 1u);
  EXPECT_EQ(trial.selections[0].vetoed, true);
  nlohmann::json summary;
  stage_.report(summary);
  EXPECT_EQ(summary["errp"]["decisions"], 1);
}

}  // namespace
}  // namespace arbci::session

namespace arbci::session {
namespace {

// The calibration review (gates.review, gates.min_auc) on hand-built training results.
class ReviewParadigmStageTest : public ParadigmStageTest {
 protected:
  static SessionConfig gated(bool review, double min_auc) {
    SessionConfig c = shortSession();
    c.gates.review = review;
    c.gates.min_auc = min_auc;
    return c;
  }
  explicit ReviewParadigmStageTest(bool review = true, double min_auc = 0.0,
                                   bool experimenter = true)
      : ParadigmStageTest(gated(review, min_auc), experimenter) {}
  // Through the calibration run to its training result, AUC `auc`.
  void trainedAt(double auc) {
    begin();
    ASSERT_TRUE(until(bci::Phase::Training));
    cycle();
    model_ = trainedModel();
    cycle([auc](CycleRecord& r) {
      r.p300.trained = bci::EvaluationReport{};
      r.p300.trained->auc = auc;
      r.p300.trained_on = {1, 2};
    });
  }
};

TEST_F(ReviewParadigmStageTest, TheTrainedCalibrationWaitsForGoOnline) {
  trainedAt(0.9);
  // Held in training, for as long as the experimenter looks.
  for (int i = 0; i < 120; ++i) cycle();
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::Training);
  ASSERT_TRUE(bench_.previous.paradigm.review.has_value());
  EXPECT_DOUBLE_EQ(bench_.previous.paradigm.review->auc, 0.9);
  EXPECT_FALSE(bench_.previous.paradigm.review->below);
  EXPECT_EQ(phaseText(bench_.previous), "calibration review");
  bench_.record.requests.push_back(GoOnlineRequest{});
  cycle();
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::ObjectFlashing);
  EXPECT_FALSE(bench_.previous.paradigm.review.has_value());
  bool noted = false;
  for (const bci::Annotation& a : bench_.previous.annotations)
    noted |= a.text.rfind("Calibration review: go online (AUC 0.900)", 0) == 0;
  EXPECT_TRUE(noted);
  nlohmann::json summary;
  stage_.report(summary);
  ASSERT_EQ(summary["calibration"]["reviews"].size(), 1u) << summary["calibration"].dump();
  EXPECT_EQ(summary["calibration"]["reviews"][0]["decision"], "go online");
}

TEST_F(ReviewParadigmStageTest, RecalibrateRunsTheCalibrationAgainAndTrainsAgain) {
  trainedAt(0.6);
  const int selections = selection_;
  bench_.record.requests.push_back(RecalibrateRequest{});
  cycle();
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::CalibrationCue);
  ASSERT_TRUE(bench_.previous.paradigm.calibration_selection.has_value());
  EXPECT_EQ(bench_.previous.paradigm.calibration_selection->first, 1);
  model_.reset();
  ASSERT_TRUE(until(bci::Phase::Training));
  cycle();
  EXPECT_EQ(postedOf<TrainRequest>().size(), 2u);
  EXPECT_GE(selection_, selections + 2);  // the new run's own selections
  model_ = trainedModel();
  cycle([](CycleRecord& r) {
    r.p300.trained = bci::EvaluationReport{};
    r.p300.trained->auc = 0.9;
    r.p300.trained_on = {3, 4};
  });
  ASSERT_TRUE(bench_.previous.paradigm.review.has_value());
  EXPECT_EQ(bench_.previous.paradigm.review->round, 2);
}

class MinimumAucTest : public ReviewParadigmStageTest {
 protected:
  MinimumAucTest() : ReviewParadigmStageTest(false, 0.95) {}
};

TEST_F(MinimumAucTest, BelowTheMinimumTheExperimenterDecidesEvenWithoutAReview) {
  trainedAt(0.9);
  ASSERT_TRUE(bench_.previous.paradigm.review.has_value());
  EXPECT_TRUE(bench_.previous.paradigm.review->below);
  EXPECT_NE(bench_.previous.paradigm.status.find("calibration AUC 0.900 below gates.min_auc 0.950"),
            std::string::npos)
      << bench_.previous.paradigm.status;
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::Training);
}

class UnattendedMinimumAucTest : public ReviewParadigmStageTest {
 protected:
  UnattendedMinimumAucTest() : ReviewParadigmStageTest(true, 0.95, false) {}
};

TEST_F(UnattendedMinimumAucTest, BelowTheMinimumARunWithoutExperimenterEndsWithTheReason) {
  trainedAt(0.9);
  EXPECT_EQ(bench_.previous.end_reason,
            "calibration AUC 0.900 below gates.min_auc 0.950: not going online unattended");
  EXPECT_EQ(bench_.previous.end_kind, "aborted");
  EXPECT_NE(bench_.previous.paradigm.phase, bci::Phase::ObjectFlashing);
}

TEST_F(UnattendedMinimumAucTest, AboveTheMinimumItGoesOnlineWithoutAReview) {
  trainedAt(0.97);
  EXPECT_EQ(bench_.previous.paradigm.phase, bci::Phase::ObjectFlashing);
  EXPECT_FALSE(bench_.previous.paradigm.review.has_value());
}

}  // namespace
}  // namespace arbci::session

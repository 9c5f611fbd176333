// The pre-flight check the experimenter's Start runs before any flash: camera frames arrive and
// show the reference marker, the EEG flows at its rate and passes the quality gate, the robot
// answers STATUS (preflight.h). Passed, it asks the paradigm to begin; failed, it names each key
// to look at in the log, on the terminal and in the panel, and a run without an experimenter ends
// there. The channels' quality at each check goes to the log, the recording and the summary.
#pragma once

#include <cstdint>
#include <optional>

#include "arbci/session/preflight.h"
#include "arbci/session/stage.h"

namespace arbci::session {

struct PreflightStageSettings {
  PreflightSettings check;
  double max_pose_age_s = 0.0;  // the session's tracker.max_pose_age_s
  bool experimenter = true;     // false: nobody can fix a failure, so the run ends
};

class PreflightStage final : public Stage {
 public:
  PreflightStage(const PreflightStageSettings& settings, const StageServices& services);
  const char* name() const override { return "preflight"; }
  void step(Cycle& cycle) override;
  // summary.json's "signal_quality": the verdict at Start and each channel's grade then.
  void report(nlohmann::json& summary) const override;

 private:
  void logQuality(Cycle& cycle);
  PreflightObservation observe(const Cycle& cycle) const;
  void finish(Cycle& cycle, Preflight::State state);
  PreflightStageSettings settings_;
  StageServices s_;
  Preflight preflight_;
  std::optional<std::uintmax_t> disk_free_;  // on the session folder's disk, at the check's start
  nlohmann::json quality_ = nlohmann::json::object();  // the last check's verdict and channels
};

}  // namespace arbci::session

// The calibration run's end as the paradigm stage sees it: the selections interrupted and retaken
// (training leaves their flashes out), the training asked for and awaited from the P300 and ErrP
// stages on the record (with what it cost the display meanwhile), the model saved with the ErrP
// classifier inside it, what the experimenter is told, and the summary's "calibration".
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "arbci/bci/evaluation.h"
#include "arbci/session/cycle.h"
#include "arbci/session/stage.h"

namespace arbci::session {

class CalibrationRun {
 public:
  CalibrationRun(std::string method, std::filesystem::path model_file, bool errp)
      : method_(std::move(method)), model_file_(std::move(model_file)), errp_(errp) {}

  // Calibration selection `selection` (its target `object`) was interrupted (`reason`) and is cued
  // again as the next selection.
  void retaken(int selection, int object, const std::string& reason, Cycle& cycle,
               const StageServices& s);

  // Training was asked for now; both classifiers' results are awaited.
  void trainingStarted(const Cycle& cycle, const StageServices& s);
  bool awaiting() const { return awaiting_p300_ || awaiting_errp_; }
  // What the display did while the training ran on its worker threads (frames presented, the
  // longest gap).
  void frameShown(const Presentation& shown);

  enum class Outcome { Waiting, Failed, Trained };
  // Takes this cycle's training results off the record: Failed (the P300 classifier's, with the
  // reason in `error()`), Trained once both are in (the model saved, the experimenter told), or
  // still Waiting.
  Outcome collect(const Cycle& cycle, const StageServices& s);
  const std::string& error() const { return error_; }
  const std::optional<bci::EvaluationReport>& report() const { return report_; }

  // The experimenter's (or the gate's) decision on the trained calibration, for the summary.
  void reviewed(const std::string& decision, double auc, double time_s);
  // A recalibration: the next training is awaited afresh (retakes and reviews stay listed).
  void restart();

  // summary.json's "calibration" (selections, those used, AUC, accuracy, the retaken ones, the
  // reviews).
  void summarise(nlohmann::json& summary) const;

 private:
  void saveModel(const Cycle& cycle);
  void tellTrained(const Cycle& cycle, const StageServices& s) const;
  void logErrp(const Cycle& cycle, const StageServices& s) const;

  std::string method_;
  std::filesystem::path model_file_;
  bool errp_;
  struct Retake {
    int selection = 0, object = 0;
    std::string reason;
    int retaken_as = 0;
  };
  std::vector<Retake> retakes_;
  nlohmann::json reviews_ = nlohmann::json::array();
  double since_ = 0.0;
  bool awaiting_p300_ = false, awaiting_errp_ = false;
  std::optional<bci::EvaluationReport> report_, errp_report_;
  std::vector<int> trained_on_;
  std::string error_, errp_failure_;
  int frames_ = 0;
  double longest_s_ = 0.0;
  std::optional<double> last_at_;
};

}  // namespace arbci::session

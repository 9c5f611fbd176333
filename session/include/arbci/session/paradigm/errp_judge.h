// The ErrP's verdict on each selection shown as feedback, and the counts the summary gives: the
// feedback's epoch score (from the ErrP stage, on the record) and the selection's own certainty
// make the posterior probability that the selection was wrong; above the threshold it is
// rejected. It also keeps how often wrong and right selections were caught or vetoed, the
// corrections made (runner-up, repeat, skipped or returned trials) and the time they cost.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "arbci/bci/p300_model.h"

namespace arbci::session {

struct ErrpVerdict {
  bool veto = false;
  double score = 0.0, prior_error = 0.0, posterior_error = 0.0;
};

class ErrpJudge {
 public:
  explicit ErrpJudge(double threshold) : threshold_(threshold) {}
  double threshold() const { return threshold_; }

  // A selection was made with this certainty: a score still held is an earlier feedback's.
  void selectionMade(double certainty);
  // Its feedback is shown; `error`: whether it is known to be wrong (online: against the
  // intention; nullopt when not known).
  void feedbackShown(std::optional<bool> error);
  // A new feedback appeared on the screen: its score is awaited (one held is an earlier one's).
  void awaitScore() { score_.reset(); }
  // The ErrP stage scored a feedback epoch.
  void scored(double score) { score_ = score; }
  // Whether the selection shown is known to be wrong (nullopt: not known).
  std::optional<bool> shownError() const { return shown_error_; }

  // The verdict on the selection shown, once its feedback epoch is scored (nullopt until then),
  // counted; `time_s` starts or ends the time a rejection costs.
  std::optional<ErrpVerdict> judge(const bci::P300Model& errp, double time_s);
  // A correction after a rejection: "runner-up", "repeat", "skip" or "return".
  void corrected(const std::string& action, double time_s);

  // summary.json's "errp" counts.
  void report(nlohmann::json& errp) const;

 private:
  double threshold_;
  double shown_certainty_ = 0.0;  // the P300 certainty of the selection shown
  std::optional<bool> shown_error_;
  std::optional<double> score_;  // the latest feedback's, until a verdict takes it
  int decisions_ = 0;            // verdicts on selections shown
  int wrong_shown_ = 0, wrong_caught_ = 0;
  int correct_shown_ = 0, correct_vetoed_ = 0;
  int runner_up_ = 0, repeats_ = 0, skipped_trials_ = 0;
  double correction_s_ = 0.0;   // from each rejection to the next accepted selection
  double vetoed_since_ = -1.0;  // session time of the first rejection not yet made good
};

}  // namespace arbci::session

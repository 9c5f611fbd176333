#include "arbci/session/paradigm/errp_judge.h"

#include <utility>

#include "arbci/bci/decision.h"

namespace arbci::session {

void ErrpJudge::selectionMade(double certainty) {
  shown_certainty_ = certainty;
  score_.reset();
}

void ErrpJudge::feedbackShown(std::optional<bool> error) {
  shown_error_ = error;
}

std::optional<ErrpVerdict> ErrpJudge::judge(const bci::P300Model& errp, double time_s) {
  const auto score = std::exchange(score_, std::nullopt);
  if (!score) return std::nullopt;  // its epoch is not complete yet
  ErrpVerdict v;
  v.score = *score;
  v.prior_error = 1.0 - shown_certainty_;
  v.posterior_error = bci::errorPosterior(errp.score_model, *score, v.prior_error);
  v.veto = v.posterior_error > threshold_;
  ++decisions_;
  if (shown_error_) {
    (*shown_error_ ? wrong_shown_ : correct_shown_) += 1;
    if (v.veto) (*shown_error_ ? wrong_caught_ : correct_vetoed_) += 1;
  }
  if (v.veto && vetoed_since_ < 0.0) vetoed_since_ = time_s;
  if (!v.veto && vetoed_since_ >= 0.0) {
    correction_s_ += time_s - vetoed_since_;
    vetoed_since_ = -1.0;
  }
  return v;
}

void ErrpJudge::corrected(const std::string& action, double time_s) {
  if (action == "runner-up") ++runner_up_;
  if (action == "repeat") ++repeats_;
  if (action == "skip" || action == "return") {
    ++skipped_trials_;
    if (vetoed_since_ >= 0.0) correction_s_ += time_s - vetoed_since_;
    vetoed_since_ = -1.0;
  }
}

void ErrpJudge::report(nlohmann::json& errp) const {
  errp.update({{"threshold", threshold_},
               {"decisions", decisions_},
               {"wrong_selections", wrong_shown_},
               {"wrong_caught", wrong_caught_},
               {"correct_selections", correct_shown_},
               {"correct_vetoed", correct_vetoed_},
               {"runner_up", runner_up_},
               {"repeated", repeats_},
               {"trials_skipped", skipped_trials_},
               {"correction_s", correction_s_}});
}

}  // namespace arbci::session

// A session's recording scored as the session ran: its selections split where the session marked
// them (bci/selection_marks.h), the calibration run apart from the online trials (a model trained
// on that run scores it in-sample, which says nothing of how it does on new data), and each
// online object and cell selection decided as the session decides it, with dynamic stopping.
#pragma once

#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "arbci/bci/decision.h"
#include "arbci/bci/p300_model.h"
#include "arbci/bci/recording.h"
#include "arbci/bci/selection_marks.h"

namespace arbci::app {

struct OnlineDecision {
  bci::SelectionKind kind = bci::SelectionKind::Objects;
  int trial = 0, number = 0;
  bci::Decision decision;
  int sequences = 0;
  std::set<int> truth;  // the codes attended as recorded; empty: not known
  bool right() const { return !truth.empty() && decision.codes == truth; }
};

struct SessionEvaluation {
  std::string source;
  // The calibration run: its selections, those decided right after every sequence recorded, and
  // whether the model was trained on them (its provenance names this recording or "this
  // session's calibration run").
  int calibration_selections = 0, calibration_right = 0;
  bool in_sample = false;
  std::vector<OnlineDecision> online;
};

// Whether `recording` marks online selections (a session's, or `arbci eeg simulate --trials`).
bool isSessionRecording(const bci::Recording& recording);

// An online selection is decided on every flash recorded (at most `max_sequences` sequences, 0:
// all): the flashes the session showed, which it decided on. `rule` with a certainty replays
// dynamic stopping instead (a recording that holds every sequence, as `arbci eeg simulate
// --trials` writes): after each whole sequence from its minimum, once as certain as it asks.
SessionEvaluation evaluateSession(const bci::P300Model& model, const bci::Recording& recording,
                                  const bci::StoppingRule& rule, int max_sequences);

void printSessionEvaluation(std::ostream& out, const SessionEvaluation& evaluation,
                            const bci::StoppingRule& rule);

}  // namespace arbci::app

// Error-related potentials from a session recording: its selections' feedback events
// ("Feedback <codes> correct|error" annotations, stamped at the feedback's presentation) as the
// stimuli of an ErrP dataset, so `buildDataset`/`trainModel` train and cross-validate the ErrP
// classifier as they do the P300 one.
#pragma once

#include <string>

#include "arbci/bci/recording.h"

namespace arbci::bci {

// Stimulus codes of an ErrP dataset: the classes, not choices.
constexpr int kErrorFeedbackCode = 1;  // the ErrP classifier's target
constexpr int kCorrectFeedbackCode = 2;

struct FeedbackRecording {
  Recording recording;  // the signal, with one stimulus per feedback of known correctness
  int errors = 0, correct = 0;
  int unknown = 0;  // feedback whose correctness the session did not know: left out
};

// Throws std::invalid_argument naming the file when it holds no feedback event.
FeedbackRecording feedbackRecording(const Recording& session);

}  // namespace arbci::bci

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

// A session's feedbacks come from two parts: the calibration block (a cued target, then a shown
// selection, a quarter of them wrong by design) before the classifiers are trained, and the
// online selections after. They differ: the calibration's are evenly spaced and the subject
// expects errors there; online errors follow from the P300 classifier.
enum class FeedbackPart { Both, Calibration };

struct FeedbackCounts {
  int errors = 0, correct = 0;
  int total() const { return errors + correct; }
};

struct FeedbackRecording {
  Recording recording;                 // the signal, with one stimulus per feedback taken
  FeedbackCounts calibration, online;  // of known correctness, taken or not
  int errors = 0, correct = 0;         // taken
  int unknown = 0;  // feedback whose correctness the session did not know: left out
};

// A feedback is the calibration's when it comes before the session's "Phase training the
// classifier" annotation (or the recording has calibration phases and no training). Throws
// std::invalid_argument naming the file when it holds no feedback event, or none of `part`.
FeedbackRecording feedbackRecording(const Recording& session,
                                    FeedbackPart part = FeedbackPart::Both);

// The fewest calibration feedbacks (a share `wrong_rate` of them wrong, in random order) that
// train the ErrP classifier with `folds` contiguous cross-validation folds: every fold's training
// part must keep kMinimumTargets of each class with a chance of 99 % or more, because the wrong
// ones fall at random and a held-out block may take more than its share. 0 when no size up to
// 100,000 is enough.
int minimumCalibrationFeedbacks(double wrong_rate, int folds);

}  // namespace arbci::bci

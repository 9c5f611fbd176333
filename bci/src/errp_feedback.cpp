#include "arbci/bci/errp_feedback.h"

#include <stdexcept>

namespace arbci::bci {

FeedbackRecording feedbackRecording(const Recording& session) {
  FeedbackRecording out;
  out.recording = session;
  out.recording.stimuli.clear();
  out.recording.parameters["Paradigm"] = "single stimulus, 2 stimuli";
  int found = 0;
  for (const Annotation& a : session.annotations) {
    if (a.text.rfind("Feedback ", 0) != 0) continue;
    ++found;
    const auto ends = [&](const std::string& suffix) {
      return a.text.size() > suffix.size() &&
             a.text.compare(a.text.size() - suffix.size(), suffix.size(), suffix) == 0;
    };
    if (!ends(" error") && !ends(" correct")) {
      ++out.unknown;
      continue;
    }
    const bool error = ends(" error");
    (error ? out.errors : out.correct) += 1;
    out.recording.stimuli.push_back(
        {a.sample, error ? kErrorFeedbackCode : kCorrectFeedbackCode, error, 0, true});
  }
  if (found == 0) {
    throw std::invalid_argument(session.source +
                                ": no feedback events (\"Feedback ... correct|error\"): record a "
                                "session with errp.enabled to train an ErrP classifier");
  }
  return out;
}

}  // namespace arbci::bci

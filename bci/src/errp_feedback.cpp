#include "arbci/bci/errp_feedback.h"

#include "arbci/bci/paradigm.h"

#include <limits>
#include <stdexcept>

namespace arbci::bci {

namespace {

bool startsWith(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

// The first sample after the calibration block: the training phase's start; the end of the
// recording when it has calibration phases but never trained; 0 when it has no calibration.
std::int64_t calibrationEnd(const Recording& session) {
  bool calibration = false;
  for (const Annotation& a : session.annotations) {
    if (startsWith(a.text, kPhaseAnnotation + std::string(toString(Phase::Training))))
      return a.sample;
    // Every calibration phase's name starts so: "calibration: target cued", "...: flashing".
    calibration |= startsWith(a.text, kPhaseAnnotation + std::string("calibration"));
  }
  return calibration ? std::numeric_limits<std::int64_t>::max() : 0;
}

}  // namespace

FeedbackRecording feedbackRecording(const Recording& session, FeedbackPart part) {
  FeedbackRecording out;
  const std::int64_t calibration_end = calibrationEnd(session);
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
    const bool in_calibration = a.sample < calibration_end;
    FeedbackCounts& counts = in_calibration ? out.calibration : out.online;
    (error ? counts.errors : counts.correct) += 1;
    if (part == FeedbackPart::Calibration && !in_calibration) continue;
    (error ? out.errors : out.correct) += 1;
    out.recording.stimuli.push_back(
        {a.sample, error ? kErrorFeedbackCode : kCorrectFeedbackCode, error, 0, true});
  }
  if (found == 0) {
    throw std::invalid_argument(session.source +
                                ": no feedback events (\"Feedback ... correct|error\"): record a "
                                "session with errp.enabled to train an ErrP classifier");
  }
  if (part == FeedbackPart::Calibration && out.calibration.total() == 0) {
    throw std::invalid_argument(
        session.source + ": no calibration feedback (its " + std::to_string(out.online.total()) +
        " feedbacks of known correctness are all online: the session started with a trained "
        "model); leave out --calibration-only");
  }
  return out;
}

}  // namespace arbci::bci

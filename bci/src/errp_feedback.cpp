#include "arbci/bci/errp_feedback.h"

#include "arbci/bci/paradigm.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "arbci/bci/classifier.h"

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

namespace {

double logChoose(int n, int k) {
  return std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0);
}

// P(X > limit) for X ~ Hypergeometric(population n, successes e, draws b).
double upperTail(int n, int e, int b, int limit) {
  double p = 0.0;
  for (int x = std::max(limit + 1, 0); x <= std::min(e, b); ++x)
    if (b - x <= n - e) p += std::exp(logChoose(e, x) + logChoose(n - e, b - x) - logChoose(n, b));
  return p;
}

// The chance that some fold's training part has fewer than kMinimumTargets of a class, bounded
// above by the sum over folds of the held-out block's hypergeometric tail (a union bound: the
// size it gives is never too small).
double foldFailure(int n, int wrong, int folds) {
  double p = 0.0;
  for (int f = 0; f < folds; ++f) {
    const int b = static_cast<int>(std::lround(static_cast<double>(f + 1) * n / folds)) -
                  static_cast<int>(std::lround(static_cast<double>(f) * n / folds));
    p += upperTail(n, wrong, b, wrong - kMinimumTargets);          // too few errors left
    p += upperTail(n, n - wrong, b, n - wrong - kMinimumTargets);  // too few correct left
  }
  return p;
}

}  // namespace

int minimumCalibrationFeedbacks(double wrong_rate, int folds) {
  constexpr double kAcceptedFailure = 0.01;
  for (int n = 2 * kMinimumTargets; n <= 100000; ++n) {
    const int wrong = static_cast<int>(std::lround(wrong_rate * n));
    if (wrong < kMinimumTargets || n - wrong < kMinimumTargets) continue;
    if (foldFailure(n, wrong, folds) <= kAcceptedFailure) return n;
  }
  return 0;
}

}  // namespace arbci::bci

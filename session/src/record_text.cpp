#include "arbci/session/record_text.h"

#include <algorithm>
#include <cstdio>

namespace arbci::session {

std::string phaseText(const CycleRecord& record) {
  if (!record.ended && record.paradigm.review) return "calibration review";
  if (!record.ended) return bci::toString(record.paradigm.phase);
  const std::string& kind = record.end_kind;
  const std::string& why = record.end_reason;
  return "ended: " + kind + (why == kind ? "" : " (" + why + ")");
}

std::string reasonText(const CycleRecord& record) {
  return record.ended ? phaseText(record) : record.paradigm.status;
}

std::string recoveryText(const CycleRecord& record) {
  const ParadigmPart& p = record.paradigm;
  if (record.ended || (p.phase != bci::Phase::EmergencyStop && p.phase != bci::Phase::RobotFault) ||
      !p.interrupted)
    return "";
  const bci::Phase was = *p.interrupted;
  const bool robot_step = was == bci::Phase::Grasping || was == bci::Phase::Dropping;
  const auto holding = record.robot.holding();
  std::string where = record.robot.at_home ? "The arm is at home" : "The arm is where it stopped";
  where += holding ? ", holding object " + std::to_string(*holding) + ". " : ", holding nothing. ";
  if (!record.robot.at_home) where += "Home (Robot panel) first where it must be cleared. ";
  const std::string step = std::string(bci::toString(was));
  if (robot_step) {
    return "Stopped in trial " + std::to_string(p.trial) + " (" + step + "). " + where +
           "Next: Retry step does the " + (was == bci::Phase::Grasping ? "grasp" : "put-down") +
           " again; Skip trial or Resume ends this trial here and starts the next" +
           (holding ? " (the object stays in the gripper until a put-down: Open gripper in "
                      "the Robot panel)"
                    : "") +
           ".";
  }
  return "Stopped in trial " + std::to_string(p.trial) + " (" + step + "). " + where +
         "Next: Resume (or Retry step) goes on with " + step + "; Skip trial starts the next.";
}

std::string timingWarning(const CycleRecord& record, const SessionConfig& settings) {
  const Presentation& p = record.presentation;
  if (!p.display_too_slow || !p.median_frame_ms) return "";
  char text[160];
  std::snprintf(text, sizeof text, "display too slow: a frame every %.1f ms (configured %.1f ms)",
                *p.median_frame_ms, 1000.0 / settings.paradigm.display_hz);
  return text;
}

std::string trackingAlarm(const CycleRecord& record, const SessionConfig& settings) {
  std::vector<int> ids;
  for (const WorldObjectSettings& o : settings.world.objects) {
    if (record.robot.holding() != o.id) ids.push_back(o.id);
  }
  return record.tracking.alarm(ids, record.time_s);
}

std::string eegClockLine(const CycleRecord& record) {
  const EegPart& eeg = record.eeg;
  char text[160];
  std::snprintf(text, sizeof text, "EEG: lost samples %lld, clock drift %+.1f ppm, jitter %.2f ms",
                static_cast<long long>(eeg.lost_samples), eeg.drift_ppm, eeg.jitter_ms);
  return eeg.source_line.empty() ? std::string(text) : std::string(text) + "\n" + eeg.source_line;
}

std::vector<std::string> selectionLines(const CycleRecord& record) {
  std::vector<std::string> lines;
  if (const auto& trials = record.paradigm.trials) {
    for (const TrialRecord& t : *trials) lines.push_back(selectionLine(t));
  }
  return lines;
}

std::string statusLine(const CycleRecord& record, const SessionConfig& settings,
                       double cycle_p50_ms) {
  char text[256];
  std::snprintf(text, sizeof text,
                "t=%.1f s  trial %d/%d  %s  cycle p50 %.1f ms  overruns %d  late frames %lld",
                record.time_s, std::max(record.paradigm.trial, 0), settings.paradigm.trials,
                bci::toString(record.paradigm.phase), cycle_p50_ms, record.overruns,
                static_cast<long long>(record.presentation.late_frames));
  std::string line = text;
  for (const std::string& warning :
       {timingWarning(record, settings), trackingAlarm(record, settings)}) {
    if (!warning.empty()) line.append("  [").append(warning).append("]");
  }
  return line;
}

double cycleBudgetMs(const SessionConfig& settings) {
  return 1000.0 * settings.eeg.block_size / settings.eeg.rate_hz;
}

}  // namespace arbci::session

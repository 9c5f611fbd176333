// What a cycle's record says to a person, in the same words wherever it is shown: the window's
// panels and status bar, and a terminal run's status line. Each reads the record (and the
// session's settings) alone.
#pragma once

#include <string>
#include <vector>

#include "arbci/session/cycle.h"
#include "arbci/session/session_config.h"

namespace arbci::session {

// The paradigm's phase ("phase 1: objects flashing"), or once ended how and why, in the
// summary's words ("ended: estop (ended by the experimenter in: robot grasping)").
std::string phaseText(const CycleRecord& record);
// Why the session is not going as planned now (a pause, a failed training, a refused grasp; ""
// when it is), or once ended, phaseText().
std::string reasonText(const CycleRecord& record);
// After an emergency stop or a robot fault: where the arm is and what each way on does (Retry
// step, Skip trial, Resume), in a line; "" otherwise.
std::string recoveryText(const CycleRecord& record);
// "display too slow: a frame every 25.0 ms (configured 16.7 ms)" while the display cannot hold
// paradigm.display_hz, else "".
std::string timingWarning(const CycleRecord& record, const SessionConfig& settings);
// "" while the reference and every object not in the gripper are tracked within the allowed pose
// age; else "tracking lost: reference 0 (2.1 s), object 40 (never seen)".
std::string trackingAlarm(const CycleRecord& record, const SessionConfig& settings);
// "EEG: lost samples 0, clock drift +1.2 ppm, jitter 0.30 ms", and the source's own line.
std::string eegClockLine(const CycleRecord& record);
// One line per trial so far (trial_record.h's selectionLine).
std::vector<std::string> selectionLines(const CycleRecord& record);
// Time, trial, phase, the cycle's median compute time (`cycle_p50_ms`, kept by whoever watches
// the cycles), overruns, late frames, and any warning.
std::string statusLine(const CycleRecord& record, const SessionConfig& settings,
                       double cycle_p50_ms);
// The cycle's time budget: one EEG block (15 samples at 256 Hz: 58.6 ms).
double cycleBudgetMs(const SessionConfig& settings);

}  // namespace arbci::session

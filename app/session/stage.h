// The contract every part of the session's cycle keeps, in the spirit of BCI2000's filters. A
// stage's settings struct (its part of the session file, and nothing else) validates itself before
// the run, naming the key, the value and what is allowed; the stage starts when it is constructed
// (opening its devices and files); each displayed frame it steps with the cycle's context; at the
// end of the run it stops, saving what it holds. The cycle times each stage under its name
// (summary.json's "cycle", the log's "cycle" and "late_frame" lines).
//
// The stages run in the order data flows: acquire (eeg, cameras) -> process (tracking) -> decide
// (robot, paradigm) -> render. A later stage reads what an earlier one made this cycle.
#pragma once

#include <cstdint>
#include <string>

namespace arbci::app {

struct CycleContext {
  std::int64_t frame = 0;  // the display frame being made
  double time_s = 0.0;     // session seconds at the cycle's start
  double due_s = 0.0;      // when this frame is due on screen (session seconds)
  double host_s = 0.0;     // time_s on the host clock (bci::hostSeconds(); simulated: time_s)
  // The EEG sample taken at time_s, through the clock model: filled in by the EEG stage, which
  // runs first, for every later stage.
  std::int64_t eeg_sample = 0;
};

class Stage {
 public:
  virtual ~Stage() = default;
  // Its name in the cycle's timing.
  virtual const char* name() const = 0;
  virtual void step(CycleContext& cycle) = 0;
  // The run has ended (`reason`); called once, before the summary is written.
  virtual void stop(const CycleContext& /*cycle*/, const std::string& /*reason*/) {}
};

}  // namespace arbci::app

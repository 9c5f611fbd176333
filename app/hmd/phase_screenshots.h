// Which HMD frames a session keeps as screenshots: one as each phase of a trial begins
// (hmd_trial<N>_<phase>.png), the calibration run's, the end's and a robot fault's. A flashing
// phase waits for a frame that shows a flash, so the picture shows what the subject saw.
// `kept` (hmd.screenshots) narrows it: "first_trial" keeps trial 1's phases only, "end" only the
// end's and a robot fault's, "none" nothing.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "arbci/bci/paradigm.h"

namespace arbci::app {

class PhaseScreenshots {
 public:
  PhaseScreenshots(std::filesystem::path folder, std::string kept)
      : folder_(std::move(folder)), kept_(std::move(kept)) {}

  void phaseEntered(bci::Phase phase, int trial);
  // The file this frame should be written to, if one is due; asked once per frame drawn.
  std::optional<std::filesystem::path> take(const bci::FrameStimulus& shown);

 private:
  std::filesystem::path folder_;
  std::string kept_;
  std::optional<std::string> name_;
  bool needs_flash_ = false;
};

}  // namespace arbci::app

#include "hmd/phase_screenshots.h"

namespace arbci::app {
namespace {

std::string phaseSlug(bci::Phase phase) {
  switch (phase) {
    case bci::Phase::CalibrationFlashing:
      return "calibration";
    case bci::Phase::CalibrationFeedback:
      return "calibration_feedback";
    case bci::Phase::ObjectFlashing:
      return "1_objects_flashing";
    case bci::Phase::ObjectSelected:
      return "2_object_selected";
    case bci::Phase::Grasping:
      return "3_grasping";
    case bci::Phase::CellFlashing:
      return "4_grid_flashing";
    case bci::Phase::CellSelected:
      return "5_cell_selected";
    case bci::Phase::Dropping:
      return "6_putting_down";
    case bci::Phase::RobotFault:
      return "robot_fault";
    case bci::Phase::Finished:
      return "finished";
    default:
      return "";
  }
}

}  // namespace

void PhaseScreenshots::phaseEntered(bci::Phase phase, int trial) {
  const std::string slug = phaseSlug(phase);
  if (slug.empty() || kept_ == "none") return;
  const bool ending = phase == bci::Phase::Finished || phase == bci::Phase::RobotFault;
  const bool in_trial = !ending && phase != bci::Phase::CalibrationFlashing &&
                        phase != bci::Phase::CalibrationFeedback;
  if (kept_ == "end" && !ending) return;
  if (kept_ == "first_trial" && in_trial && trial != 1) return;
  // The calibration run's phases recur with every target: the first of each is kept.
  const bool once = phase == bci::Phase::CalibrationFlashing ||
                    phase == bci::Phase::CalibrationFeedback || phase == bci::Phase::Finished ||
                    phase == bci::Phase::RobotFault;
  if ((phase == bci::Phase::CalibrationFlashing || phase == bci::Phase::CalibrationFeedback) &&
      std::filesystem::exists(folder_ / ("hmd_" + slug + ".png")))
    return;
  name_ = once ? "hmd_" + slug + ".png" : "hmd_trial" + std::to_string(trial) + "_" + slug + ".png";
  needs_flash_ = phase == bci::Phase::CalibrationFlashing || phase == bci::Phase::ObjectFlashing ||
                 phase == bci::Phase::CellFlashing;
}

std::optional<std::filesystem::path> PhaseScreenshots::take(const bci::FrameStimulus& shown) {
  if (!name_ || (needs_flash_ && shown.lit.empty())) return std::nullopt;
  const std::filesystem::path path = folder_ / *name_;
  name_.reset();
  return path;
}

}  // namespace arbci::app

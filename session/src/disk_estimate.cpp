#include "arbci/session/disk_estimate.h"

#include <cmath>
#include <cstdio>

namespace arbci::session {
namespace {

// A grasp and a put-down with the arm's approach, lift and homing: the simulated arm takes
// about 15 s; twice that leaves room for a slower real arm.
constexpr double kRobotSecondsPerTrial = 30.0;
// log.jsonl: a cycle line every 6 frames and a line per event (~3 kB a second in the default
// session).
constexpr double kLogBytesPerSecond = 4000.0;
// The BDF's annotation channel: one 513-byte area per record of a quarter second or so.
constexpr double kAnnotationBytesPerSecond = 2100.0;
// A PNG of camera images with overlays compresses about 2.4 : 1 from 8-bit RGB.
constexpr double kPngRatio = 0.45;
// Whatever the run, a little more: summary, model, the figures of a report.
constexpr double kFixedBytes = 5e6;

int screenshotsOf(const std::string& kept, int trials) {
  if (kept == "none") return 0;
  if (kept == "end") return 2;
  const int per_trial = 6, calibration = 2, end = 2;
  return calibration + end + per_trial * (kept == "first_trial" ? 1 : trials);
}

std::string megabytes(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.0f MB", std::ceil(bytes / 1e6));
  return text;
}

}  // namespace

DiskEstimate plannedRunBytes(const SessionConfig& c, int eeg_channels, double eeg_rate_hz) {
  const bci::ParadigmSettings& p = c.paradigm;
  const double soa = p.soaSeconds();
  const double objects = static_cast<double>(c.world.objects.size());
  const double lines = c.world.grid.rows + c.world.grid.columns;
  const double between = p.result_s + p.pause_s;
  const double calibration =
      p.calibration_selections * (p.cue_s + p.calibration_sequences * objects * soa + between);
  const double trial =
      p.sequences * (objects + lines) * soa + 2.0 * between + kRobotSecondsPerTrial;
  DiskEstimate out;
  out.planned_s = calibration + p.trials * trial;
  const double eeg = out.planned_s * (eeg_channels * 3.0 * eeg_rate_hz + kAnnotationBytesPerSecond);
  const double log = out.planned_s * kLogBytesPerSecond;
  const double screenshots =
      screenshotsOf(c.hmd.screenshots, p.trials) * c.hmd.width * c.hmd.height * 3.0 * kPngRatio;
  const double total = 2.0 * (eeg + log + screenshots) + kFixedBytes;
  out.bytes = static_cast<std::uintmax_t>(total);
  char minutes[32];
  std::snprintf(minutes, sizeof minutes, "%.0f min", std::ceil(out.planned_s / 60.0));
  out.what = "about " + megabytes(total) + ": twice the " + minutes + " planned (recording " +
             megabytes(eeg) + ", log " + megabytes(log) + ", screenshots " +
             megabytes(screenshots) + " as hmd.screenshots \"" + c.hmd.screenshots + "\")";
  return out;
}

}  // namespace arbci::session

// Sequences of a moving marker with exact truth, for the pose-stability tests and the bench:
// every frame integrated over its exposure (the marker smears exactly as it moves), with sensor
// noise and, where the camera compresses, JPEG. Run through ARBCI's tracker with its poses, or
// through libapriltag (its own tags, the same motion) with IPPE, the pose peers compute.
#pragma once

#include <functional>
#include <string>

#include <opencv2/core.hpp>

#include "arbci/vision/marker_detector.h"
#include "arbci/vision/pose.h"
#include "support/synthetic_markers.h"

namespace arbci::test {

struct PoseSequence {
  std::string name;
  std::function<vision::Pose(double t)> truth;  // T_cam_marker at time t (s)
  double seconds = 5.0, fps = 30.0, exposure_ms = 16.0, noise = 2.0;
  int jpeg_quality = 0;     // 0: none
  unsigned noise_seed = 1;  // draws the sensor noise of every frame (renderSequenceFrame)
  double side_m = 0.06;     // the black square
  cv::Size size{640, 480};
  cv::Matx33d k{560, 0, 319.5, 0, 560, 239.5, 0, 0, 1};
  int frames() const { return static_cast<int>(seconds * fps + 0.5); }
};

// A marker held in the hand and turned: across the image at up to about 700 px/s and turning at
// up to about 200 deg/s, 0.55 m away (a 60 mm marker is about 60 px), JPEG at quality 75.
PoseSequence fastHandheldSequence(double seconds = 5.0);
// A marker 1.1 m away (about 30 px), tilted 40 degrees, the head turning slowly; JPEG at 75.
PoseSequence farMarkerSequence(double seconds = 5.0);

// Frame `index` of the sequence with `family`'s marker `id`; `seed` draws the noise.
cv::Mat renderSequenceFrame(const PoseSequence& sequence, MarkerFamily family, int id, int index,
                            unsigned seed);

// How a run's poses compare with the truth.
struct PoseStability {
  int frames = 0, found = 0;
  int flips = 0;               // rotation error over 15 degrees: the other planar solution
  double outward_px = 0.0;     // mean corner offset along the diagonal, away from the centre
  double rotation_deg = 0.0;   // mean rotation error of the frames without a flip
  double corner_rms_px = 0.0;  // the corners' distance from the truth
};

// ARBCI: `config`'s detector, its tracker (with One-Euro corner smoothing when `smooth`) and
// MarkerPoses with `pose`.
PoseStability runArbciPoses(const PoseSequence& sequence, const vision::DetectorConfig& config,
                            const vision::PoseOptions& pose, bool smooth);
// libapriltag (tag36h11 at `decimate`, its default edge refinement) with IPPE on each frame's
// corners, the solution of least reprojection error: what a peer's pipeline gives.
PoseStability runAprilTagIppe(const PoseSequence& sequence, int decimate);

}  // namespace arbci::test

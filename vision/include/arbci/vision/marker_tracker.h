// Markers over frames: stable identities and, optionally, smoothed corners.
//  - A square whose decode failed this frame keeps the identity it had in the last few frames
//    when it is clearly the same square (similar area, close centre; ARToolKitPlus's rule); it is
//    reported with from_history set and a reduced confidence. Nothing is reported without a
//    square in the frame.
//  - A different identity decoded where a confirmed one was seen last frame must repeat in a
//    second frame before it replaces it, so a single misread cannot flicker an ID.
//  - Corner smoothing (optional) is a One-Euro filter per coordinate: heavy when the marker is
//    still, light when it moves, so it removes jitter without lagging a moving marker.
#pragma once

#include <vector>

#include "arbci/vision/marker.h"
#include "arbci/vision/marker_detector.h"

namespace arbci::vision {

struct TrackerOptions {
  int keep_frames = 3;  // how long an identity is kept for squares that fail to decode
  bool smooth_corners = false;
  double min_cutoff_hz = 1.0;  // One-Euro: cutoff at rest
  double beta = 0.2;           // One-Euro: cutoff increase per px/s of corner speed
  double derivative_cutoff_hz = 1.0;
};

class MarkerTracker {
 public:
  explicit MarkerTracker(TrackerOptions options = {});

  // The frame's stable markers from its detections and all its square outlines (with their ideal
  // corners by index when the detector has a lens); `time_s` is the frame's capture time
  // (smoothing uses the interval between frames).
  std::vector<MarkerDetection> update(const std::vector<MarkerDetection>& detections,
                                      const std::vector<SquareCorners>& squares, double time_s,
                                      const std::vector<SquareCorners>* ideal_squares = nullptr);
  void reset();

 private:
  struct OneEuro {
    double value = 0, derivative = 0;
    bool primed = false;
    double filter(double x, double dt, const TrackerOptions& o);
  };
  struct Track {
    MarkerDetection marker;  // as last reported
    int last_frame = 0;
    int seen = 0;         // consecutive frames with a decode
    int pending_id = -1;  // a different id decoded here once, awaiting confirmation
    std::array<OneEuro, 8> filters;
  };
  void smooth(Track& track, MarkerDetection& marker, double dt);

  TrackerOptions options_;
  std::vector<Track> tracks_;
  int frame_ = 0;
  double last_time_ = 0.0;
};

}  // namespace arbci::vision

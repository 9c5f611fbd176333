// A marker with one corner covered, as a gripper's finger or a hand covers it during a grasp:
// one marker at a random pose and a disc over one of its corners, dark or light, its radius a
// given fraction of the marker's side. Drawn for any family, so a peer reads the same scene with
// its own marker.
#pragma once

#include <opencv2/core.hpp>

#include "support/synthetic_markers.h"

namespace arbci::test {

enum class Occluder { Dark, Light };

struct OccludedFrame {
  cv::Mat image;  // 640x480 grey
  Corners truth;  // the black square's corners, TL TR BR BL
};

// The scene `seed` (pose, corner, and radius drawn between `min_fraction` and `max_fraction` of
// the marker's side) with `family`'s marker `id`: the same seed gives the same scene whatever the
// family.
OccludedFrame occludedMarkerFrame(MarkerFamily family, int id, Occluder occluder,
                                  double min_fraction, double max_fraction, unsigned seed);

}  // namespace arbci::test

// Scores a detector's output on a synthetic frame against its ground truth.
#pragma once

#include <vector>

#include "synthetic_markers.h"

namespace arbci::test {

struct FoundMarker {
  int id = -1;
  Corners corners;
};

struct Score {
  int truth = 0;                  // markers in the frames
  int found = 0;                  // markers detected with their right id
  int wrong_id = 0;               // detections on a marker with another id
  int false_positive = 0;         // detections on no marker (decoys, background) or duplicates
  double corner_error_sum = 0.0;  // over the corners of found markers, px
  int corners = 0;

  void add(const Score& other);
  double recall() const { return truth ? static_cast<double>(found) / truth : 0.0; }
  double meanCornerError() const { return corners ? corner_error_sum / corners : 0.0; }
};

// `ordered`: the detector reports corners in the printed order TL, TR, BR, BL; otherwise the best
// cyclic assignment is used (AprilTag reports its own order).
Score scoreFrame(const std::vector<int>& ids, const std::vector<Corners>& truth,
                 const std::vector<FoundMarker>& detections, bool ordered);

}  // namespace arbci::test

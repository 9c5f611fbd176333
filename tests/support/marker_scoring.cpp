#include "marker_scoring.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace arbci::test {
namespace {

bool inside(const Corners& quad, cv::Point2f p) {
  int positive = 0, negative = 0;
  for (int k = 0; k < 4; ++k) {
    const cv::Point2f e = quad[(k + 1) % 4] - quad[k], d = p - quad[k];
    const float cross = e.x * d.y - e.y * d.x;
    positive += cross > 0;
    negative += cross < 0;
  }
  return positive == 0 || negative == 0;
}

double cornerError(const Corners& found, const Corners& truth, bool ordered) {
  double best = std::numeric_limits<double>::max();
  for (int shift = 0; shift < (ordered ? 1 : 4); ++shift) {
    for (int reverse = 0; reverse < (ordered ? 1 : 2); ++reverse) {
      double sum = 0.0;
      for (int k = 0; k < 4; ++k) {
        const int j = reverse ? (shift - k + 4) % 4 : (shift + k) % 4;
        sum += cv::norm(found[j] - truth[k]);
      }
      best = std::min(best, sum);
    }
  }
  return best;
}

}  // namespace

void Score::add(const Score& other) {
  truth += other.truth;
  found += other.found;
  wrong_id += other.wrong_id;
  false_positive += other.false_positive;
  corner_error_sum += other.corner_error_sum;
  corners += other.corners;
}

Score scoreFrame(const std::vector<int>& ids, const std::vector<Corners>& truth,
                 const std::vector<FoundMarker>& detections, bool ordered) {
  Score score;
  score.truth = static_cast<int>(truth.size());
  std::vector<bool> matched(truth.size(), false);
  for (const FoundMarker& detection : detections) {
    const cv::Point2f centre = (detection.corners[0] + detection.corners[1] + detection.corners[2] +
                                detection.corners[3]) *
                               0.25f;
    int on = -1;
    for (size_t i = 0; i < truth.size(); ++i) {
      if (inside(truth[i], centre)) on = static_cast<int>(i);
    }
    if (on < 0 || matched[on]) {
      ++score.false_positive;
    } else if (detection.id != ids[on]) {
      ++score.wrong_id;
    } else {
      matched[on] = true;
      ++score.found;
      score.corner_error_sum += cornerError(detection.corners, truth[on], ordered);
      score.corners += 4;
    }
  }
  return score;
}

}  // namespace arbci::test

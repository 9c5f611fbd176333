#include "arbci/vision/marker_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace arbci::vision {
namespace {

cv::Point2f centre(const std::array<cv::Point2f, 4>& q) {
  return (q[0] + q[1] + q[2] + q[3]) * 0.25f;
}

float area(const std::array<cv::Point2f, 4>& q) {
  float a = 0.0f;
  for (int k = 0; k < 4; ++k) a += q[k].x * q[(k + 1) % 4].y - q[(k + 1) % 4].x * q[k].y;
  return std::abs(a) * 0.5f;
}

// ARToolKitPlus's test for the same square in another frame: area within a factor of 1.43 and
// centre moved less than sqrt(area / 2).
bool sameSquare(const std::array<cv::Point2f, 4>& a, const std::array<cv::Point2f, 4>& b) {
  const float area_a = area(a), area_b = area(b);
  if (area_a <= 0.0f || area_b <= 0.0f) return false;
  const float ratio = area_a / area_b;
  if (ratio < 0.7f || ratio > 1.43f) return false;
  const cv::Point2f d = centre(a) - centre(b);
  return d.dot(d) / area_b < 0.5f;
}

// The square's corners in the rotation that best matches the previous printed-corner order.
std::array<cv::Point2f, 4> alignCorners(const SquareCorners& square,
                                        const std::array<cv::Point2f, 4>& previous) {
  int best = 0;
  float best_distance = std::numeric_limits<float>::max();
  for (int shift = 0; shift < 4; ++shift) {
    float distance = 0.0f;
    for (int k = 0; k < 4; ++k) {
      const cv::Point2f d = square[(k + shift) % 4] - previous[k];
      distance += d.dot(d);
    }
    if (distance < best_distance) {
      best_distance = distance;
      best = shift;
    }
  }
  std::array<cv::Point2f, 4> aligned;
  for (int k = 0; k < 4; ++k) aligned[k] = square[(k + best) % 4];
  return aligned;
}

double smoothingFactor(double dt, double cutoff_hz) {
  const double tau = 1.0 / (2.0 * std::numbers::pi * cutoff_hz);
  return 1.0 / (1.0 + tau / dt);
}

}  // namespace

MarkerTracker::MarkerTracker(TrackerOptions options) : options_(options) {}

void MarkerTracker::reset() {
  tracks_.clear();
  frame_ = 0;
}

double MarkerTracker::OneEuro::filter(double x, double dt, const TrackerOptions& o) {
  if (!primed || dt <= 0.0) {
    value = x;
    derivative = 0.0;
    primed = true;
    return x;
  }
  const double raw_derivative = (x - value) / dt;
  derivative += smoothingFactor(dt, o.derivative_cutoff_hz) * (raw_derivative - derivative);
  const double cutoff = o.min_cutoff_hz + o.beta * std::abs(derivative);
  value += smoothingFactor(dt, cutoff) * (x - value);
  return value;
}

void MarkerTracker::smooth(Track& track, MarkerDetection& marker, double dt) {
  if (!options_.smooth_corners) return;
  marker.measured_ideal_corners = marker.ideal_corners;
  for (int k = 0; k < 4; ++k) {
    const cv::Point2f before = marker.corners[k];
    marker.corners[k].x =
        static_cast<float>(track.filters[2 * k].filter(marker.corners[k].x, dt, options_));
    marker.corners[k].y =
        static_cast<float>(track.filters[2 * k + 1].filter(marker.corners[k].y, dt, options_));
    marker.ideal_corners[k] += marker.corners[k] - before;  // the same correction, locally
  }
}

std::vector<MarkerDetection> MarkerTracker::update(
    const std::vector<MarkerDetection>& detections, const std::vector<SquareCorners>& squares,
    double time_s, const std::vector<SquareCorners>* ideal_squares) {
  ++frame_;
  const double dt = frame_ > 1 ? time_s - last_time_ : 0.0;
  last_time_ = time_s;
  std::vector<MarkerDetection> out;
  std::vector<bool> track_used(tracks_.size(), false);

  for (MarkerDetection marker : detections) {
    // The track this square continues: same place (any id), preferring the same id.
    int match = -1;
    for (size_t t = 0; t < tracks_.size(); ++t) {
      if (track_used[t] || !sameSquare(marker.corners, tracks_[t].marker.corners)) continue;
      if (match < 0 || tracks_[t].marker.id == marker.id) match = static_cast<int>(t);
    }
    if (match < 0) {
      Track track;
      track.marker = marker;
      track.last_frame = frame_;
      track.seen = 1;
      smooth(track, marker, 0.0);
      track.marker = marker;
      tracks_.push_back(track);
      track_used.push_back(true);
      out.push_back(marker);
      continue;
    }
    Track& track = tracks_[match];
    track_used[match] = true;
    const bool confirmed = track.seen >= 2 && track.last_frame == frame_ - 1;
    if (marker.id != track.marker.id && confirmed && track.pending_id != marker.id) {
      // A new identity where a confirmed one stood: hold it until it repeats.
      track.pending_id = marker.id;
      marker.id = track.marker.id;
      const auto turned = alignCorners(marker.corners, track.marker.corners);
      for (int shift = 0; shift < 4; ++shift) {
        if (marker.corners[shift] == turned[0]) {
          const auto ideal = marker.ideal_corners;
          for (int k = 0; k < 4; ++k) marker.ideal_corners[k] = ideal[(k + shift) % 4];
        }
      }
      marker.corners = turned;
      marker.from_history = true;
      marker.confidence = track.marker.confidence * 0.5f;
    } else {
      if (marker.id != track.marker.id) {
        for (OneEuro& f : track.filters) f.primed = false;  // a different marker: restart
        track.seen = 0;
      }
      track.pending_id = -1;
      ++track.seen;
    }
    track.last_frame = frame_;
    smooth(track, marker, dt);
    track.marker = marker;
    out.push_back(marker);
  }

  // Confirmed identities on squares that failed to decode this frame.
  for (size_t t = 0; t < tracks_.size(); ++t) {
    if (track_used[t]) continue;
    Track& track = tracks_[t];
    if (frame_ - track.last_frame > options_.keep_frames) continue;
    for (size_t s = 0; s < squares.size(); ++s) {
      const SquareCorners& square = squares[s];
      if (!sameSquare(square, track.marker.corners)) continue;
      bool taken = false;
      for (const MarkerDetection& m : out) taken = taken || sameSquare(m.corners, square);
      if (taken) break;
      MarkerDetection marker = track.marker;
      // The same turn of the square for its ideal corners.
      marker.corners = alignCorners(square, track.marker.corners);
      marker.ideal_corners = marker.corners;
      if (ideal_squares && s < ideal_squares->size()) {
        for (int shift = 0; shift < 4; ++shift) {
          if (square[shift] == marker.corners[0]) {
            for (int k = 0; k < 4; ++k)
              marker.ideal_corners[k] = (*ideal_squares)[s][(k + shift) % 4];
          }
        }
      }
      marker.from_history = true;
      marker.confidence = track.marker.confidence * 0.5f;
      smooth(track, marker, dt);
      track.marker.corners = marker.corners;
      track.seen = 0;
      out.push_back(marker);
      break;
    }
  }
  std::erase_if(tracks_,
                [&](const Track& t) { return frame_ - t.last_frame > options_.keep_frames; });
  return out;
}

}  // namespace arbci::vision

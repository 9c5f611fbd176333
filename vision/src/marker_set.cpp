#include "arbci/vision/marker_set.h"

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "arbci/vision/camera_model.h"

namespace arbci::vision {
namespace {

// The next line that is not blank or a # comment.
bool nextLine(std::istream& in, std::string& line) {
  while (std::getline(in, line)) {
    const size_t start = line.find_first_not_of(" \t\r");
    if (start == std::string::npos || line[start] == '#') continue;
    return true;
  }
  return false;
}

}  // namespace

MarkerSet::MarkerSet(std::vector<MarkerPlacement> markers) : markers_(std::move(markers)) {}

MarkerSet MarkerSet::loadArToolKitConfig(const std::filesystem::path& path, double unit_m) {
  const std::string source = path.string();
  std::ifstream in(path);
  if (!in) throw CalibrationFileError(source + ": cannot open");
  std::string line;
  int count = 0;
  if (!nextLine(in, line) || !(std::istringstream(line) >> count) || count <= 0 || count > 1000) {
    throw CalibrationFileError(source + ": the first entry must be the number of markers");
  }
  std::vector<MarkerPlacement> markers;
  for (int m = 0; m < count; ++m) {
    const std::string where = source + ": marker " + std::to_string(m) + ": ";
    MarkerPlacement placement;
    double width = 0.0, centre_x = 0.0, centre_y = 0.0;
    if (!nextLine(in, line) || !(std::istringstream(line) >> placement.id)) {
      throw CalibrationFileError(where + "expected a numeric marker id");
    }
    if (!nextLine(in, line) || !(std::istringstream(line) >> width) || !(width > 0.0)) {
      throw CalibrationFileError(where + "expected a positive width");
    }
    if (!nextLine(in, line) || !(std::istringstream(line) >> centre_x >> centre_y)) {
      throw CalibrationFileError(where + "expected the centre 'x y'");
    }
    double t[3][4];
    for (int r = 0; r < 3; ++r) {
      std::istringstream row;
      if (!nextLine(in, line))
        throw CalibrationFileError(where + "expected 3 rows of the 3x4 transform");
      row.str(line);
      for (int c = 0; c < 4; ++c) {
        if (!(row >> t[r][c]))
          throw CalibrationFileError(where + "transform row " + std::to_string(r + 1) +
                                     " needs 4 numbers");
      }
    }
    placement.size_m = width * unit_m;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) placement.T_set_marker.rotation(r, c) = t[r][c];
      placement.T_set_marker.translation[r] = t[r][3] * unit_m;
    }
    // ARToolKit places the corners at centre +- width / 2 in the marker's own frame.
    placement.T_set_marker.translation +=
        placement.T_set_marker.rotation * cv::Vec3d(centre_x * unit_m, centre_y * unit_m, 0.0);
    markers.push_back(placement);
  }
  return MarkerSet(std::move(markers));
}

std::optional<std::array<cv::Point3d, 4>> MarkerSet::cornersOf(int id) const {
  for (const MarkerPlacement& m : markers_) {
    if (m.id != id) continue;
    std::array<cv::Point3d, 4> corners;
    const std::array<cv::Point3d, 4> local = markerCorners(m.size_m);
    for (int k = 0; k < 4; ++k) {
      const cv::Vec3d p = m.T_set_marker.apply(cv::Vec3d(local[k].x, local[k].y, local[k].z));
      corners[k] = cv::Point3d(p[0], p[1], p[2]);
    }
    return corners;
  }
  return std::nullopt;
}

bool MarkerSet::planar() const {
  for (const MarkerPlacement& m : markers_) {
    if (const auto corners = cornersOf(m.id)) {
      for (const cv::Point3d& p : *corners) {
        if (std::abs(p.z) > 1e-9) return false;
      }
    }
  }
  return true;
}

std::optional<SetPose> estimateSetPose(const MarkerSet& set,
                                       const std::vector<MarkerDetection>& detections,
                                       const cv::Matx33d& camera_matrix,
                                       const PoseOptions& options) {
  std::map<int, int> seen;
  for (const MarkerDetection& d : detections) ++seen[d.id];
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  SetPose result;
  for (const MarkerDetection& d : detections) {
    if (seen[d.id] != 1) continue;
    const auto corners = set.cornersOf(d.id);
    if (!corners) continue;
    for (int k = 0; k < 4; ++k) {
      object.push_back((*corners)[k]);
      image.emplace_back(d.ideal_corners[k].x, d.ideal_corners[k].y);
    }
    result.used_ids.push_back(d.id);
  }
  if (object.empty()) return std::nullopt;
  result.estimate = estimatePose(object, image, camera_matrix, options);
  return result;
}

}  // namespace arbci::vision

#include "simulation/scene_painter.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "arbci/vision/marker_printer.h"

namespace arbci::session {
namespace {

// Points nearer than this to the camera's plane are cut off (a table reaching behind the head).
constexpr double kNearM = 0.02;

cv::Scalar bgr(const cv::Vec3f& rgb) {
  auto level = [](float v) { return std::round(std::clamp(v, 0.0f, 1.0f) * 255.0f); };
  return {level(rgb[2]), level(rgb[1]), level(rgb[0])};
}

// The part of a convex polygon in front of the plane z = kNearM (Sutherland-Hodgman, one plane).
std::vector<cv::Vec3d> clipNear(const std::vector<cv::Vec3d>& polygon) {
  std::vector<cv::Vec3d> out;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const cv::Vec3d& a = polygon[i];
    const cv::Vec3d& b = polygon[(i + 1) % polygon.size()];
    const bool a_in = a[2] >= kNearM, b_in = b[2] >= kNearM;
    if (a_in) out.push_back(a);
    if (a_in != b_in) out.push_back(a + (b - a) * ((kNearM - a[2]) / (b[2] - a[2])));
  }
  return out;
}

// The faces of a box in the frame `pose` (its top face centred at the origin, extending down by
// `height`), shaded as lit from above: the sides facing +-y at 0.75 of `color`, +-x at 0.6.
std::vector<std::pair<std::array<cv::Vec3d, 4>, cv::Vec3d>> boxFaces(const vision::Pose& pose,
                                                                     double width, double depth,
                                                                     double height) {
  const double w = width / 2, d = depth / 2, h = height;
  auto p = [&](double x, double y, double z) { return pose.apply(cv::Vec3d(x, y, z)); };
  auto n = [&](double x, double y, double z) { return pose.rotation * cv::Vec3d(x, y, z); };
  return {{{p(-w, d, 0), p(w, d, 0), p(w, -d, 0), p(-w, -d, 0)}, n(0, 0, 1)},
          {{p(-w, -d, 0), p(w, -d, 0), p(w, -d, -h), p(-w, -d, -h)}, n(0, -1, 0)},
          {{p(w, d, 0), p(-w, d, 0), p(-w, d, -h), p(w, d, -h)}, n(0, 1, 0)},
          {{p(w, -d, 0), p(w, d, 0), p(w, d, -h), p(w, -d, -h)}, n(1, 0, 0)},
          {{p(-w, d, 0), p(-w, -d, 0), p(-w, -d, -h), p(-w, d, -h)}, n(-1, 0, 0)}};
}

void addBox(std::vector<ScenePainter::Face>& faces, const vision::Pose& pose, double width,
            double depth, double height, const cv::Vec3f& color, const cv::Vec3f& top_color) {
  const auto box = boxFaces(pose, width, depth, height);
  for (size_t i = 0; i < box.size(); ++i) {
    const cv::Vec3f shade = i == 0 ? top_color : color * (i < 3 ? 0.75f : 0.6f);
    faces.push_back({box[i].first, box[i].second, shade, nullptr});
  }
}

}  // namespace

ScenePainter::ScenePainter(const cv::Matx33d& camera_matrix, cv::Size image_size, int supersample)
    : camera_matrix_(camera_matrix), size_(image_size), supersample_(std::max(1, supersample)) {}

cv::Scalar ScenePainter::background() {
  return bgr({0.30f, 0.32f, 0.35f});
}

cv::Point2d ScenePainter::toCanvas(const cv::Vec3d& p) const {
  const cv::Matx33d& k = camera_matrix_;
  const double u = k(0, 0) * p[0] / p[2] + k(0, 2), v = k(1, 1) * p[1] / p[2] + k(1, 2);
  // Image pixel centres at integers; a canvas pixel is 1/supersample of an image pixel.
  return {(u + 0.5) * supersample_ - 0.5, (v + 0.5) * supersample_ - 0.5};
}

void ScenePainter::fill(const std::vector<cv::Vec3d>& camera_points, const cv::Vec3f& rgb) {
  const std::vector<cv::Vec3d> front = clipNear(camera_points);
  if (front.size() < 3) return;
  std::vector<cv::Point2d> corners;
  double top = INFINITY, bottom = -INFINITY;
  for (const cv::Vec3d& p : front) {
    corners.push_back(toCanvas(p));
    top = std::min(top, corners.back().y);
    bottom = std::max(bottom, corners.back().y);
  }
  // The canvas pixels whose centre lies inside (half-open, as a GPU rasterises: two faces sharing
  // an edge never both draw a pixel, and no face grows by the half pixel an outline would add).
  const int first = std::max(0, static_cast<int>(std::ceil(top))),
            last = std::min(canvas_.rows - 1, static_cast<int>(std::ceil(bottom)) - 1);
  const cv::Vec3b color = [&] {
    const cv::Scalar c = bgr(rgb);
    return cv::Vec3b(static_cast<uchar>(c[0]), static_cast<uchar>(c[1]), static_cast<uchar>(c[2]));
  }();
  for (int row = first; row <= last; ++row) {
    double left = INFINITY, right = -INFINITY;
    for (size_t i = 0; i < corners.size(); ++i) {
      const cv::Point2d& a = corners[i];
      const cv::Point2d& b = corners[(i + 1) % corners.size()];
      if ((row < a.y) == (row < b.y)) continue;  // this edge does not cross the row's centre
      const double x = a.x + (row - a.y) * (b.x - a.x) / (b.y - a.y);
      left = std::min(left, x);
      right = std::max(right, x);
    }
    const int from = std::max(0, static_cast<int>(std::ceil(left))),
              to = std::min(canvas_.cols, static_cast<int>(std::ceil(right)));
    cv::Vec3b* pixels = canvas_.ptr<cv::Vec3b>(row);
    std::fill(pixels + std::min(from, to), pixels + to, color);
  }
}

const cv::Mat& ScenePainter::enlarged(const cv::Mat& texels, int scale, const cv::Vec3f& surround) {
  const auto key = std::make_pair(&texels, scale);
  auto found = enlarged_.find(key);
  if (found != enlarged_.end()) return found->second;
  // One texel of what surrounds the print around it: its outer edge is then interpolated like
  // any other (the texels beyond the last are not drawn at all).
  cv::Mat large, framed;
  cv::resize(texels, large, texels.size() * scale, 0, 0, cv::INTER_NEAREST);
  cv::copyMakeBorder(large, framed, 1, 1, 1, 1, cv::BORDER_CONSTANT, bgr(surround));
  return enlarged_.emplace(key, framed).first->second;
}

void ScenePainter::texture(const std::array<cv::Vec3d, 4>& camera_points, const cv::Mat& texels,
                           const cv::Vec3f& surround) {
  for (const cv::Vec3d& p : camera_points) {
    if (p[2] < kNearM) return;  // a print reaching behind the camera: not in any scene we draw
  }
  std::vector<cv::Point2f> to;
  for (const cv::Vec3d& p : camera_points) {
    const cv::Point2d c = toCanvas(p);
    to.emplace_back(static_cast<float>(c.x), static_cast<float>(c.y));
  }
  // The level of detail: texels enlarged by the power of two nearest to a canvas pixel each.
  double longest = 0.0;
  for (size_t i = 0; i < 4; ++i) longest = std::max(longest, cv::norm(to[i] - to[(i + 1) % 4]));
  const double across = std::max(texels.cols, texels.rows);
  const int scale =
      1 << std::clamp(static_cast<int>(std::lround(std::log2(longest / across))), 0, 6);
  const cv::Mat& large = enlarged(texels, scale, surround);
  // The face's corners on the texels' outer edges (inside the frame): texel edges, not centres.
  const float m = 0.5f, w = static_cast<float>(large.cols) - 1.5f,
              h = static_cast<float>(large.rows) - 1.5f;
  const cv::Matx33d warp =
      cv::getPerspectiveTransform(std::vector<cv::Point2f>{{m, m}, {w, m}, {w, h}, {m, h}}, to);
  // Where the whole texture, margin included, lands.
  std::vector<cv::Point2f> outline;
  const float x1 = static_cast<float>(large.cols) - 0.5f,
              y1 = static_cast<float>(large.rows) - 0.5f;
  cv::perspectiveTransform(
      std::vector<cv::Point2f>{{-0.5f, -0.5f}, {x1, -0.5f}, {x1, y1}, {-0.5f, y1}}, outline, warp);
  const cv::Rect area = ((cv::boundingRect(outline) + cv::Size(2, 2)) - cv::Point(1, 1)) &
                        cv::Rect({}, canvas_.size());
  if (area.empty()) return;
  const cv::Matx33d shift(1, 0, -area.x, 0, 1, -area.y, 0, 0, 1);
  cv::Mat target = canvas_(area);
  // Canvas pixels whose centre falls outside the texture keep what is under them.
  cv::warpPerspective(large, target, shift * warp, area.size(), cv::INTER_LINEAR,
                      cv::BORDER_TRANSPARENT);
}

void ScenePainter::draw(const Face& face) {
  if (face.outward != cv::Vec3d() && face.outward.dot(eye_ - face.corners[0]) <= 0.0) return;
  std::array<cv::Vec3d, 4> camera_points;
  for (size_t i = 0; i < 4; ++i) camera_points[i] = T_cam_world_.apply(face.corners[i]);
  if (face.texture) {
    texture(camera_points, *face.texture, face.rgb);
  } else {
    fill({camera_points.begin(), camera_points.end()}, face.rgb);
  }
}

const cv::Mat& ScenePainter::markerTexels(const SceneMarker& marker) {
  const auto key = std::make_tuple(std::string(marker.kind.name), marker.id,
                                   static_cast<int>(std::lround(marker.border * 1000)));
  auto found = markers_.find(key);
  if (found != markers_.end()) return found->second;
  cv::Mat texels;
  cv::cvtColor(vision::markerCells(marker.kind, marker.id, marker.border), texels,
               cv::COLOR_GRAY2BGR);
  return markers_.emplace(key, texels).first->second;
}

const cv::Mat& ScenePainter::boardTexels(const SceneBoard& board) {
  const auto key = std::make_pair(board.inner_corners.width, board.inner_corners.height);
  auto found = boards_.find(key);
  if (found != boards_.end()) return found->second;
  // A texel a square, a white margin of one square around them.
  const int squares_x = board.inner_corners.width + 1, squares_y = board.inner_corners.height + 1;
  cv::Mat texels(squares_y + 2, squares_x + 2, CV_8UC3, cv::Scalar::all(255));
  for (int y = 0; y < squares_y; ++y) {
    for (int x = 0; x < squares_x; ++x) {
      if ((x + y) % 2 == 0) texels.at<cv::Vec3b>(y + 1, x + 1) = cv::Vec3b(0, 0, 0);
    }
  }
  return boards_.emplace(key, texels).first->second;
}

cv::Mat ScenePainter::paint(const Scene& scene, const vision::Pose& T_cam_world) {
  T_cam_world_ = T_cam_world;
  eye_ = T_cam_world.inverse().translation;
  canvas_.create(size_.height * supersample_, size_.width * supersample_, CV_8UC3);
  canvas_.setTo(background());
  drawTable(scene);
  for (const Body& body : bodies(scene)) {
    for (const Face& face : body.faces) draw(face);
  }
  cv::Mat image;
  cv::resize(canvas_, image, size_, 0, 0, cv::INTER_AREA);
  return image;
}

ScenePainter::Face ScenePainter::markerFace(const SceneMarker& marker, const vision::Pose& face,
                                            double lift) {
  const double h = marker.side_m / 2;
  auto p = [&](double x, double y) { return face.apply(cv::Vec3d(x, y, lift)); };
  return Face{{p(-h, h), p(h, h), p(h, -h), p(-h, -h)},
              face.rotation * cv::Vec3d(0, 0, 1),
              {0.95f, 0.95f, 0.95f},  // printed on the white top or quiet zone
              &markerTexels(marker)};
}

void ScenePainter::drawTable(const Scene& scene) {
  // A light grey top, darker far away (soft light from the subject's side), in strips across y
  // fine enough that no step shows (under a grey level each).
  const int strips = 48;
  const double x0 = scene.table_min[0], x1 = scene.table_max[0], z = scene.table_z;
  for (int i = 0; i < strips; ++i) {
    const double y0 = scene.table_min[1] + (scene.table_max[1] - scene.table_min[1]) * i / strips,
                 y1 = scene.table_min[1] +
                      (scene.table_max[1] - scene.table_min[1]) * (i + 1) / strips;
    const float far = (static_cast<float>(i) + 0.5f) / strips;
    const cv::Vec3f near_color(0.62f, 0.60f, 0.56f), far_color(0.52f, 0.50f, 0.47f);
    draw({{cv::Vec3d(x0, y0, z), cv::Vec3d(x1, y0, z), cv::Vec3d(x1, y1, z), cv::Vec3d(x0, y1, z)},
          cv::Vec3d(0, 0, 1),
          near_color * (1.0f - far) + far_color * far,
          nullptr});
  }
  // The reference marker's white quiet zone and the marker, on the table under everything else.
  const double quiet = scene.reference.side_m * 1.4 / 2;
  const vision::Pose& r = scene.T_world_reference;
  auto p = [&](double x, double y) { return r.apply(cv::Vec3d(x, y, 0.0005)); };
  draw({{p(-quiet, quiet), p(quiet, quiet), p(quiet, -quiet), p(-quiet, -quiet)},
        r.rotation * cv::Vec3d(0, 0, 1),
        {0.95f, 0.95f, 0.95f},
        nullptr});
  draw(markerFace(scene.reference, r, 0.0012));
}

std::vector<ScenePainter::Body> ScenePainter::bodies(const Scene& scene) {
  std::vector<Body> bodies;
  auto addBody = [&](const cv::Vec3d& centre, std::vector<Face> faces) {
    bodies.push_back({cv::norm(eye_ - centre), std::move(faces)});
  };
  auto addBoxBody = [&](const vision::Pose& pose, double width, double depth, double height,
                        const cv::Vec3f& color) {
    std::vector<Face> faces;
    addBox(faces, pose, width, depth, height, color, color);
    addBody(pose.apply(cv::Vec3d(0, 0, -height / 2)), std::move(faces));
  };
  for (const SceneObject& o : scene.objects) {
    // Coloured sides, a white top carrying the marker.
    std::vector<Face> faces;
    addBox(faces, o.T_world_top, o.width_m, o.width_m, o.height_m, o.color, {0.95f, 0.95f, 0.95f});
    faces.push_back(markerFace(o.marker, o.T_world_top, 0.0007));
    addBody(o.T_world_top.apply(cv::Vec3d(0, 0, -o.height_m / 2)), std::move(faces));
    if (o.covered) {
      // A hand, flat, two centimetres above the marker and wider than it.
      vision::Pose hand = o.T_world_top;
      hand.translation += o.T_world_top.rotation * cv::Vec3d(0.01, 0.0, 0.035);
      addBoxBody(hand, o.marker.side_m * 1.8, o.marker.side_m * 1.5, 0.015, {0.87f, 0.68f, 0.56f});
    }
    if (o.gripper_over_corner) {
      // A fingertip, its rubber pad nearly black, a few millimetres above the marker's printed
      // top-left corner: it hides 18 % of the side along both edges from that corner, and merges
      // with the black border there (the hard case: the outline is no longer a square).
      const double h = o.marker.side_m / 2, pad = o.marker.side_m * 0.36;
      vision::Pose tip = o.T_world_top;
      tip.translation += o.T_world_top.rotation * cv::Vec3d(-h, h, 0.008);
      addBoxBody(tip, pad, pad, 0.006, {0.06f, 0.06f, 0.06f});
    }
  }
  if (scene.gripper) {
    const cv::Vec3d t = scene.gripper->tool;
    const double gap = 0.02 + 0.05 * scene.gripper->opening;
    const cv::Vec3f dark(0.25f, 0.25f, 0.25f), metal(0.45f, 0.47f, 0.5f);
    auto at = [](const cv::Vec3d& top) { return vision::Pose{cv::Matx33d::eye(), top}; };
    addBoxBody(at(t + cv::Vec3d(0, 0, 0.09)), 0.10, 0.04, 0.03, dark);                  // palm
    addBoxBody(at(t + cv::Vec3d(-gap / 2 - 0.006, 0, 0.06)), 0.012, 0.03, 0.06, dark);  // fingers
    addBoxBody(at(t + cv::Vec3d(gap / 2 + 0.006, 0, 0.06)), 0.012, 0.03, 0.06, dark);
    addBoxBody(at(t + cv::Vec3d(0, 0, 0.30)), 0.05, 0.05, 0.20, metal);  // wrist
  }
  if (scene.board) {
    const SceneBoard& b = *scene.board;
    const double w = (b.inner_corners.width + 3) * b.square_m / 2,
                 h = (b.inner_corners.height + 3) * b.square_m / 2;
    auto p = [&](double x, double y) { return b.T_world_board.apply(cv::Vec3d(x, y, 0.0)); };
    addBody(
        b.T_world_board.translation,
        {Face{{p(-w, h), p(w, h), p(w, -h), p(-w, -h)}, cv::Vec3d(), {1, 1, 1}, &boardTexels(b)}});
  }
  // Far to near.
  std::stable_sort(bodies.begin(), bodies.end(),
                   [](const Body& a, const Body& b) { return a.distance > b.distance; });
  return bodies;
}

}  // namespace arbci::session

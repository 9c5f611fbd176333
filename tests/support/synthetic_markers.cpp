#include "synthetic_markers.h"

#include <apriltag.h>
#include <tag36h11.h>

#include <algorithm>
#include <cmath>
#include <opencv2/aruco.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>

#include "arbci/vision/id_codes.h"

namespace arbci::test {
namespace {

constexpr float kBlackCells = 8.0f;  // border + 6 code + border

struct Camera {
  float f, cx, cy;
  cv::Point2f project(const cv::Point3f& p) const {
    return {f * p.x / p.z + cx, f * p.y / p.z + cy};
  }
};

cv::Matx33f rotation(cv::Vec3f axis, float angle) {
  cv::Mat r;
  cv::Rodrigues(cv::Mat(axis * angle), r);
  return cv::Matx33f(r);
}

// The rotation that turns the optical axis (0, 0, 1) onto the ray through `centre`.
cv::Matx33f towardsRay(const cv::Point3f& centre) {
  const cv::Vec3f ray = cv::normalize(cv::Vec3f(centre.x, centre.y, centre.z));
  const cv::Vec3f axis = cv::Vec3f(0, 0, 1).cross(ray);
  const float sine = static_cast<float>(cv::norm(axis));
  if (sine < 1e-6f) return cv::Matx33f::eye();
  return rotation(axis / sine, std::atan2(sine, ray[2]));
}

// The corners of a square of half-side `half` in the marker plane, posed and projected.
Corners projectSquare(const Camera& camera, const cv::Matx33f& r, const cv::Point3f& centre,
                      float half) {
  const cv::Vec3f local[4] = {
      {-half, -half, 0}, {half, -half, 0}, {half, half, 0}, {-half, half, 0}};
  Corners corners;
  for (int k = 0; k < 4; ++k) {
    const cv::Vec3f p = r * local[k];
    corners[k] = camera.project(centre + cv::Point3f(p[0], p[1], p[2]));
  }
  return corners;
}

cv::Point2f centroid(const Corners& q) {
  return (q[0] + q[1] + q[2] + q[3]) * 0.25f;
}

float radius(const Corners& q) {
  const cv::Point2f c = centroid(q);
  float r = 0.0f;
  for (const cv::Point2f& p : q) r = std::max(r, static_cast<float>(cv::norm(p - c)));
  return r;
}

// The quiet-zone square `quiet` cells around a marker's black square (same plane).
Corners outerSquare(const Corners& black, int quiet) {
  const float q = static_cast<float>(quiet), far = q + kBlackCells, all = far + q;
  const std::vector<cv::Point2f> from{{q, q}, {far, q}, {far, far}, {q, far}};
  const cv::Matx33d h =
      cv::getPerspectiveTransform(from, std::vector<cv::Point2f>(black.begin(), black.end()));
  const cv::Point2f unit[4] = {{0, 0}, {all, 0}, {all, all}, {0, all}};
  Corners out;
  for (int k = 0; k < 4; ++k) {
    const cv::Vec3d p = h * cv::Vec3d(unit[k].x, unit[k].y, 1.0);
    out[k] = cv::Point2f(static_cast<float>(p[0] / p[2]), static_cast<float>(p[1] / p[2]));
  }
  return out;
}

cv::Mat cellsToImage(const std::vector<std::uint8_t>& cells, int n, int cell_px) {
  cv::Mat small(n, n, CV_8UC1);
  for (int i = 0; i < n * n; ++i) small.data[i] = cells[i];
  cv::Mat image;
  cv::resize(small, image, cv::Size(n * cell_px, n * cell_px), 0, 0, cv::INTER_NEAREST);
  return image;
}

// Decoys: square, black-bordered shapes that are no family's marker.
cv::Mat decoyImage(int style, int cell_px) {
  std::vector<std::uint8_t> cells(100, 255);
  for (int r = 1; r < 9; ++r) {
    for (int c = 1; c < 9; ++c) {
      const bool border = r == 1 || r == 8 || c == 1 || c == 8;
      bool black = border;
      if (style == 0) black = border || ((r >= 4 && r <= 5) && (c >= 4 && c <= 5));  // frame, dot
      if (style == 1) black = border || (((r - 2) / 2 + (c - 2) / 2) % 2 == 0);      // checker
      if (style == 2) black = true;                                                  // solid
      cells[r * 10 + c] = black ? 0 : 255;
    }
  }
  return cellsToImage(cells, 10, cell_px);
}

void drawBackground(cv::Mat& frame, std::mt19937& random) {
  std::uniform_int_distribution<int> grey(0, 255), base(100, 200);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  frame.setTo(base(random));
  const int w = frame.cols, h = frame.rows;
  // A gentle gradient across the table.
  cv::Mat ramp(h, w, CV_32F);
  const float angle = unit(random) * 6.283f, strength = 40.0f * unit(random);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      ramp.at<float>(y, x) = strength * ((x * std::cos(angle) + y * std::sin(angle)) / (w + h));
    }
  }
  cv::Mat f;
  frame.convertTo(f, CV_32F);
  f += ramp;
  f.convertTo(frame, CV_8U);
  // Clutter: shapes, lines and text of any grey.
  for (int i = 0; i < 30; ++i) {
    const cv::Point a(static_cast<int>(unit(random) * w), static_cast<int>(unit(random) * h));
    const cv::Point size(5 + static_cast<int>(unit(random) * w / 6),
                         5 + static_cast<int>(unit(random) * h / 6));
    const cv::Scalar colour(grey(random));
    const int thickness = unit(random) < 0.5f ? cv::FILLED : 1 + static_cast<int>(unit(random) * 4);
    switch (i % 5) {
      case 0:
        cv::rectangle(frame, a, a + size, colour, thickness, cv::LINE_AA);
        break;
      case 1:
        cv::ellipse(frame, a, cv::Size(size.x / 2, size.y / 2), unit(random) * 180, 0, 360, colour,
                    thickness, cv::LINE_AA);
        break;
      case 2:
        cv::line(frame, a, a + size, colour, 1 + static_cast<int>(unit(random) * 5), cv::LINE_AA);
        break;
      case 3:
        cv::putText(frame, "ARBCI 42", a, cv::FONT_HERSHEY_SIMPLEX, 0.4 + unit(random), colour, 1,
                    cv::LINE_AA);
        break;
      case 4:
        cv::circle(frame, a, size.x / 3, colour, thickness, cv::LINE_AA);
        break;
    }
  }
}

// A gain field in [0.15, 1]: a gradient, a vignette and a soft shadow band.
cv::Mat gainField(cv::Size size, std::mt19937& random) {
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const float angle = unit(random) * 6.283f;
  const float band_angle = unit(random) * 6.283f;
  const float band_offset = (unit(random) - 0.5f) * 0.6f * static_cast<float>(size.width);
  const float band_width = (0.12f + 0.15f * unit(random)) * static_cast<float>(size.width);
  const cv::Point2f centre(size.width * 0.5f, size.height * 0.5f);
  const float corner = static_cast<float>(cv::norm(centre));
  cv::Mat gain(size, CV_32F);
  float lo = 1e9f, hi = -1e9f;
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const cv::Point2f d = cv::Point2f(static_cast<float>(x), static_cast<float>(y)) - centre;
      const float along = (d.x * std::cos(angle) + d.y * std::sin(angle)) / (2.0f * corner) + 0.5f;
      const float gradient = 1.0f - 0.6f * along;
      const float r = static_cast<float>(cv::norm(d)) / corner;
      const float vignette = 1.0f - 0.55f * r * r;
      const float across =
          std::abs(d.x * std::cos(band_angle) + d.y * std::sin(band_angle) - band_offset);
      const float edge = std::clamp((across - band_width * 0.5f) / 20.0f + 0.5f, 0.0f, 1.0f);
      const float shadow = 0.35f + 0.65f * edge * edge * (3.0f - 2.0f * edge);
      const float g = gradient * vignette * shadow;
      gain.at<float>(y, x) = g;
      lo = std::min(lo, g);
      hi = std::max(hi, g);
    }
  }
  gain = (gain - lo) * (0.85f / (hi - lo)) + 0.15f;
  return gain;
}

void applyCondition(cv::Mat& frame, Condition condition, std::mt19937& random) {
  if (condition == Condition::MotionBlur || condition == Condition::MotionBlurJpeg ||
      condition == Condition::FastMotionJpeg) {
    const float shortest = condition == Condition::FastMotionJpeg ? 9.0f : 5.0f;
    std::uniform_real_distribution<float> length(shortest, 15.0f), angle(0.0f, 3.14159265f);
    motionBlur(frame, length(random), angle(random));
    if (condition != Condition::MotionBlur) {
      std::vector<std::uint8_t> jpeg;
      cv::imencode(".jpg", frame, jpeg, {cv::IMWRITE_JPEG_QUALITY, 50});
      frame = cv::imdecode(jpeg, cv::IMREAD_GRAYSCALE);
    }
    return;
  }
  if (condition == Condition::UnevenLight || condition == Condition::Combined) {
    cv::Mat f;
    frame.convertTo(f, CV_32F);
    f = f.mul(gainField(frame.size(), random));
    f.convertTo(frame, CV_8U);
  }
  if (condition == Condition::Blur || condition == Condition::Combined) {
    cv::GaussianBlur(frame, frame, cv::Size(0, 0), 1.5);
  }
  if (condition == Condition::Noise || condition == Condition::Combined) {
    cv::Mat noise(frame.size(), CV_32F);
    cv::theRNG().state = random();
    cv::randn(noise, 0.0, 12.0);
    cv::Mat f;
    frame.convertTo(f, CV_32F);
    f += noise;
    f.convertTo(frame, CV_8U);
  }
}

// The synthetic table, or the layout's photograph under Condition::Cluttered.
void drawTable(cv::Mat& frame, const SceneLayout& layout, Condition condition,
               std::mt19937& random) {
  if (condition != Condition::Cluttered) {
    drawBackground(frame, random);
    return;
  }
  if (layout.backdrop.size() != layout.size || layout.backdrop.type() != CV_8UC1) {
    throw std::invalid_argument(
        "the cluttered condition draws the scene over the layout's backdrop: an 8-bit grey image "
        "of the frame's size (backdropFromPhotos)");
  }
  layout.backdrop.copyTo(frame);
}

void drawDecoys(cv::Mat& frame, const SceneLayout& layout) {
  for (size_t i = 0; i < layout.decoys.size(); ++i) {
    drawWarped(frame, decoyImage(layout.decoy_styles[i], 8), outerSquare(layout.decoys[i], 1));
  }
}

}  // namespace

// Smears the frame along a line of `length` px at `angle` (a box kernel on that line).
void motionBlur(cv::Mat& frame, float length, float angle) {
  const int size = static_cast<int>(std::ceil(length)) | 1;
  cv::Mat kernel = cv::Mat::zeros(size * 4, size * 4, CV_32F);  // drawn at 4x, then reduced
  const cv::Point2f centre(size * 2.0f, size * 2.0f);
  const cv::Point2f half(std::cos(angle) * length * 2.0f, std::sin(angle) * length * 2.0f);
  cv::line(kernel, centre - half, centre + half, cv::Scalar(1.0), 1, cv::LINE_AA);
  cv::resize(kernel, kernel, cv::Size(size, size), 0, 0, cv::INTER_AREA);
  kernel /= cv::sum(kernel)[0];
  cv::filter2D(frame, frame, -1, kernel, cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
}

std::string toString(MarkerFamily family) {
  switch (family) {
    case MarkerFamily::ArbciBch:
      return "arbci-bch";
    case MarkerFamily::Aruco6x6:
      return "aruco-6x6";
    case MarkerFamily::AprilTag36h11:
      return "apriltag-36h11";
  }
  return "?";
}

std::string toString(Condition condition) {
  switch (condition) {
    case Condition::Clean:
      return "clean";
    case Condition::Blur:
      return "blur";
    case Condition::Noise:
      return "noise";
    case Condition::UnevenLight:
      return "uneven light";
    case Condition::Combined:
      return "combined";
    case Condition::MotionBlur:
      return "motion blur";
    case Condition::MotionBlurJpeg:
      return "motion+JPEG";
    case Condition::Cluttered:
      return "cluttered";
    case Condition::FastMotionJpeg:
      return "fast motion+J";
  }
  return "?";
}

const std::vector<int>& usableIds(MarkerFamily family) {
  static const std::vector<int> bch = [] {
    std::vector<int> ids;
    for (int id = 0; id <= vision::BchCode::kMaxId; ++id) {
      if (vision::BchCode::rotationMargin(id) >= 5) ids.push_back(id);
    }
    return ids;
  }();
  static const std::vector<int> aruco = [] {
    std::vector<int> ids(250);
    for (int i = 0; i < 250; ++i) ids[i] = i;
    return ids;
  }();
  static const std::vector<int> apriltag = [] {
    std::vector<int> ids(587);
    for (int i = 0; i < 587; ++i) ids[i] = i;
    return ids;
  }();
  switch (family) {
    case MarkerFamily::ArbciBch:
      return bch;
    case MarkerFamily::Aruco6x6:
      return aruco;
    default:
      return apriltag;
  }
}

cv::Mat markerImage(MarkerFamily family, int id, int cell_px, int quiet_cells) {
  std::vector<std::uint8_t> cells(100, 255);
  if (family == MarkerFamily::ArbciBch) {
    const vision::CodeGrid grid = vision::wordToGrid(vision::BchCode::encode(id));
    for (int r = 1; r < 9; ++r) {
      for (int c = 1; c < 9; ++c) {
        const bool border = r == 1 || r == 8 || c == 1 || c == 8;
        cells[r * 10 + c] = border ? 0 : (grid[(r - 2) * 6 + (c - 2)] ? 255 : 0);
      }
    }
  } else if (family == MarkerFamily::Aruco6x6) {
    cv::Mat drawn;
    cv::aruco::drawMarker(cv::aruco::getPredefinedDictionary(cv::aruco::DICT_6X6_250), id, 8, drawn,
                          1);
    for (int r = 0; r < 8; ++r) {
      for (int c = 0; c < 8; ++c) cells[(r + 1) * 10 + c + 1] = drawn.at<std::uint8_t>(r, c);
    }
  } else {
    apriltag_family_t* tags = tag36h11_create();
    image_u8_t* drawn = apriltag_to_image(tags, id);
    for (int r = 0; r < 10; ++r) {
      for (int c = 0; c < 10; ++c) cells[r * 10 + c] = drawn->buf[r * drawn->stride + c];
    }
    image_u8_destroy(drawn);
    tag36h11_destroy(tags);
  }
  cv::Mat image = cellsToImage(cells, 10, cell_px);
  const int extra = std::max(0, quiet_cells - 1) * cell_px;
  if (extra > 0) {
    cv::copyMakeBorder(image, image, extra, extra, extra, extra, cv::BORDER_CONSTANT,
                       cv::Scalar(255));
  }
  return image;
}

void drawWarped(cv::Mat& frame, const cv::Mat& patch, const Corners& quad) {
  constexpr int kScale = 4;
  float x_min = quad[0].x, x_max = x_min, y_min = quad[0].y, y_max = y_min;
  for (const cv::Point2f& p : quad) {
    x_min = std::min(x_min, p.x);
    x_max = std::max(x_max, p.x);
    y_min = std::min(y_min, p.y);
    y_max = std::max(y_max, p.y);
  }
  const int x0 = std::max(0, static_cast<int>(std::floor(x_min)) - 1);
  const int y0 = std::max(0, static_cast<int>(std::floor(y_min)) - 1);
  const int x1 = std::min(frame.cols - 1, static_cast<int>(std::ceil(x_max)) + 1);
  const int y1 = std::min(frame.rows - 1, static_cast<int>(std::ceil(y_max)) + 1);
  if (x1 <= x0 || y1 <= y0) return;
  const cv::Size region(x1 - x0 + 1, y1 - y0 + 1);
  // Patch corners in OpenCV coordinates, and where they land on the supersampled canvas.
  const float w = static_cast<float>(patch.cols), h = static_cast<float>(patch.rows);
  const std::vector<cv::Point2f> from{
      {-0.5f, -0.5f}, {w - 0.5f, -0.5f}, {w - 0.5f, h - 0.5f}, {-0.5f, h - 0.5f}};
  std::vector<cv::Point2f> to;
  for (const cv::Point2f& p : quad) {
    to.emplace_back((p.x - static_cast<float>(x0) + 0.5f) * kScale - 0.5f,
                    (p.y - static_cast<float>(y0) + 0.5f) * kScale - 0.5f);
  }
  const cv::Mat h_matrix = cv::getPerspectiveTransform(from, to);
  cv::Mat canvas, coverage;
  cv::warpPerspective(patch, canvas, h_matrix, region * kScale, cv::INTER_LINEAR,
                      cv::BORDER_CONSTANT, 0);
  cv::warpPerspective(cv::Mat(patch.size(), CV_8UC1, cv::Scalar(255)), coverage, h_matrix,
                      region * kScale, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
  cv::Mat small, alpha;
  cv::resize(canvas, small, region, 0, 0, cv::INTER_AREA);
  cv::resize(coverage, alpha, region, 0, 0, cv::INTER_AREA);
  cv::Mat target = frame(cv::Rect(cv::Point(x0, y0), region));
  for (int y = 0; y < region.height; ++y) {
    for (int x = 0; x < region.width; ++x) {
      const float a = alpha.at<std::uint8_t>(y, x) / 255.0f;
      std::uint8_t& pixel = target.at<std::uint8_t>(y, x);
      // Ink and paper are not ideal: black reflects ~8 %, paper ~90 % of the light.
      const float printed = 20.0f + small.at<std::uint8_t>(y, x) * (215.0f / 255.0f);
      pixel = cv::saturate_cast<std::uint8_t>(pixel * (1.0f - a) + printed * a);
    }
  }
}

SceneLayout makeLayout(const LayoutOptions& options, std::uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const Camera camera{0.9f * options.size.width, options.size.width * 0.5f,
                      options.size.height * 0.5f};
  SceneLayout layout;
  layout.size = options.size;
  layout.seed = seed;
  layout.quiet_cells = std::max(1, static_cast<int>(std::lround(options.quiet_cells)));
  const float outer_ratio = (kBlackCells + 2.0f * layout.quiet_cells) / kBlackCells;
  std::vector<Corners> placed;  // quiet zones of everything placed so far
  const int total = options.markers + options.decoys;
  for (int object = 0; object < total; ++object) {
    for (int attempt = 0; attempt < 500; ++attempt) {
      const float side =
          options.min_side_px * std::pow(options.max_side_px / options.min_side_px, unit(random));
      const float depth = 1.0f;
      const float half = 0.5f * side * depth / camera.f;
      const float tilt = options.max_tilt_deg * unit(random) * static_cast<float>(CV_PI) / 180.0f;
      const float axis_angle = unit(random) * 2.0f * static_cast<float>(CV_PI);
      const float spin = unit(random) * 2.0f * static_cast<float>(CV_PI);
      cv::Matx33f r = rotation({std::cos(axis_angle), std::sin(axis_angle), 0.0f}, tilt) *
                      rotation({0, 0, 1}, spin);
      const cv::Point2f at(unit(random) * options.size.width, unit(random) * options.size.height);
      const cv::Point3f centre((at.x - camera.cx) * depth / camera.f,
                               (at.y - camera.cy) * depth / camera.f, depth);
      if (options.tilt_from == LayoutOptions::TiltFrom::LineOfSight) r = towardsRay(centre) * r;
      const Corners black = projectSquare(camera, r, centre, half);
      const Corners outer = projectSquare(camera, r, centre, half * outer_ratio);
      bool fits = true;
      for (const cv::Point2f& p : outer) {
        fits = fits && p.x > 3 && p.y > 3 && p.x < options.size.width - 4 &&
               p.y < options.size.height - 4;
      }
      for (const Corners& other : placed) {
        fits = fits &&
               cv::norm(centroid(other) - centroid(outer)) > radius(other) + radius(outer) + 4.0f;
      }
      if (!fits) continue;
      placed.push_back(outer);
      if (object < options.markers) {
        layout.markers.push_back(black);
      } else {
        layout.decoys.push_back(black);
        layout.decoy_styles.push_back(static_cast<int>(random() % 3));
      }
      break;
    }
  }
  return layout;
}

RenderedScene renderScene(const SceneLayout& layout, MarkerFamily family, Condition condition) {
  std::mt19937 random(layout.seed);
  RenderedScene scene;
  scene.image.create(layout.size, CV_8UC1);
  drawTable(scene.image, layout, condition, random);
  drawDecoys(scene.image, layout);
  const std::vector<int>& ids = usableIds(family);
  std::mt19937 id_random(layout.seed * 7919u + static_cast<std::uint32_t>(family));
  for (const Corners& marker : layout.markers) {
    const int id = ids[id_random() % ids.size()];
    drawWarped(scene.image, markerImage(family, id, 8, layout.quiet_cells),
               outerSquare(marker, layout.quiet_cells));
    scene.ids.push_back(id);
    scene.markers.push_back(marker);
  }
  std::mt19937 condition_random(layout.seed * 31u + static_cast<std::uint32_t>(condition));
  applyCondition(scene.image, condition, condition_random);
  return scene;
}

cv::Mat backdropFromPhotos(const std::vector<cv::Mat>& photos, cv::Size size, std::uint32_t seed) {
  if (photos.empty()) throw std::invalid_argument("backdropFromPhotos: no photographs given");
  std::mt19937 random(seed * 2654435761u + 17u);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const cv::Mat& photo = photos[random() % photos.size()];
  cv::Mat grey;
  if (photo.channels() == 1)
    grey = photo;
  else
    cv::cvtColor(photo, grey, photo.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  const double cover = std::max(static_cast<double>(size.width) / grey.cols,
                                static_cast<double>(size.height) / grey.rows);
  const double scale = cover * (1.0 + 0.5 * unit(random));
  cv::Mat scaled;
  cv::resize(grey, scaled,
             cv::Size(std::max(size.width, static_cast<int>(std::ceil(grey.cols * scale))),
                      std::max(size.height, static_cast<int>(std::ceil(grey.rows * scale)))),
             0, 0, scale < 1.0 ? cv::INTER_AREA : cv::INTER_LINEAR);
  const int x = static_cast<int>(unit(random) * (scaled.cols - size.width));
  const int y = static_cast<int>(unit(random) * (scaled.rows - size.height));
  return scaled(cv::Rect(x, y, size.width, size.height)).clone();
}

cv::Mat renderMarkerFree(const SceneLayout& layout, Condition condition) {
  std::mt19937 random(layout.seed);
  cv::Mat image(layout.size, CV_8UC1);
  drawTable(image, layout, condition, random);
  drawDecoys(image, layout);
  std::mt19937 condition_random(layout.seed * 31u + static_cast<std::uint32_t>(condition));
  applyCondition(image, condition, condition_random);
  return image;
}

}  // namespace arbci::test

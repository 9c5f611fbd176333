#include "arbci/render/hmd_view.h"

#include <map>
#include <opencv2/calib3d.hpp>
#include <sstream>

#include "arbci/render/primitive_renderer.h"
#include "arbci/render/shader_program.h"
#include "arbci/render/texture.h"
#include "gl.h"

namespace arbci::render {

cv::Vec3d GridLayout::cellCorner(double row_edge, double column_edge) const {
  const double x = (column_edge - columns / 2.0) * cell_m;
  const double y = (rows / 2.0 - row_edge) * cell_m;
  return T_world_grid.apply(cv::Vec3d(x, y, 0.0));
}

cv::Vec3d GridLayout::cellCentre(int row, int column) const {
  return cellCorner(row - 0.5, column - 0.5);
}

namespace {

// The rectified view of a distorting camera: a camera matrix that keeps only valid pixels, and
// the map from each output pixel to its normalised source coordinate.
struct Rectification {
  cv::Matx33d camera_matrix;
  cv::Mat map;  // CV_32FC2
};

Rectification rectify(const vision::CameraModel& camera) {
  Rectification r;
  const cv::Size size = camera.image_size;
  r.camera_matrix =
      cv::getOptimalNewCameraMatrix(camera.camera_matrix, camera.distortion, size, 0.0, size);
  cv::Mat map;
  cv::initUndistortRectifyMap(camera.camera_matrix, camera.distortion, cv::noArray(),
                              r.camera_matrix, size, CV_32FC2, map, cv::noArray());
  r.map.create(size, CV_32FC2);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const cv::Vec2f s = map.at<cv::Vec2f>(y, x);
      r.map.at<cv::Vec2f>(y, x) =
          cv::Vec2f((s[0] + 0.5f) / size.width, (s[1] + 0.5f) / size.height);
    }
  }
  return r;
}

std::string cameraKey(const vision::CameraModel& c) {
  std::ostringstream key;
  key.precision(17);
  key << c.image_size.width << 'x' << c.image_size.height;
  for (int i = 0; i < 9; ++i) key << ',' << c.camera_matrix.val[i];
  for (double d : c.distortion) key << ',' << d;
  return key.str();
}

}  // namespace

struct HmdView::Impl {
  ShaderProgram image_program = ShaderProgram::fromAssets("image");
  PrimitiveRenderer primitives;
  unsigned int quad_array = 0, quad_buffer = 0;
  Texture eye_texture[2];
  struct CachedRectification {
    Rectification rectification;
    Texture map_texture;
  };
  std::map<std::string, CachedRectification> rectifications;

  Impl() {
    const float corners[] = {-1, -1, 1, -1, 1, 1, -1, -1, 1, 1, -1, 1};
    glGenVertexArrays(1, &quad_array);
    glGenBuffers(1, &quad_buffer);
    glBindVertexArray(quad_array);
    glBindBuffer(GL_ARRAY_BUFFER, quad_buffer);
    glBufferData(GL_ARRAY_BUFFER, sizeof corners, corners, GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
    glBindVertexArray(0);
  }
  ~Impl() {
    glDeleteBuffers(1, &quad_buffer);
    glDeleteVertexArrays(1, &quad_array);
  }

  CachedRectification& rectificationOf(const vision::CameraModel& camera) {
    const std::string key = cameraKey(camera);
    auto found = rectifications.find(key);
    if (found != rectifications.end()) return found->second;
    CachedRectification cached{rectify(camera), Texture()};
    cached.map_texture.uploadMap(cached.rectification.map);
    return rectifications.emplace(key, std::move(cached)).first->second;
  }

  void background(int eye, const EyeImage& view, bool undistort) {
    if (view.image.empty()) return;
    eye_texture[eye].upload(view.image, false);
    const bool remap = undistort && !view.camera.distortion.empty();
    image_program.use();
    glUniform1i(image_program.uniform("image"), 0);
    glUniform1i(image_program.uniform("remap"), 1);
    glUniform1i(image_program.uniform("use_remap"), remap ? 1 : 0);
    glUniform1i(image_program.uniform("grey"), eye_texture[eye].grey() ? 1 : 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, eye_texture[eye].id());
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, remap ? rectificationOf(view.camera).map_texture.id() : 0);
    glActiveTexture(GL_TEXTURE0);
    glDisable(GL_DEPTH_TEST);
    glBindVertexArray(quad_array);
    glDrawArrays(GL_TRIANGLES, 0, 6);
    glBindVertexArray(0);
  }
};

HmdView::HmdView() : impl_(std::make_unique<Impl>()) {}
HmdView::~HmdView() = default;

std::optional<cv::Point2d> HmdView::project(const EyeImage& eye, const cv::Vec3d& world,
                                            Size viewport) const {
  if (!eye.T_cam_world) return std::nullopt;
  const cv::Vec3d p = eye.T_cam_world->apply(world);
  if (p[2] < 0.01) return std::nullopt;
  cv::Point2d pixel;
  const bool distorting = !eye.camera.distortion.empty();
  if (distorting && !undistort_) {
    std::vector<cv::Point3d> object{cv::Point3d(p[0], p[1], p[2])};
    std::vector<cv::Point2d> image;
    cv::projectPoints(object, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), eye.camera.camera_matrix,
                      eye.camera.distortion, image);
    pixel = image[0];
  } else {
    const cv::Matx33d k = distorting
                              ? impl_->rectificationOf(eye.camera).rectification.camera_matrix
                              : eye.camera.camera_matrix;
    pixel = {k(0, 0) * p[0] / p[2] + k(0, 1) * p[1] / p[2] + k(0, 2),
             k(1, 1) * p[1] / p[2] + k(1, 2)};
  }
  const double sx = static_cast<double>(viewport.width) / eye.camera.image_size.width;
  const double sy = static_cast<double>(viewport.height) / eye.camera.image_size.height;
  return cv::Point2d((pixel.x + 0.5) * sx - 0.5, (pixel.y + 0.5) * sy - 0.5);
}

void HmdView::draw(const HmdFrame& frame, unsigned int framebuffer, Size size) {
  Impl& m = *impl_;
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glViewport(0, 0, size.width, size.height);
  glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  const Size eye_size{size.width / 2, size.height};
  const glm::vec2 viewport(eye_size.width, eye_size.height);
  const EyeImage* eyes[2] = {&frame.left, &frame.right};
  for (int e = 0; e < 2; ++e) {
    const EyeImage& eye = *eyes[e];
    glViewport(e * eye_size.width, 0, eye_size.width, eye_size.height);
    m.background(e, eye, undistort_);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    // A polygon through world points, subdivided so straight edges follow the lens.
    const bool curved = !eye.camera.distortion.empty() && !undistort_;
    auto outline = [&](const std::vector<cv::Vec3d>& corners, bool closed) {
      std::vector<glm::vec2> points;
      const size_t n = corners.size(), edges = closed ? n : n - 1;
      const int steps = curved ? 12 : 1;
      for (size_t i = 0; i < edges; ++i) {
        for (int s = 0; s < steps; ++s) {
          const double t = static_cast<double>(s) / steps;
          const auto p = project(eye, corners[i] * (1.0 - t) + corners[(i + 1) % n] * t, eye_size);
          if (!p) return std::vector<glm::vec2>{};
          points.emplace_back(static_cast<float>(p->x + 0.5), static_cast<float>(p->y + 0.5));
        }
      }
      if (!closed) {
        const auto p = project(eye, corners.back(), eye_size);
        if (!p) return std::vector<glm::vec2>{};
        points.emplace_back(static_cast<float>(p->x + 0.5), static_cast<float>(p->y + 0.5));
      }
      return points;
    };
    if (frame.grid) {
      const GridLayout& g = *frame.grid;
      auto cell = [&](int row, int column) {
        return std::vector<cv::Vec3d>{g.cellCorner(row - 1, column - 1),
                                      g.cellCorner(row - 1, column), g.cellCorner(row, column),
                                      g.cellCorner(row, column - 1)};
      };
      const GridHighlight& h = frame.grid_highlight;
      for (int r = 1; r <= g.rows; ++r) {
        for (int c = 1; c <= g.columns; ++c) {
          glm::vec4 fill(0.0f);
          if (h.rows.count(r) || h.columns.count(c)) fill = colors_.flash;
          if (h.cued && *h.cued == std::make_pair(r, c))
            fill = colors_.cued * glm::vec4(1, 1, 1, 0.6f);
          if (h.selected && *h.selected == std::make_pair(r, c))
            fill = colors_.selected * glm::vec4(1, 1, 1, 0.6f);
          if (fill.a > 0.0f) {
            const auto polygon = outline(cell(r, c), true);
            if (!polygon.empty()) m.primitives.fillPolygon(polygon, fill, viewport);
          }
        }
      }
      for (int r = 0; r <= g.rows; ++r) {
        const auto line = outline({g.cellCorner(r, 0), g.cellCorner(r, g.columns)}, false);
        if (!line.empty()) m.primitives.drawPolyline(line, false, 2.0f, colors_.grid, viewport);
      }
      for (int c = 0; c <= g.columns; ++c) {
        const auto line = outline({g.cellCorner(0, c), g.cellCorner(g.rows, c)}, false);
        if (!line.empty()) m.primitives.drawPolyline(line, false, 2.0f, colors_.grid, viewport);
      }
    }
    for (const ObjectHighlight& o : frame.objects) {
      const double h = o.side_m * o.margin / 2.0;
      std::vector<cv::Vec3d> corners;
      for (const auto& [x, y] : {std::pair{-h, h}, {h, h}, {h, -h}, {-h, -h}})
        corners.push_back(o.T_world_top.apply(cv::Vec3d(x, y, 0.0)));
      const auto polygon = outline(corners, true);
      if (polygon.empty()) continue;
      switch (o.state) {
        case HighlightState::Flashing:
          m.primitives.fillPolygon(polygon, colors_.flash, viewport);
          break;
        case HighlightState::Idle:
          m.primitives.drawPolyline(polygon, true, 2.0f, colors_.idle, viewport);
          break;
        case HighlightState::Cued:
          m.primitives.drawPolyline(polygon, true, 4.0f, colors_.cued, viewport);
          break;
        case HighlightState::Selected:
          m.primitives.drawPolyline(polygon, true, 5.0f, colors_.selected, viewport);
          break;
        case HighlightState::Held:
          m.primitives.drawPolyline(polygon, true, 5.0f, colors_.held, viewport);
          break;
        case HighlightState::Lost:
          m.primitives.drawPolyline(polygon, true, 2.0f, colors_.lost, viewport);
          break;
      }
    }
    glDisable(GL_BLEND);
    if (frame.photodiode_patch) {
      const float side = static_cast<float>(HmdFrame::kPatchPx);
      const glm::vec2 patch[4] = {{0.0f, 0.0f}, {side, 0.0f}, {side, side}, {0.0f, side}};
      const float level = *frame.photodiode_patch ? 1.0f : 0.0f;
      m.primitives.fillPolygon(patch, glm::vec4(level, level, level, 1.0f), viewport);
    }
  }
  glViewport(0, 0, size.width, size.height);
}

}  // namespace arbci::render

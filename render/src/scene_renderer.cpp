#include "arbci/render/scene_renderer.h"

#include <opencv2/imgproc.hpp>

#include "arbci/vision/marker_printer.h"
#include "gl.h"

namespace arbci::render {
namespace {

glm::vec3 toGlm(const cv::Vec3d& v) { return {static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2])}; }

// Appends two triangles for the quad a b c d (counter-clockwise seen from outside).
template <typename V>
void quad(std::vector<V>& out, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d, const glm::vec4& color,
          const glm::vec2 (&uv)[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}}) {
  out.push_back({a, uv[0], color});
  out.push_back({b, uv[1], color});
  out.push_back({c, uv[2], color});
  out.push_back({a, uv[0], color});
  out.push_back({c, uv[2], color});
  out.push_back({d, uv[3], color});
}

// A box in the frame `pose` (its top face centred at the origin, extending down by `height`),
// shaded as lit from above.
template <typename V>
void box(std::vector<V>& out, const vision::Pose& pose, double width, double depth, double height, const glm::vec3& color,
         const glm::vec3& top_color) {
  const double w = width / 2, d = depth / 2;
  auto p = [&](double x, double y, double z) { return toGlm(pose.apply(cv::Vec3d(x, y, z))); };
  const glm::vec4 top(top_color, 1.0f), side_a(color * 0.75f, 1.0f), side_b(color * 0.6f, 1.0f);
  quad(out, p(-w, d, 0), p(w, d, 0), p(w, -d, 0), p(-w, -d, 0), top);
  quad(out, p(-w, -d, 0), p(w, -d, 0), p(w, -d, -height), p(-w, -d, -height), side_a);  // facing -y
  quad(out, p(w, d, 0), p(-w, d, 0), p(-w, d, -height), p(w, d, -height), side_a);      // facing +y
  quad(out, p(w, -d, 0), p(w, d, 0), p(w, d, -height), p(w, -d, -height), side_b);      // facing +x
  quad(out, p(-w, d, 0), p(-w, -d, 0), p(-w, -d, -height), p(-w, d, -height), side_b);  // facing -x
}

}  // namespace

SceneRenderer::SceneRenderer() : program_(ShaderProgram::fromAssets("scene")) {
  transform_location_ = program_.uniform("transform");
  textured_location_ = program_.uniform("textured");
  sampler_location_ = program_.uniform("marker");
  glGenVertexArrays(1, &vertex_array_);
  glGenBuffers(1, &vertex_buffer_);
  glBindVertexArray(vertex_array_);
  glBindBuffer(GL_ARRAY_BUFFER, vertex_buffer_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<void*>(offsetof(Vertex, position)));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<void*>(offsetof(Vertex, uv)));
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<void*>(offsetof(Vertex, color)));
  glBindVertexArray(0);
}

SceneRenderer::~SceneRenderer() {
  glDeleteBuffers(1, &vertex_buffer_);
  glDeleteVertexArrays(1, &vertex_array_);
}

const Texture& SceneRenderer::markerTexture(const SceneMarker& marker) {
  const auto key = std::make_tuple(static_cast<int>(marker.kind), marker.id, static_cast<int>(marker.border * 1000));
  auto found = markers_.find(key);
  if (found != markers_.end()) return found->second;
  const cv::Mat cells = vision::markerCells(marker.kind, marker.id, marker.border);
  cv::Mat large;
  cv::resize(cells, large, cells.size() * 32, 0, 0, cv::INTER_NEAREST);
  Texture texture;
  texture.upload(large, true);
  return markers_.emplace(key, std::move(texture)).first->second;
}

void SceneRenderer::flush(const std::vector<Vertex>& vertices, const glm::mat4& transform, const Texture* texture) {
  if (vertices.empty()) return;
  program_.use();
  glUniformMatrix4fv(transform_location_, 1, GL_FALSE, &transform[0][0]);
  glUniform1i(textured_location_, texture ? 1 : 0);
  glUniform1i(sampler_location_, 0);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, texture ? texture->id() : 0);
  glBindVertexArray(vertex_array_);
  glBindBuffer(GL_ARRAY_BUFFER, vertex_buffer_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)), vertices.data(), GL_STREAM_DRAW);
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(vertices.size()));
  glBindVertexArray(0);
}

void SceneRenderer::draw(const Scene& scene, const glm::mat4& world_to_clip) {
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glDisable(GL_CULL_FACE);
  std::vector<Vertex> solid;
  // The table: a light grey top, slightly darker far away (soft light from the subject's side).
  const float z = static_cast<float>(scene.table_z);
  const glm::vec3 a(scene.table_min[0], scene.table_min[1], z), b(scene.table_max[0], scene.table_min[1], z),
      c(scene.table_max[0], scene.table_max[1], z), d(scene.table_min[0], scene.table_max[1], z);
  solid.push_back({a, {0, 0}, {0.62f, 0.60f, 0.56f, 1}});
  solid.push_back({b, {0, 0}, {0.62f, 0.60f, 0.56f, 1}});
  solid.push_back({c, {0, 0}, {0.52f, 0.50f, 0.47f, 1}});
  solid.push_back({a, {0, 0}, {0.62f, 0.60f, 0.56f, 1}});
  solid.push_back({c, {0, 0}, {0.52f, 0.50f, 0.47f, 1}});
  solid.push_back({d, {0, 0}, {0.52f, 0.50f, 0.47f, 1}});
  // The reference marker's white quiet zone, a hair above the table.
  vision::Pose lifted = scene.T_world_reference;
  lifted.translation += scene.T_world_reference.rotation * cv::Vec3d(0, 0, 0.0005);
  const double quiet = scene.reference.side_m * 1.4;
  box(solid, lifted, quiet, quiet, 0.0005, glm::vec3(0.95f), glm::vec3(0.95f));
  // Objects: coloured sides, a white top carrying the marker.
  for (const SceneObject& o : scene.objects) box(solid, o.T_world_top, o.width_m, o.width_m, o.height_m, o.color, glm::vec3(0.95f));
  if (scene.gripper) {
    const cv::Vec3d t = scene.gripper->tool;
    const double gap = 0.02 + 0.05 * scene.gripper->opening;
    vision::Pose palm{cv::Matx33d::eye(), t + cv::Vec3d(0, 0, 0.06)};
    const glm::vec3 dark(0.25f), metal(0.45f, 0.47f, 0.5f);
    box(solid, vision::Pose{cv::Matx33d::eye(), palm.translation + cv::Vec3d(0, 0, 0.03)}, 0.10, 0.04, 0.03, dark, dark);
    box(solid, vision::Pose{cv::Matx33d::eye(), t + cv::Vec3d(-gap / 2 - 0.006, 0, 0.06)}, 0.012, 0.03, 0.06, dark, dark);
    box(solid, vision::Pose{cv::Matx33d::eye(), t + cv::Vec3d(gap / 2 + 0.006, 0, 0.06)}, 0.012, 0.03, 0.06, dark, dark);
    box(solid, vision::Pose{cv::Matx33d::eye(), t + cv::Vec3d(0, 0, 0.30)}, 0.05, 0.05, 0.20, metal, metal);
  }
  flush(solid, world_to_clip, nullptr);

  // Markers, each a textured square a hair above its face.
  auto drawMarker = [&](const SceneMarker& marker, const vision::Pose& face, double lift) {
    const double h = marker.side_m / 2;
    auto p = [&](double x, double y) { return toGlm(face.apply(cv::Vec3d(x, y, lift))); };
    std::vector<Vertex> square;
    quad(square, p(-h, h), p(h, h), p(h, -h), p(-h, -h), glm::vec4(1.0f));
    flush(square, world_to_clip, &markerTexture(marker));
  };
  drawMarker(scene.reference, scene.T_world_reference, 0.0012);
  for (const SceneObject& o : scene.objects) drawMarker(o.marker, o.T_world_top, 0.0007);
}

}  // namespace arbci::render

#include "arbci/render/scene_renderer.h"

#include <opencv2/imgproc.hpp>

#include "arbci/vision/marker_printer.h"
#include "gl.h"

namespace arbci::render {
namespace {

glm::vec3 toGlm(const cv::Vec3d& v) {
  return {static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2])};
}

// Appends two triangles for the quad a b c d (counter-clockwise seen from outside).
template <typename V>
void quad(std::vector<V>& out, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
          const glm::vec3& d, const glm::vec4& color,
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
void box(std::vector<V>& out, const vision::Pose& pose, double width, double depth, double height,
         const glm::vec3& color, const glm::vec3& top_color) {
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

SceneRenderer::SceneRenderer()
    : textured_(ShaderProgram::fromAssets("scene")),
      flat_(ShaderProgram::fromAssets("scene_flat")) {
  textured_transform_ = textured_.uniform("transform");
  flat_transform_ = flat_.uniform("transform");
  sampler_location_ = textured_.uniform("marker");
  glGenVertexArrays(1, &vertex_array_);
  glGenBuffers(1, &vertex_buffer_);
  glBindVertexArray(vertex_array_);
  glBindBuffer(GL_ARRAY_BUFFER, vertex_buffer_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                        reinterpret_cast<void*>(offsetof(Vertex, position)));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                        reinterpret_cast<void*>(offsetof(Vertex, uv)));
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                        reinterpret_cast<void*>(offsetof(Vertex, color)));
  glBindVertexArray(0);
}

SceneRenderer::~SceneRenderer() {
  glDeleteBuffers(1, &vertex_buffer_);
  glDeleteVertexArrays(1, &vertex_array_);
}

const Texture& SceneRenderer::markerTexture(const SceneMarker& marker) {
  const auto key = std::make_tuple(std::string(marker.kind.name), marker.id,
                                   static_cast<int>(marker.border * 1000));
  auto found = markers_.find(key);
  if (found != markers_.end()) return found->second;
  const cv::Mat cells = vision::markerCells(marker.kind, marker.id, marker.border);
  cv::Mat large;
  cv::resize(cells, large, cells.size() * 32, 0, 0, cv::INTER_NEAREST);
  Texture texture;
  texture.upload(large, true);
  return markers_.emplace(key, std::move(texture)).first->second;
}

const Texture& SceneRenderer::boardTexture(const SceneBoard& board) {
  const auto key = std::make_pair(board.inner_corners.width, board.inner_corners.height);
  auto found = boards_.find(key);
  if (found != boards_.end()) return found->second;
  // Squares of 32 px, a white margin of one square around them.
  const int squares_x = board.inner_corners.width + 1, squares_y = board.inner_corners.height + 1,
            s = 32;
  cv::Mat image((squares_y + 2) * s, (squares_x + 2) * s, CV_8UC1, cv::Scalar(255));
  for (int y = 0; y < squares_y; ++y) {
    for (int x = 0; x < squares_x; ++x) {
      if ((x + y) % 2 == 0) image(cv::Rect((x + 1) * s, (y + 1) * s, s, s)).setTo(0);
    }
  }
  Texture texture;
  texture.upload(image, true);
  return boards_.emplace(key, std::move(texture)).first->second;
}

void SceneRenderer::drawBatches(const std::vector<Vertex>& vertices,
                                const std::vector<Batch>& batches, const glm::mat4& transform) {
  if (vertices.empty()) return;
  textured_.use();
  glUniformMatrix4fv(textured_transform_, 1, GL_FALSE, &transform[0][0]);
  glUniform1i(sampler_location_, 0);
  flat_.use();
  glUniformMatrix4fv(flat_transform_, 1, GL_FALSE, &transform[0][0]);
  glActiveTexture(GL_TEXTURE0);
  glBindVertexArray(vertex_array_);
  glBindBuffer(GL_ARRAY_BUFFER, vertex_buffer_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)),
               vertices.data(), GL_STREAM_DRAW);
  for (const Batch& b : batches) {
    if (b.depth_test) {
      glEnable(GL_DEPTH_TEST);
    } else {
      glDisable(GL_DEPTH_TEST);
    }
    if (b.texture) {
      textured_.use();
      glBindTexture(GL_TEXTURE_2D, b.texture->id());
    } else {
      flat_.use();
    }
    glDrawArrays(GL_TRIANGLES, static_cast<GLint>(b.first), static_cast<GLsizei>(b.count));
  }
  glBindVertexArray(0);
}

void SceneRenderer::draw(const Scene& scene, const glm::mat4& world_to_clip) {
  glDepthFunc(GL_LEQUAL);
  glDisable(GL_CULL_FACE);
  std::vector<Vertex> solid;
  // The table: a light grey top, slightly darker far away (soft light from the subject's side).
  const float z = static_cast<float>(scene.table_z);
  const glm::vec3 a(scene.table_min[0], scene.table_min[1], z),
      b(scene.table_max[0], scene.table_min[1], z), c(scene.table_max[0], scene.table_max[1], z),
      d(scene.table_min[0], scene.table_max[1], z);
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
  // The table and the quiet zone lie behind everything else: drawn first, without the depth
  // test (which costs llvmpipe more than the drawing).
  const size_t flat = solid.size();
  // Objects: coloured sides, a white top carrying the marker.
  for (const SceneObject& o : scene.objects) {
    box(solid, o.T_world_top, o.width_m, o.width_m, o.height_m, o.color, glm::vec3(0.95f));
    if (o.covered) {
      // A hand, flat, two centimetres above the marker and wider than it.
      const glm::vec3 skin(0.87f, 0.68f, 0.56f);
      vision::Pose hand = o.T_world_top;
      hand.translation += o.T_world_top.rotation * cv::Vec3d(0.01, 0.0, 0.035);
      box(solid, hand, o.marker.side_m * 1.8, o.marker.side_m * 1.5, 0.015, skin, skin);
    }
    if (o.gripper_over_corner) {
      // A fingertip, its rubber pad nearly black, a few millimetres above the marker's printed
      // top-left corner: it hides 18 % of the side along both edges from that corner, and merges
      // with the black border there (the hard case: the outline is no longer a square).
      const glm::vec3 dark(0.06f);
      const double h = o.marker.side_m / 2, pad = o.marker.side_m * 0.36;
      vision::Pose tip = o.T_world_top;
      tip.translation += o.T_world_top.rotation * cv::Vec3d(-h, h, 0.008);
      box(solid, tip, pad, pad, 0.006, dark, dark);
    }
  }
  if (scene.gripper) {
    const cv::Vec3d t = scene.gripper->tool;
    const double gap = 0.02 + 0.05 * scene.gripper->opening;
    vision::Pose palm{cv::Matx33d::eye(), t + cv::Vec3d(0, 0, 0.06)};
    const glm::vec3 dark(0.25f), metal(0.45f, 0.47f, 0.5f);
    box(solid, vision::Pose{cv::Matx33d::eye(), palm.translation + cv::Vec3d(0, 0, 0.03)}, 0.10,
        0.04, 0.03, dark, dark);
    box(solid, vision::Pose{cv::Matx33d::eye(), t + cv::Vec3d(-gap / 2 - 0.006, 0, 0.06)}, 0.012,
        0.03, 0.06, dark, dark);
    box(solid, vision::Pose{cv::Matx33d::eye(), t + cv::Vec3d(gap / 2 + 0.006, 0, 0.06)}, 0.012,
        0.03, 0.06, dark, dark);
    box(solid, vision::Pose{cv::Matx33d::eye(), t + cv::Vec3d(0, 0, 0.30)}, 0.05, 0.05, 0.20, metal,
        metal);
  }
  std::vector<Batch> batches{{0, flat, nullptr, false}, {flat, solid.size() - flat, nullptr, true}};
  // Markers, each a textured square a hair above its face.
  auto addMarker = [&](const SceneMarker& marker, const vision::Pose& face, double lift) {
    const double h = marker.side_m / 2;
    auto p = [&](double x, double y) { return toGlm(face.apply(cv::Vec3d(x, y, lift))); };
    batches.push_back({solid.size(), 6, &markerTexture(marker), true});
    quad(solid, p(-h, h), p(h, h), p(h, -h), p(-h, -h), glm::vec4(1.0f));
  };
  addMarker(scene.reference, scene.T_world_reference, 0.0012);
  if (scene.board) {
    const SceneBoard& b = *scene.board;
    const double w = (b.inner_corners.width + 3) * b.square_m / 2,
                 h = (b.inner_corners.height + 3) * b.square_m / 2;
    auto p = [&](double x, double y) { return toGlm(b.T_world_board.apply(cv::Vec3d(x, y, 0.0))); };
    batches.push_back({solid.size(), 6, &boardTexture(b), true});
    quad(solid, p(-w, h), p(w, h), p(w, -h), p(-w, -h), glm::vec4(1.0f));
  }
  for (const SceneObject& o : scene.objects) addMarker(o.marker, o.T_world_top, 0.0007);
  drawBatches(solid, batches, world_to_clip);
}

}  // namespace arbci::render

// Draws a Scene with depth: the table, boxes with their markers (textures made from the same
// cells the marker printer draws), the reference marker with a white quiet zone, the gripper.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <tuple>

#include <glm/glm.hpp>

#include "arbci/render/scene.h"
#include "arbci/render/shader_program.h"
#include "arbci/render/texture.h"

namespace arbci::render {

class SceneRenderer {
 public:
  SceneRenderer();  // needs a current GL context
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // Into the bound framebuffer's current viewport, depth-tested.
  void draw(const Scene& scene, const glm::mat4& world_to_clip);

 private:
  struct Vertex {
    glm::vec3 position;
    glm::vec2 uv;
    glm::vec4 color;
  };
  // Runs of vertices sharing a texture (none for plain colour). All of a frame's vertices go to
  // the GPU in one upload: re-filling the buffer between draws makes Mesa's llvmpipe finish
  // each draw first, which costs more than the drawing.
  struct Batch {
    size_t first = 0, count = 0;
    const Texture* texture = nullptr;
    bool depth_test = true;
  };
  const Texture& markerTexture(const SceneMarker& marker);
  const Texture& boardTexture(const SceneBoard& board);
  void drawBatches(const std::vector<Vertex>& vertices, const std::vector<Batch>& batches,
                   const glm::mat4& transform);

  ShaderProgram textured_, flat_;
  int textured_transform_ = -1, flat_transform_ = -1, sampler_location_ = -1;
  unsigned int vertex_array_ = 0, vertex_buffer_ = 0;
  std::map<std::tuple<std::string, int, int>, Texture> markers_;
  std::map<std::pair<int, int>, Texture> boards_;
};

}  // namespace arbci::render

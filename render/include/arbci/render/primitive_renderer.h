// Draws coloured points, lines and triangles through one shader and one streaming vertex buffer.
// Thick lines are expanded to triangles on the CPU (core profiles only guarantee 1 px lines).
#pragma once

#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "arbci/render/shader_program.h"

namespace arbci::render {

struct ColoredVertex {
  glm::vec3 position;
  glm::vec4 color;
};

enum class Primitive { Points, Lines, LineStrip, Triangles, TriangleStrip, TriangleFan };

class PrimitiveRenderer {
 public:
  PrimitiveRenderer();  // needs a current GL context
  ~PrimitiveRenderer();
  PrimitiveRenderer(const PrimitiveRenderer&) = delete;
  PrimitiveRenderer& operator=(const PrimitiveRenderer&) = delete;

  void draw(Primitive primitive, std::span<const ColoredVertex> vertices,
            const glm::mat4& transform);

  // A closed or open polyline of `width` pixels; points are in viewport pixels of a viewport of
  // `viewport_size`: x right, y down, pixel (i, j) covers [i, i+1] x [j, j+1] (so an OpenCV
  // image coordinate, whose pixel centres are integers, maps to coordinate + 0.5).
  void drawPolyline(std::span<const glm::vec2> points, bool closed, float width, glm::vec4 color,
                    glm::vec2 viewport_size);
  // A filled convex polygon in viewport pixels.
  void fillPolygon(std::span<const glm::vec2> points, glm::vec4 color, glm::vec2 viewport_size);

 private:
  ShaderProgram program_;
  int transform_location_ = -1;
  unsigned int vertex_array_ = 0;
  unsigned int vertex_buffer_ = 0;
  std::vector<ColoredVertex> scratch_;
};

// Maps viewport pixels (x right, y down, origin at the top-left corner of the viewport) to clip
// space.
glm::mat4 pixelToClip(glm::vec2 viewport_size);

}  // namespace arbci::render

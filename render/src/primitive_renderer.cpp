#include "arbci/render/primitive_renderer.h"

#include <cstddef>

#include "gl.h"

namespace arbci::render {
namespace {
GLenum glPrimitive(Primitive primitive) {
  switch (primitive) {
    case Primitive::Points:
      return GL_POINTS;
    case Primitive::Lines:
      return GL_LINES;
    case Primitive::LineStrip:
      return GL_LINE_STRIP;
    case Primitive::Triangles:
      return GL_TRIANGLES;
    case Primitive::TriangleStrip:
      return GL_TRIANGLE_STRIP;
    case Primitive::TriangleFan:
      return GL_TRIANGLE_FAN;
  }
  return GL_POINTS;
}
}  // namespace

glm::mat4 pixelToClip(glm::vec2 viewport_size) {
  // x: [0, w] -> [-1, 1]; y: [0, h] -> [1, -1].
  glm::mat4 m(1.0f);
  m[0][0] = 2.0f / viewport_size.x;
  m[1][1] = -2.0f / viewport_size.y;
  m[3][0] = -1.0f;
  m[3][1] = 1.0f;
  return m;
}

PrimitiveRenderer::PrimitiveRenderer() : program_(ShaderProgram::fromAssets("flat")) {
  transform_location_ = program_.uniform("transform");
  glGenVertexArrays(1, &vertex_array_);
  glGenBuffers(1, &vertex_buffer_);
  glBindVertexArray(vertex_array_);
  glBindBuffer(GL_ARRAY_BUFFER, vertex_buffer_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(ColoredVertex),
                        reinterpret_cast<void*>(offsetof(ColoredVertex, position)));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, sizeof(ColoredVertex),
                        reinterpret_cast<void*>(offsetof(ColoredVertex, color)));
  glBindVertexArray(0);
}

PrimitiveRenderer::~PrimitiveRenderer() {
  glDeleteBuffers(1, &vertex_buffer_);
  glDeleteVertexArrays(1, &vertex_array_);
}

void PrimitiveRenderer::draw(Primitive primitive, std::span<const ColoredVertex> vertices,
                             const glm::mat4& transform) {
  if (vertices.empty()) return;
  program_.use();
  glUniformMatrix4fv(transform_location_, 1, GL_FALSE, &transform[0][0]);
  glBindVertexArray(vertex_array_);
  glBindBuffer(GL_ARRAY_BUFFER, vertex_buffer_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size_bytes()), vertices.data(),
               GL_STREAM_DRAW);
  glDrawArrays(glPrimitive(primitive), 0, static_cast<GLsizei>(vertices.size()));
  glBindVertexArray(0);
}

void PrimitiveRenderer::drawPolyline(std::span<const glm::vec2> points, bool closed, float width,
                                     glm::vec4 color, glm::vec2 viewport_size) {
  const size_t n = points.size();
  if (n < 2) return;
  scratch_.clear();
  const float half = width * 0.5f;
  const size_t segments = closed ? n : n - 1;
  for (size_t i = 0; i < segments; ++i) {
    const glm::vec2 a = points[i];
    const glm::vec2 b = points[(i + 1) % n];
    const glm::vec2 d = b - a;
    const float length = glm::length(d);
    if (length <= 0.0f) continue;
    const glm::vec2 along = d / length * half;  // extend by half a width so corners close
    const glm::vec2 normal(-along.y, along.x);
    const glm::vec2 p0 = a - along + normal, p1 = a - along - normal;
    const glm::vec2 p2 = b + along + normal, p3 = b + along - normal;
    for (const glm::vec2& p : {p0, p1, p2, p2, p1, p3}) {
      scratch_.push_back({glm::vec3(p, 0.0f), color});
    }
  }
  draw(Primitive::Triangles, scratch_, pixelToClip(viewport_size));
}

void PrimitiveRenderer::fillPolygon(std::span<const glm::vec2> points, glm::vec4 color,
                                    glm::vec2 viewport_size) {
  scratch_.clear();
  for (const glm::vec2& p : points) scratch_.push_back({glm::vec3(p, 0.0f), color});
  draw(Primitive::TriangleFan, scratch_, pixelToClip(viewport_size));
}

}  // namespace arbci::render

#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec2 uv;
layout(location = 2) in vec4 color;
uniform mat4 transform;
out vec2 texture_coord;
out vec4 vertex_color;
void main() {
  gl_Position = transform * vec4(position, 1.0);
  texture_coord = uv;
  vertex_color = color;
}

#version 330 core
// A full-viewport quad for a camera image: texture coordinate (0,0) at the image's top-left.
layout(location = 0) in vec2 corner;
out vec2 image_coord;
void main() {
  image_coord = vec2(corner.x * 0.5 + 0.5, 0.5 - corner.y * 0.5);
  gl_Position = vec4(corner, 0.0, 1.0);
}

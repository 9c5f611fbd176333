#version 330 core
in vec2 texture_coord;
in vec4 vertex_color;
uniform sampler2D marker;
uniform bool textured;
out vec4 fragment_color;
void main() {
  vec4 c = vertex_color;
  if (textured) c.rgb *= texture(marker, texture_coord).rrr;
  fragment_color = c;
}

#version 330 core
// Textured parts of the scene: the markers.
in vec2 texture_coord;
in vec4 vertex_color;
uniform sampler2D marker;
out vec4 fragment_color;
void main() { fragment_color = vec4(vertex_color.rgb * texture(marker, texture_coord).rrr, vertex_color.a); }

#version 330 core
// The untextured parts of the scene (no sampler: Mesa's llvmpipe pays for sampling code even in
// a branch not taken).
in vec2 texture_coord;
in vec4 vertex_color;
out vec4 fragment_color;
void main() { fragment_color = vertex_color; }

#version 330 core
// Shows a camera image, optionally through a remap table (undistortion on the GPU): the table
// holds, for each output pixel, the normalised source coordinate to sample.
in vec2 image_coord;
uniform sampler2D image;
uniform sampler2D remap;
uniform bool use_remap;
uniform bool grey;
out vec4 fragment_color;
void main() {
  vec2 source = use_remap ? texture(remap, image_coord).rg : image_coord;
  if (source.x < 0.0 || source.x > 1.0 || source.y < 0.0 || source.y > 1.0) {
    fragment_color = vec4(0.0, 0.0, 0.0, 1.0);
    return;
  }
  vec4 c = texture(image, source);
  fragment_color = grey ? vec4(c.rrr, 1.0) : vec4(c.rgb, 1.0);
}

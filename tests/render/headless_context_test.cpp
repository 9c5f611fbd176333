// The headless EGL context renders through the shared drawing code into a framebuffer that reads
// back exactly what was drawn.
#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include <vector>

#include "arbci/render/framebuffer.h"
#include "arbci/render/gl_context.h"
#include "arbci/render/primitive_renderer.h"

namespace arbci::render {
namespace {

void expectPixel(const RgbaImage& image, int x, int y, int r, int g, int b) {
  const std::uint8_t* p = image.at(x, y);
  EXPECT_EQ(p[0], r) << "red at " << x << "," << y;
  EXPECT_EQ(p[1], g) << "green at " << x << "," << y;
  EXPECT_EQ(p[2], b) << "blue at " << x << "," << y;
}

TEST(HeadlessContext, ReportsAnOpenGl33CoreContext) {
  auto context = createHeadlessContext({32, 32});
  ASSERT_TRUE(context->isHeadless());
  const GlInfo info = context->info();
  EXPECT_FALSE(info.vendor.empty());
  EXPECT_FALSE(info.renderer.empty());
  int major = 0, minor = 0;
  ASSERT_EQ(std::sscanf(info.version.c_str(), "%d.%d", &major, &minor), 2) << info.version;
  EXPECT_GE(major * 10 + minor, 33) << info.version;
}

TEST(HeadlessContext, RendersQuadrantsAndAThickLineThatReadBackExactly) {
  const Size size{96, 64};
  auto context = createHeadlessContext(size);
  PrimitiveRenderer renderer;
  clearFramebuffer(context->drawFramebuffer(), size, {0.0f, 0.0f, 0.0f, 1.0f});
  const glm::vec2 viewport(size.width, size.height);
  const float w = 48.0f, h = 32.0f;
  renderer.fillPolygon(std::vector<glm::vec2>{{0, 0}, {w, 0}, {w, h}, {0, h}}, {1, 0, 0, 1},
                       viewport);
  renderer.fillPolygon(std::vector<glm::vec2>{{w, 0}, {96, 0}, {96, h}, {w, h}}, {0, 1, 0, 1},
                       viewport);
  renderer.fillPolygon(std::vector<glm::vec2>{{0, h}, {w, h}, {w, 64}, {0, 64}}, {0, 0, 1, 1},
                       viewport);
  // A 4 px wide horizontal white line centred on y = 50, from x = 60 to 90, in the bottom right.
  renderer.drawPolyline(std::vector<glm::vec2>{{60, 50}, {90, 50}}, false, 4.0f, {1, 1, 1, 1},
                        viewport);
  context->present();
  const RgbaImage image = readPixels(context->drawFramebuffer(), size);
  ASSERT_EQ(image.width, 96);
  ASSERT_EQ(image.height, 64);
  expectPixel(image, 0, 0, 255, 0, 0);  // top-left quadrant red (rows are top-down)
  expectPixel(image, 47, 31, 255, 0, 0);
  expectPixel(image, 48, 0, 0, 255, 0);  // top-right green
  expectPixel(image, 95, 31, 0, 255, 0);
  expectPixel(image, 0, 32, 0, 0, 255);  // bottom-left blue
  expectPixel(image, 47, 63, 0, 0, 255);
  expectPixel(image, 70, 60, 0, 0, 0);  // bottom-right stays clear
  for (int y = 48; y < 52; ++y) expectPixel(image, 75, y, 255, 255, 255);  // the line, 4 rows
  expectPixel(image, 75, 47, 0, 0, 0);
  expectPixel(image, 75, 52, 0, 0, 0);
}

TEST(HeadlessContext, TwoContextsCoexistAndKeepTheirOwnFramebuffers) {
  auto first = createHeadlessContext({16, 16});
  auto second = createHeadlessContext({8, 8});
  second->makeCurrent();
  clearFramebuffer(second->drawFramebuffer(), {8, 8}, {0.0f, 1.0f, 0.0f, 1.0f});
  first->makeCurrent();
  clearFramebuffer(first->drawFramebuffer(), {16, 16}, {1.0f, 0.0f, 0.0f, 1.0f});
  expectPixel(readPixels(first->drawFramebuffer(), {16, 16}), 8, 8, 255, 0, 0);
  second->makeCurrent();
  expectPixel(readPixels(second->drawFramebuffer(), {8, 8}), 4, 4, 0, 255, 0);
}

TEST(HeadlessContext, RejectsAnEmptyFramebufferSize) {
  EXPECT_THROW(createHeadlessContext({0, 10}), GlError);
}

}  // namespace
}  // namespace arbci::render

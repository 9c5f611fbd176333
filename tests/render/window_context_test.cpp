// The GLFW window back end runs the same drawing code as the headless one (on an Xvfb display).
#include <gtest/gtest.h>

#include <cstdlib>
#include <glm/glm.hpp>
#include <vector>

#include "arbci/render/framebuffer.h"
#include "arbci/render/primitive_renderer.h"
#include "arbci/render/window_context.h"
#include "arbci/ui/experimenter_shell.h"
#include "arbci/ui/imgui_layer.h"
#include "arbci/ui/system_panel.h"
#include "support/panel_bench.h"
#include "support/xvfb_server.h"

namespace arbci::render {
namespace {

// One X server for this test program, started before the first window opens.
void useXvfbDisplay() {
  static const test::XvfbServer server("1280x1024x24");
  setenv("DISPLAY", server.display().c_str(), 1);
  unsetenv("XAUTHORITY");
}

// The experimenter shell with a panel in a window of its own: its text is drawn.
void drawTheShell() {
  WindowContext window({"shell", {800, 500}, true, -1, nullptr, false});
  ui::SystemPanel panel({{std::string("context"), std::string("window (GLFW)")}});
  ui::ImGuiLayer imgui(window, "");
  ui::ExperimenterShell shell;
  shell.addPanel(panel);
  test::PanelBench bench;
  RgbaImage image;
  for (int frame = 0; frame < 3; ++frame) {
    WindowContext::pollEvents();
    imgui.beginFrame(1.0f / 60.0f);
    shell.draw(window.framebufferSize(), {16.7f, "test", ""}, bench.input());
    clearFramebuffer(0, window.framebufferSize(), {0.0f, 0.0f, 0.0f, 1.0f});
    imgui.endFrame();
    image = readPixels(0, window.framebufferSize());
    window.present();
  }
  int bright = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) bright += image.at(x, y)[1] > 150;
  }
  EXPECT_GT(bright, 100) << "no text drawn";
}

// One test opens the windows (a window opened is counted among the whole-window tests): a pattern
// drawn into the back buffer, then the shell.
TEST(WindowContext, DrawsThePatternAndTheExperimenterShell) {
  useXvfbDisplay();
  ASSERT_TRUE(displayAvailable()) << "no DISPLAY although Xvfb was started";
  {
    WindowContext window({"test", {80, 60}, true, -1, nullptr, false});
    const Size size = window.framebufferSize();
    ASSERT_EQ(size, (Size{80, 60}));
    EXPECT_FALSE(window.isHeadless());
    PrimitiveRenderer renderer;
    clearFramebuffer(window.drawFramebuffer(), size, {0.0f, 0.0f, 0.0f, 1.0f});
    renderer.fillPolygon(std::vector<glm::vec2>{{0, 0}, {40, 0}, {40, 30}, {0, 30}}, {1, 0, 0, 1},
                         glm::vec2(80, 60));
    const RgbaImage image = readPixels(0, size);
    EXPECT_EQ(image.at(10, 10)[0], 255);
    EXPECT_EQ(image.at(10, 10)[1], 0);
    EXPECT_EQ(image.at(60, 50)[0], 0);
    window.present();
  }
  drawTheShell();
}

}  // namespace
}  // namespace arbci::render

// The scripted experimenter on panels drawn in process (EGL): a click waits for its button and
// presses it with real pointer input; a button still disabled at its time limit fails the script
// naming the line and the reason; a script that does not parse is refused naming the line. Time
// is the script's own (given each frame), not the wall clock.
#include <gtest/gtest.h>

#include <fstream>

#include "arbci/render/framebuffer.h"
#include "arbci/render/gl_context.h"
#include "arbci/ui/experimenter_shell.h"
#include "arbci/ui/imgui_layer.h"
#include "arbci/ui/panel_registry.h"
#include "support/panel_bench.h"
#include "support/test_files.h"
#include "workstation/experimenter_script.h"

namespace arbci::app {
namespace {

std::filesystem::path scriptFile(const std::string& name, const std::string& text) {
  const auto file = test::freshTempPath("experimenter_script", name);
  std::ofstream(file) << text;
  return file;
}

// Runs `script` over the Session panel in phase 1 (Pause enabled, Skip trial nowhere), `dt`
// seconds a frame; returns the script when done or after `frames`.
void play(ExperimenterScript& script, test::PanelBench& bench, int frames, double dt = 0.1) {
  const render::Size size{1000, 700};
  auto context = render::createHeadlessContext(size);
  ui::ImGuiLayer imgui(*context, "");
  ui::ExperimenterShell shell;
  auto panel = ui::panels().at("session").make.make();
  shell.addPanel(*panel);
  for (int frame = 0; frame < frames && !script.done(); ++frame) {
    const std::string phase = bci::toString(bench.record.paradigm.phase);
    ui::SyntheticInput input = script.beforeFrame(frame * dt, phase);
    context->makeCurrent();
    imgui.beginFrame(1.0f / 60.0f, &input);
    shell.draw(size, {16.7f, phase, ""}, bench.input());
    render::clearFramebuffer(context->drawFramebuffer(), size, {0.08f, 0.09f, 0.11f, 1.0f});
    imgui.endFrame();
    script.afterFrame(*context, size, phase, frame * dt);
  }
}

TEST(ExperimenterScript, AClickPressesItsButtonOnceItIsDrawn) {
  test::PanelBench bench;
  bench.record.paradigm.phase = bci::Phase::ObjectFlashing;
  ExperimenterScript script(scriptFile("pause", "wait \"objects flashing\" 5\nclick \"Pause\"\n"));
  play(script, bench, 50);
  EXPECT_TRUE(script.done());
  EXPECT_EQ(script.error(), "");
  EXPECT_EQ(bench.requests.count<session::PauseRequest>(), 1);
}

TEST(ExperimenterScript, AClickOnADisabledButtonFailsNamingTheLineAndTheReason) {
  test::PanelBench bench;
  bench.record.paradigm.phase = bci::Phase::ObjectFlashing;
  ExperimenterScript script(scriptFile("refused", "pause 0.5\nclick \"Resume\" 2\n"));
  play(script, bench, 100);
  EXPECT_EQ(script.error(),
            "script line 2: \"Resume\" stayed disabled: nothing to resume: the session is not "
            "paused or stopped");
  EXPECT_EQ(bench.requests.count<session::ResumeRequest>(), 0);
}

TEST(ExperimenterScript, AWaitForAPhaseThatNeverComesFailsWithThePhaseSeen) {
  test::PanelBench bench;
  ExperimenterScript script(scriptFile("wait", "wait \"finished\" 1\n"));
  play(script, bench, 30);
  EXPECT_EQ(script.error(), "script line 1: waited 1 s for \"finished\"; the phase is \"set-up\"");
}

TEST(ExperimenterScript, AScriptThatDoesNotParseIsRefusedNamingTheLine) {
  try {
    ExperimenterScript script(scriptFile("bad", "pause 1\ndance \"now\"\n"));
    FAIL() << "a script with an unknown command was taken";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("line 2: unknown command 'dance'"), std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace arbci::app

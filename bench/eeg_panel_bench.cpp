// What the EEG panel's drawing costs a frame on the CPU: ImGui's frame with the panel's window
// (controls, legend, traces, quality table) against the same frame with an empty window, for 8,
// 32 and 64 channels of 256 Hz on a 1600x900 window, 5 s and 10 s time bases. The draw lists
// it builds go to the GPU as they are; their raster is not measured here.
#include <benchmark/benchmark.h>
#include <imgui.h>

#include <random>

#include "arbci/ui/eeg_view.h"

namespace {

arbci::bci::SignalScope makeScope(int channels) {
  arbci::bci::SignalInfo info;
  info.rate_hz = 256.0;
  info.block_size = 15;
  for (int c = 0; c < channels; ++c) {
    std::string name = "E";
    name += std::to_string(c + 1);
    info.channels.push_back(name);
  }
  info.channels.back() = "Photodiode";
  arbci::bci::SignalScope scope(info, 10.0, arbci::bci::FilterSettings{},
                                arbci::bci::QualityThresholds{});
  std::mt19937 random(1);
  std::normal_distribution<float> noise(0.0f, 10.0f);
  for (std::int64_t first = 0; first < 2560 + 15; first += 15) {
    arbci::bci::Block block(first, channels, 15);
    for (float& v : block.data) v = noise(random);
    scope.append(block);
    if (first % 45 == 0) scope.markStimulus(first);
  }
  return scope;
}

struct ImGuiFrame {
  ImGuiFrame() {
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.DisplaySize = ImVec2(1600, 900);
    io.IniFilename = nullptr;
    // As the OpenGL 3 back end declares (GL 3.2 and later): draw lists over 64k vertices split.
    io.BackendFlags |= ImGuiBackendFlags_RendererHasVtxOffset;
    unsigned char* pixels = nullptr;
    int w = 0, h = 0;
    io.Fonts->GetTexDataAsRGBA32(&pixels, &w, &h);  // the font atlas, built once
  }
  ~ImGuiFrame() { ImGui::DestroyContext(); }
  template <typename Draw>
  void frame(Draw&& draw) {
    ImGui::GetIO().DeltaTime = 1.0f / 60.0f;
    ImGui::NewFrame();
    ImGui::SetNextWindowPos(ImVec2(0, 0));
    ImGui::SetNextWindowSize(ImVec2(1600, 900));
    ImGui::Begin("EEG");
    draw();
    ImGui::End();
    ImGui::Render();
  }
};

void EegPanelFrame(benchmark::State& state) {
  const int channels = static_cast<int>(state.range(0));
  const bool draw_view = state.range(1) != 0;
  const double time_base_s = static_cast<double>(state.range(2));
  arbci::bci::SignalScope scope = makeScope(channels);
  ImGuiFrame imgui;
  arbci::ui::EegView view;
  view.setTimeBase(time_base_s);
  // The grades as the session's record carries them.
  arbci::session::QualityPart quality;
  quality.channels = scope.info().channels;
  quality.quality = scope.quality();
  for (auto _ : state) {
    imgui.frame([&] {
      if (draw_view) view.draw(scope, quality, arbci::bci::QualityThresholds{}, "Photodiode", "");
    });
    benchmark::DoNotOptimize(ImGui::GetDrawData());
  }
  state.SetLabel(draw_view ? "panel, " + std::to_string(static_cast<int>(time_base_s)) + " s"
                           : std::string("empty window"));
}
BENCHMARK(EegPanelFrame)
    ->ArgsProduct({{8, 32, 64}, {0, 1}, {5, 10}})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();

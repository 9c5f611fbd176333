// Frame time of the stereo HMD view, headless (EGL, Mesa llvmpipe on the CPU): both eyes'
// camera images uploaded, four object highlights and the 3x3 grid drawn, with and without GPU
// undistortion, finished (glFinish) -- and the same plus reading the frame back.
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>

#include "arbci/render/framebuffer.h"
#include "arbci/render/gl_context.h"
#include "arbci/render/hmd_view.h"

namespace {

using namespace arbci::render;
namespace vision = arbci::vision;

void stereoView(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0)), height = static_cast<int>(state.range(1));
  const bool undistort = state.range(2) != 0, read_back = state.range(3) != 0;
  auto context = createHeadlessContext({2 * width, height});
  HmdView view;
  view.setUndistort(undistort);
  vision::CameraModel camera;
  camera.image_size = {width, height};
  const double f = 1.1 * width;
  camera.camera_matrix = cv::Matx33d(f, 0, width / 2.0 - 0.5, 0, f, height / 2.0 - 0.5, 0, 0, 1);
  camera.distortion = {-0.2, 0.05, 0, 0, 0};
  cv::Mat image(height, width, CV_8UC3);
  cv::randu(image, 0, 255);
  HmdFrame frame;
  frame.left = {image, camera, vision::cameraLookingAt({-0.032, 1.45, 0.45}, {0, 0.65, 0})};
  frame.right = {image.clone(), camera, vision::cameraLookingAt({0.032, 1.45, 0.45}, {0, 0.65, 0})};
  for (int i = 0; i < 4; ++i) {
    ObjectHighlight o;
    o.id = i + 1;
    o.T_world_top = {cv::Matx33d::eye(), cv::Vec3d(-0.3 + 0.2 * i, 0.55, 0.06)};
    o.state = i == 1 ? HighlightState::Flashing : HighlightState::Idle;
    frame.objects.push_back(o);
  }
  GridLayout grid;
  grid.T_world_grid = {cv::Matx33d::eye(), cv::Vec3d(0.25, 0.7, 0)};
  grid.rows = grid.columns = 3;
  grid.cell_m = 0.08;
  frame.grid = grid;
  frame.grid_highlight.rows = {2};
  for (auto _ : state) {
    view.draw(frame, context->drawFramebuffer(), {2 * width, height});
    if (read_back) {
      benchmark::DoNotOptimize(
          readPixels(context->drawFramebuffer(), {2 * width, height}).pixels.data());
    } else {
      context->present();  // waits for the GPU
    }
  }
  state.SetLabel(std::string("2x") + std::to_string(width) + "x" + std::to_string(height) +
                 (undistort ? " undistorted" : " raw") + (read_back ? " +read-back" : ""));
}

}  // namespace

BENCHMARK(stereoView)
    ->Args({640, 480, 0, 0})
    ->Args({640, 480, 1, 0})
    ->Args({640, 480, 1, 1})
    ->Args({1280, 720, 0, 0})
    ->Args({1280, 720, 1, 0})
    ->Args({1280, 720, 1, 1})
    ->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();

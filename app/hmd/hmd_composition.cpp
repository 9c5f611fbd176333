#include "hmd/hmd_composition.h"

#include <algorithm>
#include <opencv2/core.hpp>
#include <sstream>

namespace arbci::app {

render::GridLayout gridLayoutOf(const session::GridSettings& grid) {
  render::GridLayout layout;
  layout.T_world_grid = {cv::Matx33d::eye(), grid.centre};
  layout.rows = grid.rows;
  layout.columns = grid.columns;
  layout.cell_m = grid.cell_m;
  return layout;
}

render::HmdFrame composeHmdFrame(const bci::FrameStimulus& stimulus, const HmdScene& scene) {
  const session::TrackingPart& tracking = scene.tracking;
  render::HmdFrame frame;
  frame.left = {tracking.left_image, tracking.left_camera, tracking.T_cam_world_left};
  frame.right = {tracking.right_image, tracking.right_camera, tracking.T_cam_world_right};
  if (!scene.rest.empty()) {
    // Nothing overlaid: the instruction alone (the photodiode patch stays dark).
    frame.left.image = frame.right.image = scene.rest;
    frame.left.T_cam_world = frame.right.T_cam_world = std::nullopt;
    if (scene.photodiode_patch) frame.photodiode_patch = false;
    return frame;
  }
  const bool objects_phase = stimulus.phase == bci::Phase::ObjectFlashing ||
                             stimulus.phase == bci::Phase::CalibrationFlashing;
  const auto& objects = scene.objects;
  for (size_t i = 0; i < objects.size(); ++i) {
    const session::WorldObjectSettings& o = objects[i];
    const auto state = tracking.world ? tracking.world->object(o.id) : std::nullopt;
    if (!state) continue;
    render::ObjectHighlight h;
    h.id = o.id;
    h.T_world_top = state->T_robot_object;
    h.side_m = o.marker_m;
    const auto in_slots = std::find(scene.slots.begin(), scene.slots.end(), i);
    const int slot =
        in_slots == scene.slots.end() ? 0 : static_cast<int>(in_slots - scene.slots.begin()) + 1;
    if (objects_phase && stimulus.lit.count(slot)) h.state = render::HighlightState::Flashing;
    if (stimulus.cued_object == slot)
      h.state = stimulus.lit.count(slot) ? render::HighlightState::Flashing
                                         : render::HighlightState::Cued;
    if (stimulus.selected_object == slot) h.state = render::HighlightState::Selected;
    // A stale pose is shown greyed, never flashed (the paradigm's stage withholds its flashes).
    if (!tracking.fresh(o.id, scene.now_s)) h.state = render::HighlightState::Lost;
    if (scene.holding == o.id) h.state = render::HighlightState::Held;
    frame.objects.push_back(h);
  }
  if (stimulus.grid_visible) {
    frame.grid = scene.grid;
    if (stimulus.phase == bci::Phase::CellFlashing) {
      for (int code : stimulus.lit) {
        if (code <= scene.grid.rows)
          frame.grid_highlight.rows.insert(code);
        else
          frame.grid_highlight.columns.insert(code - scene.grid.rows);
      }
    }
    frame.grid_highlight.selected = stimulus.selected_cell;
  }
  if (scene.photodiode_patch) frame.photodiode_patch = !stimulus.lit.empty();
  return frame;
}

std::string hmdFrameSignature(const render::HmdFrame& frame) {
  std::ostringstream signature;
  if (frame.photodiode_patch) signature << (*frame.photodiode_patch ? "P" : "p");
  signature << static_cast<const void*>(frame.left.image.data)
            << static_cast<const void*>(frame.right.image.data);
  for (const auto* eye : {&frame.left, &frame.right}) {
    if (eye->T_cam_world)
      signature << cv::Mat(eye->T_cam_world->rotation) << cv::Mat(eye->T_cam_world->translation);
  }
  for (const render::ObjectHighlight& h : frame.objects) {
    signature << h.id << static_cast<int>(h.state) << cv::Mat(h.T_world_top.rotation)
              << cv::Mat(h.T_world_top.translation);
  }
  if (frame.grid) {
    signature << "grid";
    for (int r : frame.grid_highlight.rows) signature << 'r' << r;
    for (int c : frame.grid_highlight.columns) signature << 'c' << c;
    if (frame.grid_highlight.selected)
      signature << 's' << frame.grid_highlight.selected->first
                << frame.grid_highlight.selected->second;
  }
  return signature.str();
}

}  // namespace arbci::app

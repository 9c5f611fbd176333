// What the HMD shows on a frame, composed from the paradigm's stimulus and the tracked world:
// each tracked object's highlight (idle, cued, flashing, selected, held; greyed when its pose is
// stale), the grid with its lit rows and columns and the selected cell, and the photodiode patch.
// And the frame's signature: an unchanged frame need not be drawn again.
#pragma once

#include <string>
#include <vector>

#include "arbci/bci/paradigm.h"
#include "arbci/render/hmd_view.h"
#include "arbci/session/cycle.h"
#include "arbci/session/session_config.h"

namespace arbci::app {

struct HmdScene {
  const std::vector<session::WorldObjectSettings>& objects;
  const session::TrackingPart& tracking;
  // Stimulus code k stands for objects[slots[k - 1]].
  const std::vector<size_t>& slots;
  int holding = -1;  // the marker id of the object in the gripper, -1: none
  render::GridLayout grid;
  bool photodiode_patch = false;
  double now_s = 0.0;  // the frame's time: objects with an older pose than allowed are greyed
  // A rest screen instead of the scene (rest_screen.h): each eye's image; empty: the scene.
  cv::Mat rest;
};

// The session file's grid as the renderer draws it (on the table, in the robot frame).
render::GridLayout gridLayoutOf(const session::GridSettings& grid);

render::HmdFrame composeHmdFrame(const bci::FrameStimulus& stimulus, const HmdScene& scene);
std::string hmdFrameSignature(const render::HmdFrame& frame);

}  // namespace arbci::app

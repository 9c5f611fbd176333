// The projection layer a frame submits to an OpenXR runtime: one view per eye, each the eye's
// whole swapchain image seen from the pose and field of view the runtime located for that eye.
#pragma once

#include <openxr/openxr.h>

#include <array>

#include "arbci/render/gl_context.h"

namespace arbci::render {

// An OpenXR structure of `type`, every other member zero.
template <typename T>
T xrStruct(XrStructureType type) {
  T t{};
  t.type = type;
  return t;
}

// Holds the views the layer points to: fill it in place and submit `layer` while it lives.
struct ProjectionLayer {
  XrCompositionLayerProjection layer =
      xrStruct<XrCompositionLayerProjection>(XR_TYPE_COMPOSITION_LAYER_PROJECTION);
  std::array<XrCompositionLayerProjectionView, 2> views{};

  ProjectionLayer() = default;
  ProjectionLayer(const ProjectionLayer&) = delete;  // `layer` points into `views`
  ProjectionLayer& operator=(const ProjectionLayer&) = delete;

  // Left eye first, as xrLocateViews returns the views of a stereo headset.
  void fill(XrSpace space, const std::array<XrView, 2>& located,
            const std::array<XrSwapchain, 2>& swapchains, Size eye);
};

}  // namespace arbci::render

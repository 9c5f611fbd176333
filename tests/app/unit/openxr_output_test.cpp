// What an OpenXR runtime is given, without a runtime: the projection layer that points at the
// eyes' images, result codes by name, and a loader with no runtime refused with the cause and its
// code. (The eyes' images from the HMD stage's frames: hmd_stage_test.cpp.)
#include <gtest/gtest.h>

#include <cstdlib>

#include "arbci/render/gl_context.h"
#include "arbci/render/openxr_display.h"
#include "arbci/render/openxr_layer.h"
#include "hmd/openxr_output.h"

namespace arbci::app {
namespace {

TEST(OpenXrLayer, OneViewPerEyeEachTheWholeImageFromItsLocatedPose) {
  std::array<XrView, 2> located{render::xrStruct<XrView>(XR_TYPE_VIEW),
                                render::xrStruct<XrView>(XR_TYPE_VIEW)};
  located[0].pose.position = {-0.032f, 1.6f, 0.0f};
  located[1].pose.position = {0.032f, 1.6f, 0.0f};
  located[0].pose.orientation.w = located[1].pose.orientation.w = 1.0f;
  located[0].fov = {-0.8f, 0.7f, 0.75f, -0.75f};
  located[1].fov = {-0.7f, 0.8f, 0.75f, -0.75f};
  const auto left = reinterpret_cast<XrSwapchain>(0x11);
  const auto right = reinterpret_cast<XrSwapchain>(0x22);
  const auto space = reinterpret_cast<XrSpace>(0x33);
  render::ProjectionLayer p;
  p.fill(space, located, {left, right}, {640, 480});
  EXPECT_EQ(p.layer.type, XR_TYPE_COMPOSITION_LAYER_PROJECTION);
  EXPECT_EQ(p.layer.space, space);
  ASSERT_EQ(p.layer.viewCount, 2u);
  ASSERT_EQ(p.layer.views, p.views.data());
  const std::array<XrSwapchain, 2> chains{left, right};
  for (size_t i = 0; i < 2; ++i) {
    const XrCompositionLayerProjectionView& v = p.layer.views[i];
    EXPECT_EQ(v.type, XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW);
    EXPECT_EQ(v.subImage.swapchain, chains[i]);
    EXPECT_EQ(v.subImage.imageRect.offset.x, 0);
    EXPECT_EQ(v.subImage.imageRect.extent.width, 640);
    EXPECT_EQ(v.subImage.imageRect.extent.height, 480);
    EXPECT_EQ(v.pose.position.x, located[i].pose.position.x);
    EXPECT_EQ(v.fov.angleLeft, located[i].fov.angleLeft);
  }
}

TEST(OpenXrResult, ResultCodesAreNamed) {
  EXPECT_EQ(render::xrResultText(XR_ERROR_RUNTIME_UNAVAILABLE),
            "XR_ERROR_RUNTIME_UNAVAILABLE (-51)");
  EXPECT_EQ(render::xrResultText(XR_ERROR_FORM_FACTOR_UNAVAILABLE),
            "XR_ERROR_FORM_FACTOR_UNAVAILABLE (-35)");
  EXPECT_EQ(render::xrResultText(-123456), "XrResult -123456");
}

TEST(OpenXrOutputOpen, WithoutTheLoaderTheFailureSaysWhichPackageToInstall) {
  auto context = render::createHeadlessContext({64, 64});
  try {
    render::OpenXrDisplay display(*context, {640, 480}, 5.0, "libarbci_no_such_openxr_loader.so");
    FAIL() << "opened without a loader";
  } catch (const render::OpenXrError& error) {
    const std::string what = error.what();
    EXPECT_EQ(what.rfind("OpenXR: no OpenXR loader: ", 0), 0u) << what;
    EXPECT_NE(what.find("libarbci_no_such_openxr_loader.so"), std::string::npos) << what;
    EXPECT_NE(what.find("install Debian's libopenxr-loader1"), std::string::npos) << what;
    EXPECT_EQ(error.result(), XR_ERROR_RUNTIME_UNAVAILABLE);
  }
}

TEST(OpenXrOutputOpen, WithoutARuntimeTheFailureNamesTheSettingTheCallAndTheCode) {
  auto context = render::createHeadlessContext({64, 64});
  ::setenv("XR_RUNTIME_JSON", "/nonexistent/arbci/no_runtime.json", 1);
  session::SessionConfig config;
  config.hmd.output = "openxr";
  OpenXrOutput output(config, *context);
  ::unsetenv("XR_RUNTIME_JSON");
  EXPECT_FALSE(output.open());
  const std::string& failure = output.failure();
  EXPECT_EQ(failure.rfind("hmd.output = openxr: OpenXR: no runtime answered", 0), 0u) << failure;
  EXPECT_NE(failure.find("XR_ERROR_"), std::string::npos) << failure;
  EXPECT_NE(failure.find("set hmd.output to window"), std::string::npos) << failure;
}

}  // namespace
}  // namespace arbci::app

#include "arbci/render/openxr_display.h"

#include <EGL/egl.h>
#include <GL/glx.h>
#include <time.h>

#include "gl.h"
#define XR_USE_PLATFORM_EGL
#define XR_USE_PLATFORM_XLIB
#define XR_USE_GRAPHICS_API_OPENGL
#define XR_USE_TIMESPEC
// Every call through the loader opened at run time (dlopen): a machine without it runs the
// window path as ever and fails only hmd.output "openxr", saying so.
#define XR_NO_PROTOTYPES
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>
#include <openxr/openxr_reflection.h>

#include <dlfcn.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>
#include <vector>

#include "arbci/render/openxr_layer.h"

namespace arbci::render {

std::string xrResultText(int result) {
  switch (result) {
#define ARBCI_XR_RESULT(name, value) \
  case value:                        \
    return #name " (" #value ")";
    XR_LIST_ENUM_XrResult(ARBCI_XR_RESULT)
#undef ARBCI_XR_RESULT
  }
  return "XrResult " + std::to_string(result);
}

void ProjectionLayer::fill(XrSpace space, const std::array<XrView, 2>& located,
                           const std::array<XrSwapchain, 2>& swapchains, Size eye) {
  for (size_t i = 0; i < 2; ++i) {
    XrCompositionLayerProjectionView& v = views[i];
    v = xrStruct<XrCompositionLayerProjectionView>(XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW);
    v.pose = located[i].pose;
    v.fov = located[i].fov;
    v.subImage.swapchain = swapchains[i];
    v.subImage.imageRect = {{0, 0}, {eye.width, eye.height}};
    v.subImage.imageArrayIndex = 0;
  }
  layer = xrStruct<XrCompositionLayerProjection>(XR_TYPE_COMPOSITION_LAYER_PROJECTION);
  layer.space = space;
  layer.viewCount = 2;
  layer.views = views.data();
}

void copyEyes(unsigned int texture, Size size, unsigned int left, unsigned int right, Size eye) {
  GLint previous_read = 0, previous_draw = 0;
  glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &previous_read);
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &previous_draw);
  GLuint fbos[2];
  glGenFramebuffers(2, fbos);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbos[0]);
  glFramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture, 0);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbos[1]);
  const int half = size.width / 2;
  for (int i = 0; i < 2; ++i) {
    glFramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D,
                           i == 0 ? left : right, 0);
    const int x0 = i * half;
    const bool same = half == eye.width && size.height == eye.height;
    glBlitFramebuffer(x0, 0, x0 + half, size.height, 0, 0, eye.width, eye.height,
                      GL_COLOR_BUFFER_BIT, same ? GL_NEAREST : GL_LINEAR);
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>(previous_read));
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(previous_draw));
  glDeleteFramebuffers(2, fbos);
}

namespace {

// The OpenXR functions ARBCI calls, each resolved through xrGetInstanceProcAddr.
// clang-format off
#define ARBCI_XR_GLOBAL_FUNCTIONS(X) \
  X(xrEnumerateInstanceExtensionProperties) X(xrCreateInstance)
#define ARBCI_XR_INSTANCE_FUNCTIONS(X)                                                         \
  X(xrAcquireSwapchainImage) X(xrBeginFrame) X(xrBeginSession) X(xrCreateReferenceSpace)       \
  X(xrCreateSession) X(xrCreateSwapchain) X(xrDestroyInstance) X(xrDestroySession)             \
  X(xrDestroySpace) X(xrDestroySwapchain) X(xrEndFrame) X(xrEndSession)                        \
  X(xrEnumerateSwapchainFormats) X(xrEnumerateSwapchainImages)                                 \
  X(xrEnumerateViewConfigurationViews) X(xrGetInstanceProperties) X(xrGetSystem)               \
  X(xrGetSystemProperties) X(xrLocateSpace) X(xrLocateViews) X(xrPollEvent)                    \
  X(xrReleaseSwapchainImage) X(xrRequestExitSession) X(xrWaitFrame) X(xrWaitSwapchainImage)    \
  X(xrConvertTimeToTimespecTimeKHR) X(xrGetOpenGLGraphicsRequirementsKHR)
// clang-format on

struct XrApi {
  PFN_xrGetInstanceProcAddr xrGetInstanceProcAddr = nullptr;
#define ARBCI_XR_DECLARE(name) PFN_##name name = nullptr;
  ARBCI_XR_GLOBAL_FUNCTIONS(ARBCI_XR_DECLARE)
  ARBCI_XR_INSTANCE_FUNCTIONS(ARBCI_XR_DECLARE)
#undef ARBCI_XR_DECLARE
};

double secondsOf(const timespec& t) {
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

struct OpenXrDisplay::State {
  XrInstance instance = XR_NULL_HANDLE;
  XrSystemId system = XR_NULL_SYSTEM_ID;
  XrSession session = XR_NULL_HANDLE;
  XrSpace local = XR_NULL_HANDLE, view = XR_NULL_HANDLE;
  std::array<XrSwapchain, 2> swapchains{XR_NULL_HANDLE, XR_NULL_HANDLE};
  std::array<std::vector<XrSwapchainImageOpenGLKHR>, 2> images;
  XrSessionState state = XR_SESSION_STATE_UNKNOWN;
  bool running = false;
  std::string runtime, system_name;
  Size eye;
  double period_s = 0.0;
  void* loader = nullptr;  // dlopen's handle, closed last
  XrApi api;

  // The runtime's name leads every message, once one answered.
  [[noreturn]] void fail(const std::string& what, XrResult result) const {
    const std::string who = runtime.empty() ? "OpenXR" : "OpenXR runtime " + runtime;
    throw OpenXrError(who + ": " + what + " returned " + xrResultText(result), result);
  }
  void check(XrResult result, const char* what) const {
    if (XR_FAILED(result)) fail(what, result);
  }
  // The loader, and through it the functions that need no instance.
  void openLoader(const std::string& library) {
    // Not a call's result: said as what is missing.
    loader = dlopen(library.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!loader)
      throw OpenXrError("OpenXR: no OpenXR loader: " + std::string(dlerror()) +
                            " (install Debian's libopenxr-loader1)",
                        XR_ERROR_RUNTIME_UNAVAILABLE);
    api.xrGetInstanceProcAddr =
        reinterpret_cast<PFN_xrGetInstanceProcAddr>(dlsym(loader, "xrGetInstanceProcAddr"));
    if (!api.xrGetInstanceProcAddr)
      throw OpenXrError("OpenXR: " + library + " has no xrGetInstanceProcAddr",
                        XR_ERROR_RUNTIME_UNAVAILABLE);
#define ARBCI_XR_LOAD(name) load(XR_NULL_HANDLE, #name, api.name);
    ARBCI_XR_GLOBAL_FUNCTIONS(ARBCI_XR_LOAD)
#undef ARBCI_XR_LOAD
  }
  template <typename F>
  void load(XrInstance from, const char* name, F& f) const {
    PFN_xrVoidFunction any = nullptr;
    check(api.xrGetInstanceProcAddr(from, name, &any), name);
    f = reinterpret_cast<F>(any);
  }

  // Takes the runtime's events; the session's state tells when frames may go and when it ends.
  void pollEvents() {
    XrEventDataBuffer event = xrStruct<XrEventDataBuffer>(XR_TYPE_EVENT_DATA_BUFFER);
    while (true) {
      event = xrStruct<XrEventDataBuffer>(XR_TYPE_EVENT_DATA_BUFFER);
      const XrResult r = api.xrPollEvent(instance, &event);
      if (r == XR_EVENT_UNAVAILABLE) return;
      check(r, "xrPollEvent");
      if (event.type == XR_TYPE_EVENT_DATA_INSTANCE_LOSS_PENDING)
        fail("the instance is about to be lost (xrPollEvent)", XR_ERROR_INSTANCE_LOST);
      if (event.type != XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED) continue;
      state = reinterpret_cast<const XrEventDataSessionStateChanged&>(event).state;
      if (state == XR_SESSION_STATE_READY && !running) {
        XrSessionBeginInfo begin = xrStruct<XrSessionBeginInfo>(XR_TYPE_SESSION_BEGIN_INFO);
        begin.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
        check(api.xrBeginSession(session, &begin), "xrBeginSession");
        running = true;
      } else if (state == XR_SESSION_STATE_STOPPING) {
        api.xrEndSession(session);
        running = false;
        fail("the runtime stopped the session (state STOPPING)", XR_ERROR_SESSION_NOT_RUNNING);
      } else if (state == XR_SESSION_STATE_LOSS_PENDING || state == XR_SESSION_STATE_EXITING) {
        running = false;
        fail(std::string("the session ended (state ") +
                 (state == XR_SESSION_STATE_EXITING ? "EXITING" : "LOSS_PENDING") + ")",
             XR_ERROR_SESSION_LOST);
      }
    }
  }

  void createInstance(bool egl) {
    uint32_t count = 0;
    XrResult r = api.xrEnumerateInstanceExtensionProperties(nullptr, 0, &count, nullptr);
    if (XR_FAILED(r))
      fail(
          "no runtime answered (is one installed and active? XR_RUNTIME_JSON or "
          "/etc/xdg/openxr/1/active_runtime.json names it): "
          "xrEnumerateInstanceExtensionProperties",
          r);
    std::vector<XrExtensionProperties> available(
        count, xrStruct<XrExtensionProperties>(XR_TYPE_EXTENSION_PROPERTIES));
    check(api.xrEnumerateInstanceExtensionProperties(nullptr, count, &count, available.data()),
          "xrEnumerateInstanceExtensionProperties");
    auto has = [&](const char* name) {
      return std::any_of(available.begin(), available.end(), [&](const XrExtensionProperties& e) {
        return std::strcmp(e.extensionName, name) == 0;
      });
    };
    std::vector<const char*> wanted{XR_KHR_OPENGL_ENABLE_EXTENSION_NAME,
                                    XR_KHR_CONVERT_TIMESPEC_TIME_EXTENSION_NAME};
    if (egl) wanted.push_back(XR_MNDX_EGL_ENABLE_EXTENSION_NAME);
    for (const char* name : wanted) {
      if (!has(name))
        fail(std::string("the runtime lacks ") + name +
                 (egl ? " (a headless run needs XR_MNDX_egl_enable; run in a window instead)" : ""),
             XR_ERROR_EXTENSION_NOT_PRESENT);
    }
    XrInstanceCreateInfo info = xrStruct<XrInstanceCreateInfo>(XR_TYPE_INSTANCE_CREATE_INFO);
    std::strncpy(info.applicationInfo.applicationName, "ARBCI", XR_MAX_APPLICATION_NAME_SIZE - 1);
    info.applicationInfo.applicationVersion = 1;
    std::strncpy(info.applicationInfo.engineName, "ARBCI", XR_MAX_ENGINE_NAME_SIZE - 1);
    info.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
    info.enabledExtensionCount = static_cast<uint32_t>(wanted.size());
    info.enabledExtensionNames = wanted.data();
    check(api.xrCreateInstance(&info, &instance), "xrCreateInstance");
#define ARBCI_XR_LOAD(name) load(instance, #name, api.name);
    ARBCI_XR_INSTANCE_FUNCTIONS(ARBCI_XR_LOAD)
#undef ARBCI_XR_LOAD
    XrInstanceProperties properties = xrStruct<XrInstanceProperties>(XR_TYPE_INSTANCE_PROPERTIES);
    check(api.xrGetInstanceProperties(instance, &properties), "xrGetInstanceProperties");
    runtime = std::string(properties.runtimeName) + " " +
              std::to_string(XR_VERSION_MAJOR(properties.runtimeVersion)) + "." +
              std::to_string(XR_VERSION_MINOR(properties.runtimeVersion)) + "." +
              std::to_string(XR_VERSION_PATCH(properties.runtimeVersion));
  }

  void findHeadset() {
    XrSystemGetInfo info = xrStruct<XrSystemGetInfo>(XR_TYPE_SYSTEM_GET_INFO);
    info.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
    const XrResult r = api.xrGetSystem(instance, &info, &system);
    if (r == XR_ERROR_FORM_FACTOR_UNAVAILABLE)
      fail("no headset is connected (or it is off): xrGetSystem", r);
    check(r, "xrGetSystem");
    XrSystemProperties properties = xrStruct<XrSystemProperties>(XR_TYPE_SYSTEM_PROPERTIES);
    check(api.xrGetSystemProperties(instance, system, &properties), "xrGetSystemProperties");
    system_name = properties.systemName;
    XrGraphicsRequirementsOpenGLKHR requirements =
        xrStruct<XrGraphicsRequirementsOpenGLKHR>(XR_TYPE_GRAPHICS_REQUIREMENTS_OPENGL_KHR);
    check(api.xrGetOpenGLGraphicsRequirementsKHR(instance, system, &requirements),
          "xrGetOpenGLGraphicsRequirementsKHR");
  }

  void createSession(const NativeGl& gl) {
    XrGraphicsBindingEGLMNDX egl =
        xrStruct<XrGraphicsBindingEGLMNDX>(XR_TYPE_GRAPHICS_BINDING_EGL_MNDX);
    XrGraphicsBindingOpenGLXlibKHR glx =
        xrStruct<XrGraphicsBindingOpenGLXlibKHR>(XR_TYPE_GRAPHICS_BINDING_OPENGL_XLIB_KHR);
    XrSessionCreateInfo info = xrStruct<XrSessionCreateInfo>(XR_TYPE_SESSION_CREATE_INFO);
    info.systemId = system;
    if (gl.egl_context) {
      egl.getProcAddress = eglGetProcAddress;
      egl.display = gl.egl_display;
      egl.config = gl.egl_config;
      egl.context = gl.egl_context;
      info.next = &egl;
    } else {
      glx.xDisplay = static_cast<Display*>(gl.x_display);
      glx.glxFBConfig = static_cast<GLXFBConfig>(gl.glx_fbconfig);
      glx.glxDrawable = gl.glx_drawable;
      glx.glxContext = static_cast<GLXContext>(gl.glx_context);
      int visual = 0;
      glXGetFBConfigAttrib(glx.xDisplay, glx.glxFBConfig, GLX_VISUAL_ID, &visual);
      glx.visualid = static_cast<uint32_t>(visual);
      info.next = &glx;
    }
    check(api.xrCreateSession(instance, &info, &session), "xrCreateSession");
    XrReferenceSpaceCreateInfo space =
        xrStruct<XrReferenceSpaceCreateInfo>(XR_TYPE_REFERENCE_SPACE_CREATE_INFO);
    space.poseInReferenceSpace.orientation.w = 1.0f;
    space.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
    check(api.xrCreateReferenceSpace(session, &space, &local), "xrCreateReferenceSpace (LOCAL)");
    space.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_VIEW;
    check(api.xrCreateReferenceSpace(session, &space, &view), "xrCreateReferenceSpace (VIEW)");
  }

  // The camera images are sRGB-encoded already: a linear 8-bit format shows them as drawn.
  int64_t swapchainFormat() const {
    uint32_t count = 0;
    check(api.xrEnumerateSwapchainFormats(session, 0, &count, nullptr),
          "xrEnumerateSwapchainFormats");
    std::vector<int64_t> formats(count);
    check(api.xrEnumerateSwapchainFormats(session, count, &count, formats.data()),
          "xrEnumerateSwapchainFormats");
    for (int64_t wanted : {int64_t{GL_RGBA8}, int64_t{GL_SRGB8_ALPHA8}}) {
      if (std::find(formats.begin(), formats.end(), wanted) != formats.end()) return wanted;
    }
    if (formats.empty()) fail("the runtime offers no swapchain format", XR_ERROR_RUNTIME_FAILURE);
    return formats.front();
  }

  void createSwapchains(Size wanted) {
    uint32_t count = 0;
    check(api.xrEnumerateViewConfigurationViews(
              instance, system, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0, &count, nullptr),
          "xrEnumerateViewConfigurationViews (stereo)");
    if (count != 2)
      fail("the headset has " + std::to_string(count) + " views, not 2: stereo views",
           XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED);
    std::vector<XrViewConfigurationView> views(
        count, xrStruct<XrViewConfigurationView>(XR_TYPE_VIEW_CONFIGURATION_VIEW));
    check(api.xrEnumerateViewConfigurationViews(instance, system,
                                                XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, count,
                                                &count, views.data()),
          "xrEnumerateViewConfigurationViews (stereo)");
    // The HMD stage's eye as drawn, within what the runtime allows.
    eye = {std::min<int>(wanted.width, static_cast<int>(views[0].maxImageRectWidth)),
           std::min<int>(wanted.height, static_cast<int>(views[0].maxImageRectHeight))};
    const int64_t format = swapchainFormat();
    for (size_t i = 0; i < 2; ++i) {
      XrSwapchainCreateInfo info = xrStruct<XrSwapchainCreateInfo>(XR_TYPE_SWAPCHAIN_CREATE_INFO);
      info.usageFlags =
          XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT;
      info.format = format;
      info.sampleCount = 1;
      info.width = static_cast<uint32_t>(eye.width);
      info.height = static_cast<uint32_t>(eye.height);
      info.faceCount = 1;
      info.arraySize = 1;
      info.mipCount = 1;
      check(api.xrCreateSwapchain(session, &info, &swapchains[i]), "xrCreateSwapchain");
      uint32_t n = 0;
      check(api.xrEnumerateSwapchainImages(swapchains[i], 0, &n, nullptr),
            "xrEnumerateSwapchainImages");
      images[i].assign(n, xrStruct<XrSwapchainImageOpenGLKHR>(XR_TYPE_SWAPCHAIN_IMAGE_OPENGL_KHR));
      check(api.xrEnumerateSwapchainImages(
                swapchains[i], n, &n,
                reinterpret_cast<XrSwapchainImageBaseHeader*>(images[i].data())),
            "xrEnumerateSwapchainImages");
    }
  }

  void waitUntilRunning(double ready_s) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(ready_s);
    while (!running) {
      pollEvents();
      if (running) return;
      if (std::chrono::steady_clock::now() > until)
        fail("the session was not made ready in " + std::to_string(static_cast<int>(ready_s)) +
                 " s (is the headset on and the runtime's compositor running?): xrPollEvent",
             XR_ERROR_SESSION_NOT_READY);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }

  double hostOf(XrTime time) const {
    timespec t{};
    check(api.xrConvertTimeToTimespecTimeKHR(instance, time, &t), "xrConvertTimeToTimespecTimeKHR");
    return secondsOf(t);
  }

  // Empty frames until the runtime's pacing settles (a runtime may predict a default period for
  // its first frames): the display period is the median interval of the last predicted display
  // times.
  void measurePeriod() {
    constexpr int kFrames = 12;
    std::vector<double> intervals;
    XrTime last = 0;
    for (int i = 0; i < kFrames; ++i) {
      XrFrameState frame = xrStruct<XrFrameState>(XR_TYPE_FRAME_STATE);
      XrFrameWaitInfo wait = xrStruct<XrFrameWaitInfo>(XR_TYPE_FRAME_WAIT_INFO);
      check(api.xrWaitFrame(session, &wait, &frame), "xrWaitFrame");
      XrFrameBeginInfo begin = xrStruct<XrFrameBeginInfo>(XR_TYPE_FRAME_BEGIN_INFO);
      check(api.xrBeginFrame(session, &begin), "xrBeginFrame");
      XrFrameEndInfo end = xrStruct<XrFrameEndInfo>(XR_TYPE_FRAME_END_INFO);
      end.displayTime = frame.predictedDisplayTime;
      end.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
      check(api.xrEndFrame(session, &end), "xrEndFrame");
      if (i >= kFrames / 2 && last != 0)
        intervals.push_back(1e-9 * static_cast<double>(frame.predictedDisplayTime - last));
      last = frame.predictedDisplayTime;
    }
    std::sort(intervals.begin(), intervals.end());
    period_s = intervals[intervals.size() / 2];
  }

  // A running session is asked to end and ended once the runtime says it is stopping (within
  // a second; a runtime gone is not waited for).
  void endSession() {
    if (XR_FAILED(api.xrRequestExitSession(session))) return;
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(1);
    while (std::chrono::steady_clock::now() < until) {
      XrEventDataBuffer event = xrStruct<XrEventDataBuffer>(XR_TYPE_EVENT_DATA_BUFFER);
      const XrResult r = api.xrPollEvent(instance, &event);
      if (XR_FAILED(r)) return;
      if (r == XR_SUCCESS && event.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED &&
          reinterpret_cast<const XrEventDataSessionStateChanged&>(event).state ==
              XR_SESSION_STATE_STOPPING) {
        api.xrEndSession(session);
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }

  ~State() {
    for (XrSwapchain s : swapchains) {
      if (s != XR_NULL_HANDLE) api.xrDestroySwapchain(s);
    }
    if (view != XR_NULL_HANDLE) api.xrDestroySpace(view);
    if (local != XR_NULL_HANDLE) api.xrDestroySpace(local);
    if (session != XR_NULL_HANDLE) {
      if (running) endSession();
      api.xrDestroySession(session);
    }
    if (instance != XR_NULL_HANDLE) api.xrDestroyInstance(instance);
    if (loader) dlclose(loader);
  }
};

OpenXrDisplay::OpenXrDisplay(GlContext& context, Size eye, double ready_s,
                             const std::string& loader)
    : s_(std::make_unique<State>()) {
  context.makeCurrent();
  const NativeGl gl = context.native();
  if (!gl.egl_context && !gl.glx_context)
    throw OpenXrError("OpenXR: the OpenGL context is neither EGL nor GLX on X11",
                      XR_ERROR_GRAPHICS_DEVICE_INVALID);
  s_->openLoader(loader);
  s_->createInstance(gl.egl_context != nullptr);
  s_->findHeadset();
  s_->createSession(gl);
  s_->createSwapchains(eye);
  s_->waitUntilRunning(ready_s);
  s_->measurePeriod();
}

OpenXrDisplay::~OpenXrDisplay() = default;

const std::string& OpenXrDisplay::runtime() const {
  return s_->runtime;
}
const std::string& OpenXrDisplay::system() const {
  return s_->system_name;
}
Size OpenXrDisplay::eyeSize() const {
  return s_->eye;
}
double OpenXrDisplay::periodS() const {
  return s_->period_s;
}

XrFrameTiming OpenXrDisplay::submit(unsigned int texture, Size size) {
  State& s = *s_;
  s.pollEvents();
  XrFrameTiming timing;
  XrFrameState frame = xrStruct<XrFrameState>(XR_TYPE_FRAME_STATE);
  XrFrameWaitInfo wait = xrStruct<XrFrameWaitInfo>(XR_TYPE_FRAME_WAIT_INFO);
  s.check(s.api.xrWaitFrame(s.session, &wait, &frame), "xrWaitFrame");
  XrFrameBeginInfo begin = xrStruct<XrFrameBeginInfo>(XR_TYPE_FRAME_BEGIN_INFO);
  s.check(s.api.xrBeginFrame(s.session, &begin), "xrBeginFrame");
  timing.period_s = 1e-9 * static_cast<double>(frame.predictedDisplayPeriod);
  timing.display_host_s = s.hostOf(frame.predictedDisplayTime);

  ProjectionLayer projection;
  const XrCompositionLayerBaseHeader* layers[] = {
      reinterpret_cast<const XrCompositionLayerBaseHeader*>(&projection.layer)};
  XrFrameEndInfo end = xrStruct<XrFrameEndInfo>(XR_TYPE_FRAME_END_INFO);
  end.displayTime = frame.predictedDisplayTime;
  end.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  if (frame.shouldRender) {
    XrViewLocateInfo locate = xrStruct<XrViewLocateInfo>(XR_TYPE_VIEW_LOCATE_INFO);
    locate.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
    locate.displayTime = frame.predictedDisplayTime;
    locate.space = s.local;
    XrViewState view_state = xrStruct<XrViewState>(XR_TYPE_VIEW_STATE);
    std::array<XrView, 2> views{xrStruct<XrView>(XR_TYPE_VIEW), xrStruct<XrView>(XR_TYPE_VIEW)};
    uint32_t count = 0;
    s.check(s.api.xrLocateViews(s.session, &locate, &view_state, 2, &count, views.data()),
            "xrLocateViews");
    std::array<unsigned int, 2> targets{};
    for (size_t i = 0; i < 2; ++i) {
      uint32_t index = 0;
      XrSwapchainImageAcquireInfo acquire =
          xrStruct<XrSwapchainImageAcquireInfo>(XR_TYPE_SWAPCHAIN_IMAGE_ACQUIRE_INFO);
      s.check(s.api.xrAcquireSwapchainImage(s.swapchains[i], &acquire, &index),
              "xrAcquireSwapchainImage");
      XrSwapchainImageWaitInfo wait_image =
          xrStruct<XrSwapchainImageWaitInfo>(XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO);
      wait_image.timeout = 1'000'000'000;  // 1 s: a runtime that never frees an image is lost
      s.check(s.api.xrWaitSwapchainImage(s.swapchains[i], &wait_image), "xrWaitSwapchainImage");
      targets[i] = s.images[i][index].image;
    }
    copyEyes(texture, size, targets[0], targets[1], s.eye);
    for (size_t i = 0; i < 2; ++i) {
      XrSwapchainImageReleaseInfo release =
          xrStruct<XrSwapchainImageReleaseInfo>(XR_TYPE_SWAPCHAIN_IMAGE_RELEASE_INFO);
      s.check(s.api.xrReleaseSwapchainImage(s.swapchains[i], &release), "xrReleaseSwapchainImage");
    }
    projection.fill(s.local, views, s.swapchains, s.eye);
    end.layerCount = 1;
    end.layers = layers;
    timing.rendered = true;
    XrSpaceLocation head = xrStruct<XrSpaceLocation>(XR_TYPE_SPACE_LOCATION);
    const XrSpaceLocationFlags tracked =
        XR_SPACE_LOCATION_POSITION_VALID_BIT | XR_SPACE_LOCATION_ORIENTATION_VALID_BIT;
    if (XR_SUCCEEDED(s.api.xrLocateSpace(s.view, s.local, frame.predictedDisplayTime, &head)) &&
        (head.locationFlags & tracked) == tracked) {
      const XrPosef& p = head.pose;
      timing.head = HeadPose{{p.position.x, p.position.y, p.position.z},
                             {p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w}};
    }
  }
  s.check(s.api.xrEndFrame(s.session, &end), "xrEndFrame");
  timing.submitted_host_s = secondsOf([] {
    timespec t{};
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t;
  }());
  // Handed over after the display time it was predicted for, a frame can only be shown at a
  // later refresh: the first one after the handover.
  if (timing.submitted_host_s > timing.display_host_s && timing.period_s > 0.0) {
    const double behind = timing.submitted_host_s - timing.display_host_s;
    timing.display_host_s += std::ceil(behind / timing.period_s) * timing.period_s;
  }
  return timing;
}

}  // namespace arbci::render

#include "arbci/ui/imgui_layer.h"

#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <filesystem>
#include <stdexcept>

#include "arbci/render/window_context.h"
#include "arbci/ui/widget_registry.h"

namespace arbci::ui {
namespace {
constexpr const char* kUiFont = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
}

ImGuiLayer::ImGuiLayer(render::GlContext& context, const std::string& ini_path)
    : context_(context), ini_path_(ini_path) {
  if (ImGui::GetCurrentContext() != nullptr) {
    throw std::logic_error("only one ImGuiLayer may exist at a time");
  }
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = ini_path_.empty() ? nullptr : ini_path_.c_str();
  if (std::filesystem::exists(kUiFont)) {
    io.Fonts->AddFontFromFileTTF(kUiFont, 15.0f);
  } else {
    io.Fonts->AddFontDefault();
  }
  ImGui::StyleColorsDark();
  // Opaque panels: one over another (the summary, a dialog) must not show the other's text.
  ImGui::GetStyle().Colors[ImGuiCol_WindowBg].w = 1.0f;
  ImGui::GetStyle().Colors[ImGuiCol_PopupBg].w = 1.0f;
  ImGui::GetStyle().WindowRounding = 3.0f;

  context_.makeCurrent();
  if (auto* window = dynamic_cast<render::WindowContext*>(&context_)) {
    ImGui_ImplGlfw_InitForOpenGL(window->window(), true);
    glfw_backend_ = true;
  }
  if (!ImGui_ImplOpenGL3_Init("#version 330 core")) {
    if (glfw_backend_) ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    throw render::GlError("Dear ImGui's OpenGL3 backend failed to initialise");
  }
}

ImGuiLayer::~ImGuiLayer() {
  context_.makeCurrent();
  ImGui_ImplOpenGL3_Shutdown();
  if (glfw_backend_) ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
}

void ImGuiLayer::beginFrame(float delta_seconds, const SyntheticInput* input) {
  ImGui_ImplOpenGL3_NewFrame();
  if (glfw_backend_) {
    ImGui_ImplGlfw_NewFrame();
  } else {
    const render::Size size = context_.framebufferSize();
    ImGuiIO& io = ImGui::GetIO();
    io.DisplaySize = ImVec2(static_cast<float>(size.width), static_cast<float>(size.height));
    io.DisplayFramebufferScale = ImVec2(1.0f, 1.0f);
    io.DeltaTime = delta_seconds > 0.0f ? delta_seconds : 1.0f / 60.0f;
  }
  ImGuiIO& io = ImGui::GetIO();
  if (synthetic_key_ > 0) io.KeysDown[synthetic_key_] = false;
  synthetic_key_ = 0;
  if (input) {
    // After the backend read the real devices: this frame's input is the script's.
    io.MousePos = ImVec2(input->x, input->y);
    io.MouseDown[0] = input->left_down;
    io.KeyCtrl = input->ctrl;
    if (input->key > 0 && input->key < static_cast<int>(IM_ARRAYSIZE(io.KeysDown))) {
      io.KeysDown[input->key] = true;
      synthetic_key_ = input->key;
    }
    if (!input->text.empty()) io.AddInputCharactersUTF8(input->text.c_str());
  }
  ImGui::NewFrame();
}

void ImGuiLayer::endFrame() {
  detail::endWidgetFrame();
  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

}  // namespace arbci::ui

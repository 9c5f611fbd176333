#include "arbci/render/gl_context.h"

#include "gl.h"

namespace arbci::render {
namespace {
std::string glString(GLenum name) {
  const auto* text = reinterpret_cast<const char*>(glGetString(name));
  return text ? text : "(unknown)";
}
}  // namespace

GlInfo GlContext::info() const {
  return {glString(GL_VENDOR), glString(GL_RENDERER), glString(GL_VERSION),
          glString(GL_SHADING_LANGUAGE_VERSION)};
}

}  // namespace arbci::render

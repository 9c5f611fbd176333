// Private: the OpenGL headers as the render module uses them (core functions from glvnd's
// libOpenGL, prototypes enabled).
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/gl.h>
#include <GL/glext.h>

// OpenGL declarations: the 3.3 core entry points straight from libGL (Mesa's libGL exports
// them all), so no loader is generated or vendored.
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/gl.h>
#include <GL/glext.h>

#pragma once

// OpenGL 3.3 core entry points, linked from the system's libGL (Mesa or a vendor's).
#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/glcorearb.h>

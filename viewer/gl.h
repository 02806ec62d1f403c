// gl.h — the one place the viewer includes OpenGL and GLFW, in the order they need.
//
// libepoxy is the GL loader (Debian package, no generated code): it resolves entry points lazily
// on first call, so there is no load step to forget. GLFW must not pull in its own GL header.
#pragma once
#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

// Debian's VTK 9.1 is built for GLX only: its OpenGL loader (GLEW) asks glXGetProcAddress
// for every function, and no X display exists in batch. Rendering goes to an OSMesa
// context instead (offscreen.cpp); these two definitions, exported from the executable
// that renders (CMake ENABLE_EXPORTS), hand GLEW OSMesa's functions. Remove this file when
// VTK is built with OSMesa or EGL. See reports/README.md.

#include <GL/osmesa.h>

extern "C" {
__attribute__((visibility("default"))) void* glXGetProcAddressARB(const unsigned char* name) {
  return reinterpret_cast<void*>(OSMesaGetProcAddress(reinterpret_cast<const char*>(name)));
}
__attribute__((visibility("default"))) void* glXGetProcAddress(const unsigned char* name) {
  return reinterpret_cast<void*>(OSMesaGetProcAddress(reinterpret_cast<const char*>(name)));
}
}

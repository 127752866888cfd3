#pragma once
// An off-screen canvas: an OSMesa OpenGL context around a VTK render window (the
// workaround of reports/README.md for the packaged VTK; the executable must also link
// glx_shim.cpp). Everything a report draws goes through it.

#include <memory>
#include <string>

class vtkRenderWindow;

namespace rocklab::reports {

class Canvas {
 public:
  Canvas(int width, int height);
  ~Canvas();
  Canvas(const Canvas&) = delete;
  Canvas& operator=(const Canvas&) = delete;
  vtkRenderWindow* window();
  // Renders and writes the window as a PNG.
  void savePng(const std::string& path);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rocklab::reports

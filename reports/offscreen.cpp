#include "reports/offscreen.hpp"

#include <GL/osmesa.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkWindowToImageFilter.h>

#include <stdexcept>
#include <vector>

namespace rocklab::reports {

struct Canvas::Impl {
  OSMesaContext context = nullptr;
  std::vector<unsigned char> buffer;
  vtkNew<vtkGenericOpenGLRenderWindow> window;
};

Canvas::Canvas(int width, int height) : impl_(std::make_unique<Impl>()) {
  const int attribs[] = {OSMESA_FORMAT,
                         OSMESA_RGBA,
                         OSMESA_DEPTH_BITS,
                         24,
                         OSMESA_PROFILE,
                         OSMESA_CORE_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION,
                         3,
                         OSMESA_CONTEXT_MINOR_VERSION,
                         2,
                         0};
  impl_->context = OSMesaCreateContextAttribs(attribs, nullptr);
  impl_->buffer.resize(static_cast<std::size_t>(width) * height * 4);
  if (!impl_->context ||
      !OSMesaMakeCurrent(impl_->context, impl_->buffer.data(), GL_UNSIGNED_BYTE, width, height)) {
    throw std::runtime_error("cannot create an off-screen OpenGL context (OSMesa)");
  }
  // GLEW logs a harmless "could not be initialized" line through VTK's logger on the first
  // render: keep it from users.
  vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  auto& w = impl_->window;
  w->SetSize(width, height);
  w->SetIsCurrent(true);
  w->SetReadyForRendering(true);
  w->SetOwnContext(false);
}

Canvas::~Canvas() {
  impl_->window->Finalize();
  if (impl_->context) OSMesaDestroyContext(impl_->context);
}

vtkRenderWindow* Canvas::window() {
  return impl_->window;
}

void Canvas::savePng(const std::string& path) {
  impl_->window->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(impl_->window);
  grab->ReadFrontBufferOff();
  grab->Update();
  vtkNew<vtkPNGWriter> png;
  png->SetFileName(path.c_str());
  png->SetInputConnection(grab->GetOutputPort());
  png->Write();
}

}  // namespace rocklab::reports

#pragma once
// Headless OpenGL contexts for MuJoCo's renderer: EGL surfaceless (Mesa) or OSMesa, opened at run time.
//
// MuJoCo 2.2.2 resolves its GL entry points once per process, at the first mjr_makeContext, through the first of
// eglGetProcAddress / OSMesaGetProcAddress / glXGetProcAddressARB visible in the global symbol scope. The library
// chosen first is therefore made RTLD_GLOBAL (and neither is linked). On Mesa both libraries share libglapi, so
// renderers of either backend then coexist in one process, in either order (tested); other drivers may not.
#include <memory>
#include <string>

namespace stvl::sensors {

enum class GlBackend { kAuto, kEgl, kOsmesa };

// "auto" | "egl" | "osmesa"; throws std::invalid_argument naming the value otherwise.
GlBackend parse_gl_backend(const std::string& name);
const char* to_string(GlBackend backend);

class GlContext {
 public:
  // kAuto honours STVL_GL=egl|osmesa, else tries EGL then OSMesa. Throws std::runtime_error naming every backend
  // tried and why it failed; std::invalid_argument for a bad STVL_GL value.
  static std::unique_ptr<GlContext> create(GlBackend backend);
  virtual ~GlContext() = default;
  virtual void make_current() = 0;
  // Leaves the calling thread with no context of this backend current (so that another thread may make one of
  // them current). Throws std::runtime_error when the backend refuses.
  virtual void release() = 0;
  // The address of a GL entry point (eglGetProcAddress / OSMesaGetProcAddress), null when unknown.
  virtual void* proc_address(const char* name) const = 0;
  virtual GlBackend backend() const = 0;
};

}  // namespace stvl::sensors

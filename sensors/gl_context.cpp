#include "sensors/gl_context.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/osmesa.h>
#include <dlfcn.h>

#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "common/enum_names.hpp"

namespace stvl::sensors {
namespace {

// Opened RTLD_LOCAL and promoted to RTLD_GLOBAL only once a context works, so that a failed EGL attempt does not
// leave eglGetProcAddress visible to MuJoCo when kAuto falls back to OSMesa.
void* open_library(const std::vector<const char*>& names, std::string& why, const char*& opened) {
  for (const char* name : names) {
    opened = name;
    if (void* handle = dlopen(name, RTLD_NOW | RTLD_LOCAL)) return handle;
    const char* error = dlerror();
    why += std::string(why.empty() ? "" : "; ") + (error ? error : name);
  }
  return nullptr;
}

void promote_to_global(const char* name) { dlopen(name, RTLD_NOW | RTLD_NOLOAD | RTLD_GLOBAL); }

template <typename T>
T symbol(void* library, const char* name) {
  return reinterpret_cast<T>(dlsym(library, name));
}

std::string hex(int value) {
  char text[16];
  std::snprintf(text, sizeof(text), "0x%x", value);
  return text;
}

class EglContext final : public GlContext {
 public:
  EglContext() {
    std::string why;
    const char* opened = nullptr;
    library_ = open_library({"libEGL.so.1", "libEGL.so"}, why, opened);
    if (!library_) throw std::runtime_error("cannot load libEGL (" + why + ")");
    get_proc_ = symbol<PFNEGLGETPROCADDRESSPROC>(library_, "eglGetProcAddress");
    auto get_proc = get_proc_;
    get_error_ = symbol<PFNEGLGETERRORPROC>(library_, "eglGetError");
    make_current_ = symbol<PFNEGLMAKECURRENTPROC>(library_, "eglMakeCurrent");
    auto initialize = symbol<PFNEGLINITIALIZEPROC>(library_, "eglInitialize");
    auto choose_config = symbol<PFNEGLCHOOSECONFIGPROC>(library_, "eglChooseConfig");
    auto bind_api = symbol<PFNEGLBINDAPIPROC>(library_, "eglBindAPI");
    auto create_context = symbol<PFNEGLCREATECONTEXTPROC>(library_, "eglCreateContext");
    destroy_context_ = symbol<PFNEGLDESTROYCONTEXTPROC>(library_, "eglDestroyContext");
    if (!get_proc || !get_error_ || !make_current_ || !initialize || !choose_config || !bind_api || !create_context ||
        !destroy_context_) {
      throw std::runtime_error("libEGL lacks core EGL 1.4 entry points");
    }
    auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(get_proc("eglGetPlatformDisplayEXT"));
    if (!get_platform_display) throw std::runtime_error("eglGetPlatformDisplayEXT is not available");
    display_ = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (display_ == EGL_NO_DISPLAY) {
      throw std::runtime_error("no EGL surfaceless display (EGL_PLATFORM_SURFACELESS_MESA), error " +
                               hex(get_error_()));
    }
    EGLint major = 0, minor = 0;
    if (!initialize(display_, &major, &minor)) {
      throw std::runtime_error("eglInitialize failed on the surfaceless display, error " + hex(get_error_()));
    }
    // MuJoCo renders into its own framebuffer object: any config with a depth buffer will do, or none at all.
    const EGLint attributes[] = {EGL_RED_SIZE,
                                 8,
                                 EGL_GREEN_SIZE,
                                 8,
                                 EGL_BLUE_SIZE,
                                 8,
                                 EGL_DEPTH_SIZE,
                                 24,
                                 EGL_SURFACE_TYPE,
                                 EGL_PBUFFER_BIT,
                                 EGL_RENDERABLE_TYPE,
                                 EGL_OPENGL_BIT,
                                 EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    if (!choose_config(display_, attributes, &config, 1, &count) || count < 1) config = nullptr;
    if (!bind_api(EGL_OPENGL_API)) throw std::runtime_error("eglBindAPI(EGL_OPENGL_API) failed");
    context_ = create_context(display_, config, EGL_NO_CONTEXT, nullptr);
    if (context_ == EGL_NO_CONTEXT) {
      throw std::runtime_error("eglCreateContext failed, error " + hex(get_error_()));
    }
    make_current();
    promote_to_global(opened);
  }
  ~EglContext() override {
    if (context_ != EGL_NO_CONTEXT) {
      make_current_(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      destroy_context_(display_, context_);
    }
    // The display and library stay: other renderers may share the (per-process) display.
  }
  void make_current() override {
    if (!make_current_(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
      throw std::runtime_error("eglMakeCurrent failed, error " + hex(get_error_()));
    }
  }
  void release() override {
    if (!make_current_(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT)) {
      throw std::runtime_error("eglMakeCurrent(EGL_NO_CONTEXT) failed, error " + hex(get_error_()));
    }
  }
  void* proc_address(const char* name) const override { return reinterpret_cast<void*>(get_proc_(name)); }
  GlBackend backend() const override { return GlBackend::kEgl; }

 private:
  void* library_ = nullptr;
  PFNEGLGETPROCADDRESSPROC get_proc_ = nullptr;
  PFNEGLGETERRORPROC get_error_ = nullptr;
  PFNEGLMAKECURRENTPROC make_current_ = nullptr;
  PFNEGLDESTROYCONTEXTPROC destroy_context_ = nullptr;
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
};

class OsmesaContext final : public GlContext {
 public:
  OsmesaContext() {
    std::string why;
    const char* opened = nullptr;
    library_ = open_library({"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"}, why, opened);
    if (!library_) throw std::runtime_error("cannot load libOSMesa (" + why + ")");
    auto create =
        symbol<OSMesaContext (*)(GLenum, GLint, GLint, GLint, OSMesaContext)>(library_, "OSMesaCreateContextExt");
    make_current_ = symbol<decltype(make_current_)>(library_, "OSMesaMakeCurrent");
    destroy_ = symbol<decltype(destroy_)>(library_, "OSMesaDestroyContext");
    get_proc_ = symbol<decltype(get_proc_)>(library_, "OSMesaGetProcAddress");
    if (!create || !make_current_ || !destroy_ || !get_proc_)
      throw std::runtime_error("libOSMesa lacks OSMesaCreateContextExt");
    context_ = create(OSMESA_RGBA, 24, 8, 8, nullptr);
    if (!context_) throw std::runtime_error("OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 8) failed");
    make_current();
    promote_to_global(opened);
  }
  ~OsmesaContext() override {
    if (context_) destroy_(context_);
  }
  void make_current() override {
    // MuJoCo draws into its own framebuffer object; the default buffer only has to exist.
    if (!make_current_(context_, buffer_, GL_UNSIGNED_BYTE, kSide, kSide)) {
      throw std::runtime_error("OSMesaMakeCurrent failed");
    }
  }
  void release() override {
    if (!make_current_(nullptr, nullptr, GL_UNSIGNED_BYTE, 0, 0))
      throw std::runtime_error("OSMesaMakeCurrent(NULL) failed");
  }
  void* proc_address(const char* name) const override { return reinterpret_cast<void*>(get_proc_(name)); }
  GlBackend backend() const override { return GlBackend::kOsmesa; }

 private:
  static constexpr int kSide = 4;
  void* library_ = nullptr;
  OSMESAproc (*get_proc_)(const char*) = nullptr;
  GLboolean (*make_current_)(OSMesaContext, void*, GLenum, GLsizei, GLsizei) = nullptr;
  void (*destroy_)(OSMesaContext) = nullptr;
  OSMesaContext context_ = nullptr;
  unsigned char buffer_[kSide * kSide * 4] = {};
};

std::unique_ptr<GlContext> make(GlBackend backend) {
  if (backend == GlBackend::kEgl) return std::make_unique<EglContext>();
  return std::make_unique<OsmesaContext>();
}

}  // namespace

namespace {
constexpr EnumName<GlBackend> kGlBackendNames[] = {
    {GlBackend::kAuto, "auto"}, {GlBackend::kEgl, "egl"}, {GlBackend::kOsmesa, "osmesa"}};
}  // namespace

GlBackend parse_gl_backend(const std::string& name) { return parse_enum(name, kGlBackendNames, "GL backend"); }
const char* to_string(GlBackend backend) { return enum_name(backend, kGlBackendNames); }

std::unique_ptr<GlContext> GlContext::create(GlBackend backend) {
  static std::mutex mutex;  // dlopen order decides MuJoCo's GL binding: keep creation serial
  std::lock_guard<std::mutex> lock(mutex);
  if (backend == GlBackend::kAuto) {
    if (const char* env = std::getenv("STVL_GL"); env && *env) {
      const GlBackend forced = parse_gl_backend(env);
      if (forced != GlBackend::kAuto) backend = forced;
    }
  }
  std::vector<GlBackend> candidates = backend == GlBackend::kAuto
                                          ? std::vector<GlBackend>{GlBackend::kEgl, GlBackend::kOsmesa}
                                          : std::vector<GlBackend>{backend};
  std::string failures;
  for (GlBackend candidate : candidates) {
    try {
      return make(candidate);
    } catch (const std::runtime_error& e) {
      failures += std::string(failures.empty() ? "" : "; ") + to_string(candidate) + ": " + e.what();
    }
  }
  throw std::runtime_error("no off-screen OpenGL context (tried " + failures + ")");
}

}  // namespace stvl::sensors

#include "client/viewer/gl_functions.h"

#include <string>

namespace meshstream::client {

Result<GlFunctions> load_gl_functions(GlProcLoader load) {
  GlFunctions gl;
#define MS_GL_LOAD(ret, name, params)                                                       \
  gl.name = reinterpret_cast<ret(APIENTRY*) params>(load("gl" #name));                      \
  if (gl.name == nullptr) {                                                                 \
    return make_error(ErrorCode::kUnsupported,                                              \
                      std::string("OpenGL context lacks gl") + #name + " (need 3.3 core)"); \
  }
  MS_GL_FUNCTIONS(MS_GL_LOAD)
#undef MS_GL_LOAD
  return gl;
}

}  // namespace meshstream::client

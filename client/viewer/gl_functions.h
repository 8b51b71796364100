// The OpenGL 3.3 core entry points the renderer uses, loaded at run time
// through whichever context is current: glfwGetProcAddress for the window,
// OSMesaGetProcAddress for off-screen snapshots. One table instead of a
// loader library because the two contexts live in different libraries (the
// glvnd libGL for GLX, Mesa's libOSMesa), and linking both for their gl*
// symbols would let one shadow the other; through the table the same
// renderer code drives either.
#pragma once

#include <GL/glcorearb.h>

#include "common/base/result.h"

namespace meshstream::client {

// X-macro: return type, name, parameter list.
#define MS_GL_FUNCTIONS(X)                                                                   \
  X(const GLubyte*, GetString, (GLenum name))                                                \
  X(GLenum, GetError, (void))                                                                \
  X(void, GetIntegerv, (GLenum pname, GLint * data))                                         \
  X(void, Viewport, (GLint x, GLint y, GLsizei width, GLsizei height))                       \
  X(void, ClearColor, (GLfloat r, GLfloat g, GLfloat b, GLfloat a))                          \
  X(void, Clear, (GLbitfield mask))                                                          \
  X(void, Enable, (GLenum cap))                                                              \
  X(void, Disable, (GLenum cap))                                                             \
  X(void, DepthFunc, (GLenum func))                                                          \
  X(void, Finish, (void))                                                                    \
  X(void, PixelStorei, (GLenum pname, GLint param))                                          \
  X(void, ReadPixels,                                                                        \
    (GLint x, GLint y, GLsizei w, GLsizei h, GLenum format, GLenum type, void* pixels))      \
  X(void, ReadBuffer, (GLenum src))                                                          \
  X(GLuint, CreateShader, (GLenum type))                                                     \
  X(void, ShaderSource,                                                                      \
    (GLuint shader, GLsizei count, const GLchar* const* string, const GLint* length))        \
  X(void, CompileShader, (GLuint shader))                                                    \
  X(void, GetShaderiv, (GLuint shader, GLenum pname, GLint * params))                        \
  X(void, GetShaderInfoLog, (GLuint shader, GLsizei size, GLsizei * length, GLchar * log))   \
  X(void, DeleteShader, (GLuint shader))                                                     \
  X(GLuint, CreateProgram, (void))                                                           \
  X(void, AttachShader, (GLuint program, GLuint shader))                                     \
  X(void, BindAttribLocation, (GLuint program, GLuint index, const GLchar* name))            \
  X(void, LinkProgram, (GLuint program))                                                     \
  X(void, GetProgramiv, (GLuint program, GLenum pname, GLint * params))                      \
  X(void, GetProgramInfoLog, (GLuint program, GLsizei size, GLsizei * length, GLchar * log)) \
  X(void, DeleteProgram, (GLuint program))                                                   \
  X(void, UseProgram, (GLuint program))                                                      \
  X(GLint, GetUniformLocation, (GLuint program, const GLchar* name))                         \
  X(void, UniformMatrix4fv,                                                                  \
    (GLint location, GLsizei count, GLboolean transpose, const GLfloat* value))              \
  X(void, Uniform1i, (GLint location, GLint v0))                                             \
  X(void, Uniform1f, (GLint location, GLfloat v0))                                           \
  X(void, Uniform2f, (GLint location, GLfloat v0, GLfloat v1))                               \
  X(void, Uniform3f, (GLint location, GLfloat v0, GLfloat v1, GLfloat v2))                   \
  X(void, GenVertexArrays, (GLsizei n, GLuint * arrays))                                     \
  X(void, BindVertexArray, (GLuint array))                                                   \
  X(void, DeleteVertexArrays, (GLsizei n, const GLuint* arrays))                             \
  X(void, GenBuffers, (GLsizei n, GLuint * buffers))                                         \
  X(void, BindBuffer, (GLenum target, GLuint buffer))                                        \
  X(void, BufferData, (GLenum target, GLsizeiptr size, const void* data, GLenum usage))      \
  X(void, DeleteBuffers, (GLsizei n, const GLuint* buffers))                                 \
  X(void, EnableVertexAttribArray, (GLuint index))                                           \
  X(void, VertexAttribPointer,                                                               \
    (GLuint index, GLint size, GLenum type, GLboolean normalized, GLsizei stride,            \
     const void* pointer))                                                                   \
  X(void, DrawElements, (GLenum mode, GLsizei count, GLenum type, const void* indices))      \
  X(void, GenTextures, (GLsizei n, GLuint * textures))                                       \
  X(void, BindTexture, (GLenum target, GLuint texture))                                      \
  X(void, DeleteTextures, (GLsizei n, const GLuint* textures))                               \
  X(void, ActiveTexture, (GLenum texture))                                                   \
  X(void, TexBuffer, (GLenum target, GLenum internalformat, GLuint buffer))                  \
  X(void, TexImage2D,                                                                        \
    (GLenum target, GLint level, GLint internalformat, GLsizei width, GLsizei height,        \
     GLint border, GLenum format, GLenum type, const void* pixels))                          \
  X(void, TexParameteri, (GLenum target, GLenum pname, GLint param))                         \
  X(void, GenerateMipmap, (GLenum target))                                                   \
  X(void, Uniform4f, (GLint location, GLfloat v0, GLfloat v1, GLfloat v2, GLfloat v3))       \
  X(void, GenFramebuffers, (GLsizei n, GLuint * framebuffers))                               \
  X(void, BindFramebuffer, (GLenum target, GLuint framebuffer))                              \
  X(void, DeleteFramebuffers, (GLsizei n, const GLuint* framebuffers))                       \
  X(GLenum, CheckFramebufferStatus, (GLenum target))                                         \
  X(void, GenRenderbuffers, (GLsizei n, GLuint * renderbuffers))                             \
  X(void, BindRenderbuffer, (GLenum target, GLuint renderbuffer))                            \
  X(void, DeleteRenderbuffers, (GLsizei n, const GLuint* renderbuffers))                     \
  X(void, RenderbufferStorage,                                                               \
    (GLenum target, GLenum internalformat, GLsizei width, GLsizei height))                   \
  X(void, RenderbufferStorageMultisample,                                                    \
    (GLenum target, GLsizei samples, GLenum internalformat, GLsizei width, GLsizei height))  \
  X(void, FramebufferRenderbuffer,                                                           \
    (GLenum target, GLenum attachment, GLenum renderbuffertarget, GLuint renderbuffer))      \
  X(void, BlitFramebuffer,                                                                   \
    (GLint sx0, GLint sy0, GLint sx1, GLint sy1, GLint dx0, GLint dy0, GLint dx1, GLint dy1, \
     GLbitfield mask, GLenum filter))

struct GlFunctions {
#define MS_GL_MEMBER(ret, name, params) ret(APIENTRY* name) params = nullptr;
  MS_GL_FUNCTIONS(MS_GL_MEMBER)
#undef MS_GL_MEMBER
};

using GlProcLoader = void* (*)(const char* name);

// Fills a table from `load` (called with "glClear" etc.) while a GL 3.3 core
// context is current. kUnsupported naming the first function the context
// does not provide. O(number of functions).
Result<GlFunctions> load_gl_functions(GlProcLoader load);

}  // namespace meshstream::client

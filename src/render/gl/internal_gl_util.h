#pragma once
// Small OpenGL helpers for the render/gl backend: error names, checks, shader programs.
// Everything here needs the renderer's context current on the calling thread.

#include <epoxy/gl.h>

#include <string>
#include <string_view>

namespace saccade::render::gl {

/// "GL_INVALID_ENUM", ... ("GL error 0x0500" style when unknown).
std::string GlErrorName(GLenum code);

/// Throws saccade::Error "<where>: <GL error names>" when glGetError reports errors. For set-up
/// code (uploads, framebuffers), not per frame.
void CheckGlError(std::string_view where);

/// Compiles and links a program from GLSL vertex and fragment sources. Throws saccade::Error
/// with the compiler's log, naming the program, on failure.
GLuint BuildProgram(std::string_view name, const std::string& vertex_source,
                    const std::string& fragment_source);

/// A uniform's location; -1 (the GL value for "ignored") when the linker removed it.
GLint Uniform(GLuint program, const char* name);

/// A renderbuffer of `format`, multisampled when samples > 0; left unbound.
GLuint MakeRenderbuffer(GLenum format, int width, int height, int samples);

}  // namespace saccade::render::gl

#pragma once
// A linked GLSL program and its uniforms by name. The lookup is checked: a
// name its sources do not declare (a misspelling, a uniform renamed in one
// place) throws, naming the program and the uniform, instead of setting
// nothing in silence as glGetUniformLocation's -1 would.

#include <map>
#include <set>
#include <string>

#include "sensors/render/gl.h"

namespace sandbox::render {

class GlProgram {
 public:
  GlProgram() = default;
  // Compiles and links in the current context; `name` says which program in
  // errors. Throws std::runtime_error with the compiler's log.
  GlProgram(std::string name, const std::string& vertex, const std::string& fragment);

  GLuint id() const { return id_; }
  const std::string& name() const { return name_; }
  void Use() const { glUseProgram(id_); }
  // The location of the uniform `name` ("shadow_clip[1]": an array's
  // element). -1 when the sources declare it but the compiler left it out
  // (unused in this variant): setting it does nothing. Throws
  // std::logic_error "GlProgram::Uniform(): the NAME program declares no uniform 'x'"
  // when no source declares it.
  GLint Uniform(const std::string& name);

 private:
  std::string name_;
  GLuint id_{0};  // deleted with the context
  std::set<std::string> declared_;
  std::map<std::string, GLint> locations_;
};

// The uniforms a GLSL source declares ("uniform TYPE a, b[4];" gives a and
// b), without comments.
std::set<std::string> DeclaredUniforms(const std::string& source);

}  // namespace sandbox::render

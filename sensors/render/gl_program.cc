#include "sensors/render/gl_program.h"

#include <cctype>
#include <regex>
#include <stdexcept>

namespace sandbox::render {
namespace {

GLuint Compile(GLenum type, const std::string& program, const std::string& source) {
  const GLuint shader = glCreateShader(type);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096];
    glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
    glDeleteShader(shader);
    throw std::runtime_error("GlProgram::GlProgram(): the " + program + " program's " +
                             (type == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                             " shader does not compile: " + log);
  }
  return shader;
}

// The source without // and /* */ comments.
std::string WithoutComments(const std::string& source) {
  static const std::regex comments(R"(//[^\n]*|/\*[\s\S]*?\*/)");
  return std::regex_replace(source, comments, " ");
}

}  // namespace

std::set<std::string> DeclaredUniforms(const std::string& source) {
  // "uniform", an optional precision, the type, then names (with array
  // sizes) up to the semicolon.
  static const std::regex declaration(
      R"(\buniform\s+(?:(?:lowp|mediump|highp)\s+)?\w+\s+([^;{]*);)");
  static const std::regex name(R"(([A-Za-z_]\w*)\s*(?:\[[^\]]*\])?)");
  std::set<std::string> names;
  const std::string text = WithoutComments(source);
  for (std::sregex_iterator d(text.begin(), text.end(), declaration), end; d != end; ++d) {
    const std::string list = (*d)[1];
    for (std::sregex_iterator n(list.begin(), list.end(), name); n != end; ++n) {
      names.insert((*n)[1]);
    }
  }
  return names;
}

GlProgram::GlProgram(std::string name, const std::string& vertex, const std::string& fragment)
    : name_(std::move(name)) {
  const GLuint v = Compile(GL_VERTEX_SHADER, name_, vertex);
  const GLuint f = Compile(GL_FRAGMENT_SHADER, name_, fragment);
  id_ = glCreateProgram();
  glAttachShader(id_, v);
  glAttachShader(id_, f);
  glLinkProgram(id_);
  glDeleteShader(v);
  glDeleteShader(f);
  GLint ok = 0;
  glGetProgramiv(id_, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096];
    glGetProgramInfoLog(id_, sizeof(log), nullptr, log);
    throw std::runtime_error("GlProgram::GlProgram(): the " + name_ +
                             " program does not link: " + log);
  }
  declared_ = DeclaredUniforms(vertex);
  declared_.merge(DeclaredUniforms(fragment));
}

GLint GlProgram::Uniform(const std::string& name) {
  const auto found = locations_.find(name);
  if (found != locations_.end()) return found->second;
  if (!declared_.count(name.substr(0, name.find('[')))) {
    throw std::logic_error("GlProgram::Uniform(): the " + name_ + " program declares no uniform '" +
                           name + "'");
  }
  return locations_[name] = glGetUniformLocation(id_, name.c_str());
}

}  // namespace sandbox::render

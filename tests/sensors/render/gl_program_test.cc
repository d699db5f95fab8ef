// The checked uniform lookup, in a real OSMesa context: a uniform the
// sources declare has its location (or -1 where the compiler left it out); a
// name they do not declare throws, naming the program and the uniform; a
// shader that does not compile names its program.

#include "sensors/render/gl_program.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "sensors/render/gl_context.h"

namespace sandbox::render {
namespace {

const char* kVertex = R"(#version 450 core
layout(location = 0) in vec3 position;
uniform mat4 view_proj;  // used
uniform float unused_scale, spare[4];  // declared, never read
void main() { gl_Position = view_proj * vec4(position, 1.0); }
)";
const char* kFragment = R"(#version 450 core
out vec4 color;
/* uniform vec3 commented_out; */
uniform vec3 tint;
void main() { color = vec4(tint, 1.0); }
)";

TEST(GlProgramTest, DeclaredUniformsAreFoundWithoutComments) {
  EXPECT_EQ(DeclaredUniforms(kVertex),
            (std::set<std::string>{"view_proj", "unused_scale", "spare"}));
  EXPECT_EQ(DeclaredUniforms(kFragment), (std::set<std::string>{"tint"}));
}

TEST(GlProgramTest, AnUndeclaredUniformThrowsNamingProgramAndUniform) {
  GlContext context;
  GlProgram program("test", kVertex, kFragment);
  EXPECT_GE(program.Uniform("view_proj"), 0);
  EXPECT_GE(program.Uniform("tint"), 0);
  EXPECT_EQ(program.Uniform("unused_scale"), -1);  // left out by the compiler
  EXPECT_EQ(program.Uniform("spare[2]"), -1);
  try {
    program.Uniform("tnit");
    FAIL() << "a misspelt uniform was looked up";
  } catch (const std::logic_error& e) {
    EXPECT_STREQ(e.what(), "GlProgram::Uniform(): the test program declares no uniform 'tnit'");
  }
  EXPECT_THROW(program.Uniform("commented_out"), std::logic_error);
}

TEST(GlProgramTest, AShaderThatDoesNotCompileNamesItsProgram) {
  GlContext context;
  try {
    GlProgram("broken", kVertex, "#version 450 core\nvoid main() { nonsense; }\n");
    FAIL() << "a broken shader compiled";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("the broken program's fragment shader does not compile"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace sandbox::render

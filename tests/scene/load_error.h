#pragma once
// What loading a level says: its LevelError's text, or "no error".

#include <filesystem>
#include <string>

#include "scene/level.h"

namespace sandbox::testing {

inline std::string LoadError(const std::filesystem::path& file) {
  try {
    scene::LoadLevel(file);
  } catch (const scene::LevelError& error) {
    return error.what();
  }
  return "no error";
}

}  // namespace sandbox::testing

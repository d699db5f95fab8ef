#include "app/bone_values.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/command_line.h"

namespace sandbox::app {

namespace fs = std::filesystem;
using scene::RobotModel;
using scene::RobotState;

void ApplyBones(const std::string& spec, const RobotModel& model, RobotState* state) {
  std::string text = spec;
  if (fs::is_regular_file(spec)) {
    std::ifstream in(spec);
    std::ostringstream contents;
    contents << in.rdbuf();
    text = contents.str();
  }
  for (char& c : text) {
    if (c == ';') c = '\n';
  }
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::string bone_word;
    if (!(words >> bone_word)) continue;
    int bone = model.FindBone(bone_word);
    if (bone < 0 && !bone_word.empty() && bone_word.size() <= 6 &&
        bone_word.find_first_not_of("0123456789") == std::string::npos) {
      bone = std::atoi(bone_word.c_str());
    }
    if (bone < 0 || bone >= static_cast<int>(model.bones.size())) {
      throw UsageError("--bones: robot '" + model.name + "' has no bone '" + bone_word + "' (" +
                       std::to_string(model.bones.size()) + " bones)");
    }
    const scene::Bone& b = model.bones[static_cast<std::size_t>(bone)];
    std::vector<double> values;
    std::string word;
    while (words >> word) values.push_back(ParseNumber(word, "--bones " + bone_word));
    if (static_cast<int>(values.size()) != b.num_values) {
      throw UsageError(
          "--bones: bone '" + b.name + "' takes " + std::to_string(b.num_values) +
          (b.rotation == scene::BoneRotation::kQuaternion ? " values (quaternion w x y z)"
           : b.rotation == scene::BoneRotation::kSlide    ? " value (metres)"
                                                          : " values (angles in degrees)") +
          ", got " + std::to_string(values.size()));
    }
    if (b.rotation == scene::BoneRotation::kAngles) {
      for (double& v : values) v *= scene::kDegToRad;
    }
    if (!state->SetBone(bone, values.data(), b.num_values)) {
      throw UsageError("--bones: bone '" + b.name + "' rejected: " + state->last_rejection());
    }
  }
}

}  // namespace sandbox::app

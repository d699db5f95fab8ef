// Generates the bundled robots as glTF (assets/robots/generated/): a skinned
// flexible flying wing, a 6-axis arm of link meshes, a quadrotor and a box.
// Each file's root node turns the robot frame (x forward, y left, z up) into
// glTF's Y-up axes, so that every bone below it has the robot's axes.
//
//   make_robots OUT_DIR

#include <array>
#include <cmath>
#include <filesystem>
#include <string>

#include "assets/generators/gltf_writer.h"
#include "assets/generators/robot_shapes.h"

namespace sandbox::assets {
namespace {

using Point = std::array<float, 3>;
constexpr double kPi = 3.14159265358979323846;

// The root rotation: -90 degrees about x takes Z-up robot axes to glTF Y-up.
constexpr std::array<float, 4> kZUpToYUp = {-0.70710678f, 0.f, 0.f, 0.70710678f};

GltfNode Node(const std::string& name, Point translation, int mesh = -1) {
  GltfNode node;
  node.name = name;
  node.translation = translation;
  node.mesh = mesh;
  return node;
}

// Inverse bind matrix of a joint at robot-frame position p under the root
// rotation: inverse(R * T(p)) = T(-p) * R^T, column-major.
std::array<float, 16> InverseBind(const Point& p) {
  return {1, 0, 0, 0, 0, 0, 1, 0, 0, -1, 0, 0, -p[0], -p[1], -p[2], 1};
}

// Bone weights along the span at |y| = s on one side (first bone index of
// that side `first`): root inside the centre section, element k beyond joint k,
// blended linearly within kBlendHalfWidth of each joint.
void SpanWeights(double s, int first, std::array<std::uint16_t, 4>* joints,
                 std::array<float, 4>* weights) {
  using namespace robots;
  *joints = {0, 0, 0, 0};
  *weights = {1.f, 0.f, 0.f, 0.f};
  for (int k = 1; k <= kElementsPerHalf; ++k) {
    const double joint = kCentreHalfWidth + (k - 1) * kElementLength;
    const double t = (s - (joint - kBlendHalfWidth)) / (2.0 * kBlendHalfWidth);
    if (t <= 0.0) break;
    const auto bone = static_cast<std::uint16_t>(first + k - 1);
    const auto parent = static_cast<std::uint16_t>(k == 1 ? 0 : first + k - 2);
    if (t >= 1.0) {
      *joints = {bone, 0, 0, 0};
      *weights = {1.f, 0.f, 0.f, 0.f};
    } else {
      *joints = {parent, bone, 0, 0};
      *weights = {float(1.0 - t), float(t), 0.f, 0.f};
    }
  }
}

void WriteFlyingWing(const std::filesystem::path& file) {
  using namespace robots;
  GltfScene scene;
  // Bones: 0 root, 1-10 right, 11-20 left, 21-23 elevators; the skin mesh is node 24.
  std::vector<Point> joint_positions;
  scene.nodes.push_back(Node("root", {0, 0, 0}));
  scene.nodes[0].rotation_xyzw = kZUpToYUp;
  joint_positions.push_back({0, 0, 0});
  for (const int side : {-1, 1}) {
    int parent = 0;
    for (int k = 1; k <= kElementsPerHalf; ++k) {
      const float offset = float(side * (k == 1 ? kCentreHalfWidth : kElementLength));
      const std::string name = (side < 0 ? "R" : "L") + std::to_string(k);
      const int index = int(scene.nodes.size());
      scene.nodes.push_back(Node(name, {0, offset, 0}));
      scene.nodes[std::size_t(parent)].children.push_back(index);
      const Point& p = joint_positions[std::size_t(parent)];
      joint_positions.push_back({p[0], p[1] + offset, p[2]});
      parent = index;
    }
  }
  for (int e = 0; e < 3; ++e) {
    const Point hinge = {float(kTrailingEdgeX), float(kElevatorY[e]), 0};
    scene.nodes[0].children.push_back(int(scene.nodes.size()));
    scene.nodes.push_back(Node("E" + std::to_string(e + 1), hinge));
    joint_positions.push_back(hinge);
  }
  for (std::size_t j = 0; j < joint_positions.size(); ++j) {
    scene.skin.joints.push_back(int(j));
    scene.skin.inverse_bind.push_back(InverseBind(joint_positions[j]));
  }

  // The skin: an airfoil-like section swept along the span, 20 points around,
  // a station every 25 mm (about 20k vertices), closed at both tips.
  GeneratedMesh wing("flying_wing", {0.85f, 0.86f, 0.9f, 1.0f});
  const int around = 20;
  const int stations = int(std::lround(2.0 * kHalfSpan / 0.025)) + 1;
  auto add_vertex = [&](Point p, double y) {
    std::array<std::uint16_t, 4> joints;
    std::array<float, 4> weights;
    SpanWeights(std::abs(y), y < 0 ? 1 : 1 + kElementsPerHalf, &joints, &weights);
    wing.positions.push_back(ToGltf(p));
    wing.joints.push_back(joints);
    wing.weights.push_back(weights);
    return std::uint32_t(wing.positions.size() - 1);
  };
  const double chord = kLeadingEdgeX - kTrailingEdgeX;
  for (int s = 0; s < stations; ++s) {
    const double y = -kHalfSpan + 2.0 * kHalfSpan * s / (stations - 1);
    for (int a = 0; a < around; ++a) {
      const double angle = 2.0 * kPi * a / around;
      const double x = kTrailingEdgeX + chord * 0.5 * (1.0 + std::cos(angle));
      const double z = 0.5 * kThickness * std::sin(angle);
      add_vertex({float(x), float(y), float(z)}, y);
    }
  }
  for (int s = 0; s + 1 < stations; ++s) {
    for (int a = 0; a < around; ++a) {
      const auto v0 = std::uint32_t(s * around + a),
                 v1 = std::uint32_t(s * around + (a + 1) % around);
      const auto w0 = v0 + around, w1 = v1 + around;
      wing.AddTriangle(v0, w1, v1);  // counter-clockwise seen from outside
      wing.AddTriangle(v0, w0, w1);
    }
  }
  for (const int end : {0, stations - 1}) {
    const double y = end == 0 ? -kHalfSpan : kHalfSpan;
    const std::uint32_t centre =
        add_vertex({float(0.5 * (kLeadingEdgeX + kTrailingEdgeX)), float(y), 0.f}, y);
    for (int a = 0; a < around; ++a) {
      const auto v0 = std::uint32_t(end * around + a),
                 v1 = std::uint32_t(end * around + (a + 1) % around);
      if (end == 0) {
        wing.AddTriangle(centre, v0, v1);
      } else {
        wing.AddTriangle(centre, v1, v0);
      }
    }
  }
  // Elevators: flat boxes behind their hinges, each fully on its bone.
  for (int e = 0; e < 3; ++e) {
    GeneratedMesh box;
    const float y = float(kElevatorY[e]), half = float(0.5 * kElevatorWidth - 0.01);
    box.AddBox({float(kTrailingEdgeX - kElevatorChord), y - half, -0.015f},
               {float(kTrailingEdgeX), y + half, 0.015f});
    const auto base = std::uint32_t(wing.positions.size());
    for (const Point& p : box.positions) {
      wing.positions.push_back(ToGltf(p));
      wing.joints.push_back({std::uint16_t(21 + e), 0, 0, 0});
      wing.weights.push_back({1.f, 0.f, 0.f, 0.f});
    }
    for (const std::uint32_t i : box.indices) wing.indices.push_back(base + i);
  }
  wing.ComputeNormals();
  scene.meshes.push_back(wing);
  GltfNode skin_node = Node("flying_wing_skin", {0, 0, 0}, 0);
  skin_node.skinned = true;
  scene.roots = {0, int(scene.nodes.size())};
  scene.nodes.push_back(skin_node);
  WriteGltfScene(file, scene);
}

// A chain of rigid links under a rotated root: node k has mesh k (if any) in
// its own Z-up frame.
void WriteArm(const std::filesystem::path& file) {
  using namespace robots;
  GltfScene scene;
  GeneratedMesh base("arm_base", {0.3f, 0.3f, 0.32f, 1.f});
  base.AddBox({-0.15f, -0.15f, 0.f}, {0.15f, 0.15f, 0.25f});
  scene.meshes.push_back(base);
  scene.nodes.push_back(Node("base", {0, 0, 0}, 0));
  scene.nodes[0].rotation_xyzw = kZUpToYUp;
  for (int k = 0; k < 6; ++k) {
    // Link k+1 reaches up to the next joint (or the tool point).
    const float length = float(k + 1 < 6 ? kArmOffsetsZ[k + 1] : kToolZ);
    const float half = float(0.09 - 0.01 * k);
    GeneratedMesh link("link" + std::to_string(k + 1), {0.95f, 0.55f - 0.05f * k, 0.1f, 1.f});
    link.AddBox({-half, -half, 0.f}, {half, half, length});
    scene.meshes.push_back(link);
    scene.nodes.back().children.push_back(int(scene.nodes.size()));
    scene.nodes.push_back(Node("link" + std::to_string(k + 1), {0, 0, float(kArmOffsetsZ[k])},
                               int(scene.meshes.size() - 1)));
  }
  scene.nodes.back().children.push_back(int(scene.nodes.size()));
  scene.nodes.push_back(Node("tool", {0, 0, float(kToolZ)}));
  scene.roots = {0};
  WriteGltfScene(file, scene);
}

void WriteQuadrotor(const std::filesystem::path& file) {
  using namespace robots;
  GltfScene scene;
  GeneratedMesh body("quadrotor_body", {0.2f, 0.2f, 0.22f, 1.f});
  body.AddBox({-0.08f, -0.06f, -0.03f}, {0.08f, 0.06f, 0.04f});
  const float r = float(kRotorOffset);
  body.AddBox({-r, -0.012f, 0.f}, {r, 0.012f, 0.02f});  // arms along x and y
  body.AddBox({-0.012f, -r, 0.f}, {0.012f, r, 0.02f});
  scene.meshes.push_back(body);
  scene.nodes.push_back(Node("body", {0, 0, 0}, 0));
  scene.nodes[0].rotation_xyzw = kZUpToYUp;
  GeneratedMesh blade("rotor", {0.1f, 0.1f, 0.1f, 1.f});
  blade.AddBox({-0.12f, -0.01f, 0.f}, {0.12f, 0.01f, 0.005f});
  scene.meshes.push_back(blade);
  const float sx[4] = {1, 0, -1, 0}, sy[4] = {0, 1, 0, -1};
  for (int k = 0; k < 4; ++k) {
    scene.nodes[0].children.push_back(int(scene.nodes.size()));
    scene.nodes.push_back(
        Node("rotor" + std::to_string(k + 1), {sx[k] * r, sy[k] * r, float(kRotorZ)}, 1));
  }
  scene.roots = {0};
  WriteGltfScene(file, scene);
}

void WriteBox(const std::filesystem::path& file) {
  GltfScene scene;
  GeneratedMesh box("box", {0.8f, 0.5f, 0.2f, 1.f});
  box.AddBox({-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f});
  scene.meshes.push_back(box);
  scene.nodes.push_back(Node("box", {0, 0, 0}, 0));
  scene.nodes[0].rotation_xyzw = kZUpToYUp;
  scene.roots = {0};
  WriteGltfScene(file, scene);
}

}  // namespace
}  // namespace sandbox::assets

int main(int argc, char** argv) {
  using namespace sandbox::assets;
  return GeneratorMain(argc, argv, [](const std::filesystem::path& out) {
    WriteFlyingWing(out / "flying_wing.gltf");
    WriteArm(out / "arm.gltf");
    WriteQuadrotor(out / "quadrotor.gltf");
    WriteBox(out / "box.gltf");
  });
}

// SandboxLoop's part in Foxglove (--foxglove, and an MCAP --record): the
// live server, and the views no LCM message carries: the level's and robots'
// geometry, the robots' link frames, the movable actors' frames and the
// camera frames. The views of LCM messages (poses, scans) are made from the
// messages themselves (bridge/foxglove_views.h).

#include <unordered_map>

#include "app/command_line.h"
#include "app/images.h"
#include "app/sandbox_loop.h"

namespace sandbox::app {

void SandboxLoop::StartFoxglove() {
  if (options_.foxglove_port < 0) return;
  web::ServerOptions server;
  server.address = options_.foxglove_address;
  server.port = options_.foxglove_port;
  try {
    foxglove_ = std::make_unique<web::FoxgloveServer>(server);
  } catch (const std::exception& e) {
    throw CommandError(e.what());
  }
  foxglove_feed_ = std::make_unique<FoxgloveFeed>(*foxglove_);
}

bool SandboxLoop::WantsFoxgloveViews() const {
  return link_.RecordsViews() || (foxglove_feed_ && foxglove_feed_->HasClients());
}

void SandboxLoop::EmitFoxgloveView(const std::string& topic, bridge::MakeView make,
                                   std::int64_t utime, std::size_t bytes) {
  link_.RecordView(make, utime, bytes);
  if (foxglove_feed_) foxglove_feed_->PublishView(topic, std::move(make), utime);
}

void SandboxLoop::EmitFoxgloveTick(std::int64_t utime) {
  if (!foxglove_scene_sent_) {
    // Once: recorded at the first tick, latched for every client of the server.
    foxglove_scene_sent_ = true;
    const bridge::MakeView scene = [meshes = foxglove_scene_, utime] {
      return bridge::SceneUpdate("scene", *meshes, utime);
    };
    std::size_t bytes = 0;
    for (const bridge::SceneMesh& mesh : *foxglove_scene_) {
      bytes += 12 * mesh.vertices.size() + 4 * mesh.indices.size();
    }
    link_.RecordView(scene, utime, bytes);
    if (foxglove_feed_) {
      foxglove_feed_->Latch("scene", "foxglove.SceneUpdate", bridge::SceneUpdateSchema(), scene,
                            utime);
    }
  }
  if (!WantsFoxgloveViews()) return;
  for (const RobotRun& robot : robots_) {
    if (robot.foxglove_links.empty()) continue;
    // The poses copied here; their JSON is made where it is written.
    auto links = std::make_shared<std::vector<bridge::NamedPose>>();
    links->reserve(robot.foxglove_links.size());
    for (const auto& [frame, node] : robot.foxglove_links) {
      links->push_back({frame, scene::RigidPart(robot.state->node_poses_B()[std::size_t(node)])});
    }
    const std::string topic = robot.foxglove_frame + "/links";
    EmitFoxgloveView(
        topic,
        [topic, parent = robot.foxglove_frame, links, utime] {
          return bridge::FrameTransforms(topic, parent, *links, utime);
        },
        utime, links->size() * sizeof(bridge::NamedPose));
  }
  auto actors = std::make_shared<std::vector<bridge::NamedPose>>();
  for (std::size_t a = 0; a < level_.actors.size(); ++a) {
    if (level_.actors[a].movable) {
      actors->push_back({"actor/" + level_.actors[a].name, world_.actor_pose(int(a))});
    }
  }
  if (!actors->empty()) {
    EmitFoxgloveView(
        "actors/tf",
        [actors, utime] { return bridge::FrameTransforms("actors/tf", "world", *actors, utime); },
        utime, actors->size() * sizeof(bridge::NamedPose));
  }
}

std::vector<bridge::SceneMesh> SandboxLoop::FoxgloveScene() const {
  std::vector<bridge::SceneMesh> meshes;
  const auto colour = [&](int material, bridge::SceneMesh* mesh) {
    if (material < 0 || std::size_t(material) >= level_.materials.size()) return;
    const Eigen::Vector4f& rgba = level_.materials[std::size_t(material)].base_color;
    for (int k = 0; k < 4; ++k) mesh->rgba[k] = rgba[k];
  };
  // The actors: static ones in "world" at their pose, movable ones in their own frame.
  for (const scene::Actor& actor : level_.actors) {
    for (std::size_t m = 0; m < actor.meshes.size(); ++m) {
      const scene::Mesh& source = actor.meshes[m];
      if (source.indices.empty()) continue;
      bridge::SceneMesh mesh;
      mesh.id = "actor/" + actor.name + "/" + std::to_string(m);
      mesh.frame_id = actor.movable ? "actor/" + actor.name : "world";
      if (!actor.movable) mesh.X_FE = actor.X_WA;
      mesh.vertices = source.positions_A;
      mesh.indices = source.indices;
      colour(source.material, &mesh);
      meshes.push_back(std::move(mesh));
    }
  }
  // The robots: each triangle on the link frame that carries most of its
  // weight, in that link's frame at the bind pose (rigid links exactly; a
  // skinned character's skin follows its bones piecewise).
  for (std::size_t r = 0; r < robots_.size(); ++r) {
    const scene::RobotModel& model = level_.robots[r];
    std::map<int, std::string> frame_of_node;
    for (const auto& [frame, node] : robots_[r].foxglove_links) frame_of_node[node] = frame;
    std::map<int, int> joint_of_node;
    for (std::size_t j = 0; j < model.joints.size(); ++j) {
      joint_of_node.emplace(model.joints[j].node, int(j));
    }
    for (std::size_t m = 0; m < model.meshes.size(); ++m) {
      const scene::SkinnedMesh& source = model.meshes[m];
      const std::vector<int> nodes = scene::DominantNodePerTriangle(model, source);
      std::map<int, bridge::SceneMesh> by_node;
      std::map<int, std::unordered_map<std::uint32_t, std::uint32_t>> vertex_in_node;
      for (std::size_t t = 0; t < nodes.size(); ++t) {
        const auto joint = joint_of_node.find(nodes[t]);
        const auto frame = frame_of_node.find(nodes[t]);
        if (joint == joint_of_node.end() || frame == frame_of_node.end()) continue;
        bridge::SceneMesh& mesh = by_node[nodes[t]];
        if (mesh.id.empty()) {
          mesh.id = "robot/" + model.name + "/" + std::to_string(m) + "/" + frame->second;
          mesh.frame_id = frame->second;
          colour(source.bind.material, &mesh);
        }
        const Eigen::Affine3d& offset = model.joints[std::size_t(joint->second)].offset;
        std::unordered_map<std::uint32_t, std::uint32_t>& vertex_in = vertex_in_node[nodes[t]];
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t v = source.bind.indices[3 * t + std::size_t(k)];
          const auto [at, added] = vertex_in.emplace(v, std::uint32_t(mesh.vertices.size()));
          if (added) {
            mesh.vertices.push_back(
                (offset * source.bind.positions_A[v].cast<double>()).cast<float>());
          }
          mesh.indices.push_back(at->second);
        }
      }
      for (auto& [node, mesh] : by_node) meshes.push_back(std::move(mesh));
    }
  }
  return meshes;
}

void SandboxLoop::EmitFoxgloveCamera(const std::string& camera, std::int64_t utime,
                                     const render::CameraView& view, const render::Frame& frame,
                                     const std::filesystem::path& color_file) {
  if (frame.rgb.empty()) return;
  const std::string topic = "camera/" + camera, optical = topic;
  // The image as written (its JPEG or PNG), else encoded (a video only).
  std::string format;
  std::string bytes = CompressedColor(frame, color_file, true, &format);
  const render::Lens lens = FrameIntrinsics(view);
  bridge::Intrinsics intrinsics;
  intrinsics.width = frame.width, intrinsics.height = frame.height;
  intrinsics.fx = lens.fx, intrinsics.fy = lens.fy, intrinsics.cx = lens.cx,
  intrinsics.cy = lens.cy;
  if (view.lens && view.lens->model == render::Lens::Model::kFisheye) {
    intrinsics.model = "kannala_brandt", intrinsics.D = {lens.k1, lens.k2, lens.k3, lens.k4};
  } else if (view.lens) {
    intrinsics.model = "plumb_bob", intrinsics.D = {lens.k1, lens.k2, lens.p1, lens.p2, lens.k3};
  }
  const Eigen::Isometry3d X_WO = view.X_WC * bridge::OpticalInCamera();
  EmitFoxgloveView(
      topic + "/tf",
      [topic, optical, X_WO, utime] {
        return bridge::FrameTransforms(topic + "/tf", "world", {{optical, X_WO}}, utime);
      },
      utime, sizeof(bridge::NamedPose));
  EmitFoxgloveView(
      topic + "/calibration",
      [topic, optical, intrinsics, utime] {
        return bridge::CameraCalibration(topic + "/calibration", optical, intrinsics, utime);
      },
      utime, sizeof(intrinsics));
  auto image = std::make_shared<const std::string>(std::move(bytes));
  EmitFoxgloveView(
      topic + "/image",
      [topic, optical, format, image, utime] {
        return bridge::CompressedImage(topic + "/image", optical, format, *image, utime);
      },
      utime, image->size());
}

}  // namespace sandbox::app

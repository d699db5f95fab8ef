#include "web/stream_state.h"

#include <nlohmann/json.hpp>

#include <cmath>

namespace sandbox::web {
namespace {

nlohmann::json BodyJson(const StreamState::Body& body) {
  const Eigen::Quaterniond q = body.q_W.normalized();
  return {{"name", body.name},
          {"p", {body.p_W.x(), body.p_W.y(), body.p_W.z()}},
          {"q", {q.w(), q.x(), q.y(), q.z()}}};
}

}  // namespace

std::string EncodeState(const StreamState& state) {
  nlohmann::json robots = nlohmann::json::array(), actors = nlohmann::json::array();
  for (const StreamState::Robot& robot : state.robots) {
    nlohmann::json r = BodyJson(robot);
    r["has_pose"] = robot.has_pose;
    r["received"] = robot.received;
    r["rejected"] = robot.rejected;
    r["stale"] = robot.stale;
    r["bones"] = robot.bone_values;
    // To 1e-5 (10 um, 10 urad): a short number each.
    nlohmann::json joints = nlohmann::json::array();
    for (const double value : robot.joints) joints.push_back(std::round(value * 1e5) / 1e5);
    r["joints"] = std::move(joints);
    robots.push_back(std::move(r));
  }
  for (const StreamState::Body& actor : state.actors) actors.push_back(BodyJson(actor));
  nlohmann::json message = {{"type", "state"},
                                  {"tick", state.tick},
                                  {"t", state.time_s},
                                  {"tick_ms", state.tick_ms},
                                  {"late_ms", state.late_ms},
                                  {"robots", std::move(robots)},
                                  {"actors", std::move(actors)}};
  if (state.has_player) message["player"] = {{"playing", state.playing}, {"speed", state.speed}};
  return message.dump();
}

namespace {

template <typename T>
void Append(const std::vector<T>& values, std::string* out) {
  out->append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

}  // namespace

std::string EncodeSamples(const StreamState& state) {
  if (!state.has_samples) return {};
  nlohmann::json sets = nlohmann::json::array();
  for (const StreamState::Samples& set : state.samples) {
    sets.push_back({{"robot", set.robot},
                    {"sensor", set.sensor},
                    {"type", set.type},
                    {"count", set.hit.size()}});
  }
  std::string header = nlohmann::json({{"tick", state.samples_tick},
                                       {"origin",
                                        {state.samples_origin.x(), state.samples_origin.y(),
                                         state.samples_origin.z()}},
                                       {"sets", std::move(sets)}})
                           .dump();
  header.append((4 - header.size() % 4) % 4, ' ');
  std::string out = "SMPL";
  const std::uint32_t length = std::uint32_t(header.size());
  out.append(reinterpret_cast<const char*>(&length), 4);  // little-endian (x86, ARM)
  out += header;
  for (const StreamState::Samples& set : state.samples) {
    Append(set.xyz, &out);
    Append(set.surface, &out);
    Append(set.hit, &out);
    out.append((4 - out.size() % 4) % 4, '\0');
  }
  return out;
}

}  // namespace sandbox::web

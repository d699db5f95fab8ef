#include "web/stream_state.h"

#include <nlohmann/json.hpp>

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
    r["rejected"] = robot.rejected;
    r["stale"] = robot.stale;
    robots.push_back(std::move(r));
  }
  for (const StreamState::Body& actor : state.actors) actors.push_back(BodyJson(actor));
  const nlohmann::json message = {{"type", "state"},
                                  {"tick", state.tick},
                                  {"t", state.time_s},
                                  {"tick_ms", state.tick_ms},
                                  {"late_ms", state.late_ms},
                                  {"robots", std::move(robots)},
                                  {"actors", std::move(actors)}};
  return message.dump();
}

}  // namespace sandbox::web

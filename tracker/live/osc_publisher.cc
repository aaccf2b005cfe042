#include "tracker/live/osc_publisher.h"

#include <lo/lo.h>
#include <netdb.h>
#include <sys/socket.h>

#include <cmath>
#include <limits>
#include <utility>

#include "common/error.h"

namespace irbench {

OscTarget ParseOscTarget(const std::string& text, const std::string& flag) {
  const size_t colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0) throw InputError("", flag, "expected HOST:PORT, got '" + text + "'");
  OscTarget target;
  target.host = text.substr(0, colon);
  const std::string port = text.substr(colon + 1);
  if (port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos ||
      std::stoi(port) < 1 || std::stoi(port) > 65535) {
    throw InputError("", flag, "port must be 1..65535, got '" + port + "'");
  }
  target.port = std::stoi(port);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  const int error = getaddrinfo(target.host.c_str(), port.c_str(), &hints, &found);
  if (error != 0) throw InputError("", flag, "unknown host '" + target.host + "': " + gai_strerror(error));
  freeaddrinfo(found);
  return target;
}

struct OscPublisher::Address {
  lo_address address = nullptr;
};

OscPublisher::OscPublisher(const OscTarget& target) : address_(std::make_unique<Address>()) {
  address_->address = lo_address_new(target.host.c_str(), std::to_string(target.port).c_str());
  if (address_->address == nullptr) throw RuntimeError("cannot make an OSC address for " + target.host);
}

OscPublisher::~OscPublisher() { lo_address_free(address_->address); }

namespace {

double Number(const nlohmann::json& j) { return j.is_number() ? j.get<double>() : std::numeric_limits<double>::quiet_NaN(); }

}  // namespace

bool OscPublisher::Publish(const nlohmann::json& line, int dropped) {
  lo_bundle bundle = lo_bundle_new(LO_TT_IMMEDIATE);
  const auto add = [&](const char* path, lo_message message) { lo_bundle_add_message(bundle, path, message); };
  lo_message frame = lo_message_new();
  lo_message_add_int32(frame, line["frame"].get<int>());
  lo_message_add_double(frame, line["t"].get<double>());
  lo_message_add_string(frame, line["state"].get<std::string>().c_str());
  lo_message_add_int32(frame, dropped);
  add("/irbench/frame", frame);
  for (const auto& [name, p] : line["joints3d"].items()) {
    if (!p.is_array()) continue;
    lo_message joint = lo_message_new();
    lo_message_add_string(joint, name.c_str());
    for (int k = 0; k < 3; ++k) lo_message_add_double(joint, p[k].get<double>());
    add("/irbench/joint", joint);
  }
  if (line["pointing"].is_object()) {
    for (const auto& [side, ray] : line["pointing"].items()) {
      if (!ray.is_object()) continue;
      lo_message m = lo_message_new();
      lo_message_add_string(m, side.c_str());
      for (const char* key : {"origin", "dir"}) {
        for (int k = 0; k < 3; ++k) lo_message_add_double(m, ray[key][k].get<double>());
      }
      lo_message_add_string(m, ray["screen"].is_string() ? ray["screen"].get<std::string>().c_str() : "");
      const nlohmann::json& hit = ray["screen_hit"];
      lo_message_add_double(m, hit.is_array() ? Number(hit[0]) : std::numeric_limits<double>::quiet_NaN());
      lo_message_add_double(m, hit.is_array() ? Number(hit[1]) : std::numeric_limits<double>::quiet_NaN());
      lo_message_add_string(m, ray["target"].is_string() ? ray["target"].get<std::string>().c_str() : "");
      add("/irbench/pointing", m);
    }
  }
  if (line["rest"].is_object()) {
    for (const auto& [side, at_rest] : line["rest"].items()) {
      lo_message m = lo_message_new();
      lo_message_add_string(m, side.c_str());
      lo_message_add_int32(m, at_rest.get<bool>() ? 1 : 0);
      add("/irbench/rest", m);
    }
  }
  if (line["height_m"].is_number()) {
    lo_message m = lo_message_new();
    lo_message_add_double(m, line["height_m"].get<double>());
    add("/irbench/height", m);
  }
  // Postures and gestures (docs/recognition.md): the pair as "A0+A2"; the
  // gesture's label, score and start frame.
  const nlohmann::json& posture = line["posture"];
  if (posture.is_object() && posture["pair"].is_array() && posture["pair"].size() == 2) {
    lo_message m = lo_message_new();
    lo_message_add_string(m, (posture["pair"][0].get<std::string>() + "+" + posture["pair"][1].get<std::string>()).c_str());
    add("/irbench/posture", m);
  }
  const nlohmann::json& gesture = line["gesture"];
  if (gesture.is_object() && gesture["label"].is_string()) {
    lo_message m = lo_message_new();
    lo_message_add_string(m, gesture["label"].get<std::string>().c_str());
    lo_message_add_double(m, gesture.value("score", 0.0));
    lo_message_add_int32(m, gesture.value("start_frame", 0));
    add("/irbench/gesture", m);
  }
  const int sent = lo_send_bundle(address_->address, bundle);
  lo_bundle_free_recursive(bundle);
  return sent >= 0;
}

bool OscPublisher::PublishMotion(int frame, const std::string& right, const std::string& left) {
  lo_message m = lo_message_new();
  lo_message_add_int32(m, frame);
  lo_message_add_string(m, right.c_str());
  lo_message_add_string(m, left.c_str());
  const int sent = lo_send_message(address_->address, "/irbench/motion", m);
  lo_message_free(m);
  return sent >= 0;
}

}  // namespace irbench

#pragma once
// `irbench live`'s output: each tracked frame-set as one OSC bundle over UDP
// (liblo), under the address space of docs/live.md.

#include <memory>
#include <nlohmann/json.hpp>
#include <string>

namespace irbench {

// "HOST:PORT" split and checked: InputError naming `flag` for a port outside
// 1..65535 or a host that does not resolve.
struct OscTarget {
  std::string host;
  int port = 0;
};
OscTarget ParseOscTarget(const std::string& text, const std::string& flag);

class OscPublisher {
 public:
  explicit OscPublisher(const OscTarget& target);
  ~OscPublisher();
  OscPublisher(const OscPublisher&) = delete;
  OscPublisher& operator=(const OscPublisher&) = delete;

  // Sends track.jsonl's line `track_line` (architecture.md, "Tracker output")
  // as one bundle; `dropped`: frame-sets dropped so far. False when the send
  // failed (the receiver is not there: UDP does not care).
  bool Publish(const nlohmann::json& track_line, int dropped);
  // The motion labels of frame `frame` (thesis 7.1), which come the
  // labeller's latency after the frame's bundle: /irbench/motion
  // frame right left.
  bool PublishMotion(int frame, const std::string& right, const std::string& left);

 private:
  struct Address;
  std::unique_ptr<Address> address_;
};

}  // namespace irbench

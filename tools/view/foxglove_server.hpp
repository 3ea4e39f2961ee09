#pragma once
// The view's channels served live over the Foxglove WebSocket protocol
// (subprotocol foxglove.websocket.v1, JSON message encoding): Foxglove,
// Lichtblick and @foxglove/ws-protocol clients connect to ws://HOST:PORT,
// are told the channels with their schemas, subscribe, and receive each
// message as it is published. The server runs on a thread of its own
// (websocketpp on standalone asio); publish() only hands the message over.
// A client that does not keep up loses messages (counted), not the others.

#include <cstdint>
#include <memory>
#include <string>

#include "view/robot_view.hpp"

namespace cdcr::view {

class FoxgloveServer final : public ViewSink {
 public:
  // Listens on every interface at `port` (0: a free port, see port());
  // throws std::runtime_error (one line) when it cannot.
  FoxgloveServer(std::uint16_t port, const std::string& name);
  ~FoxgloveServer() override;
  FoxgloveServer(const FoxgloveServer&) = delete;
  FoxgloveServer& operator=(const FoxgloveServer&) = delete;

  void publish(Topic topic, std::uint64_t time_ns, const std::string& json) override;
  std::uint16_t port() const;
  // Messages not sent to a client because its queue was full.
  long dropped() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cdcr::view

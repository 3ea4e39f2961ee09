#include "view/foxglove_server.hpp"

#include <atomic>
#include <map>
#include <stdexcept>
#include <thread>

#define ASIO_STANDALONE
#include <nlohmann/json.hpp>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

namespace cdcr::view {

namespace {

using Server = websocketpp::server<websocketpp::config::asio>;
using nlohmann::json;

constexpr const char* kSubprotocol = "foxglove.websocket.v1";
constexpr std::uint8_t kMessageDataOpcode = 0x01;
// A client with this much unsent loses the messages until it catches up.
constexpr std::size_t kClientQueueBytes = 8u << 20;

int channel_id(Topic topic) { return static_cast<int>(topic) + 1; }

}  // namespace

struct FoxgloveServer::Impl {
  Server server;
  std::thread thread;
  std::uint16_t port = 0;
  std::atomic<long> dropped{0};
  // Per connection: subscription id by channel id. On the server's thread only.
  std::map<websocketpp::connection_hdl, std::map<int, std::uint32_t>, std::owner_less<websocketpp::connection_hdl>>
      clients;
  std::string name;

  void on_open(websocketpp::connection_hdl hdl) {
    clients[hdl];
    websocketpp::lib::error_code ec;
    server.send(hdl,
                json{{"op", "serverInfo"},
                     {"name", name},
                     {"capabilities", json::array()},
                     {"supportedEncodings", json::array()},
                     {"metadata", json::object()}}
                    .dump(),
                websocketpp::frame::opcode::text, ec);
    json channels = json::array();
    for (int t = 0; t < kTopicCount; ++t) {
      const ChannelDescription& c = view_channels()[t];
      channels.push_back({{"id", channel_id(Topic(t))},
                          {"topic", c.topic},
                          {"encoding", "json"},
                          {"schemaName", c.schema_name},
                          {"schema", c.schema},
                          {"schemaEncoding", "jsonschema"}});
    }
    server.send(hdl, json{{"op", "advertise"}, {"channels", channels}}.dump(), websocketpp::frame::opcode::text, ec);
  }

  void on_message(websocketpp::connection_hdl hdl, Server::message_ptr message) {
    const auto client = clients.find(hdl);
    if (client == clients.end() || message->get_opcode() != websocketpp::frame::opcode::text) return;
    // A request the server does not understand is ignored, as the protocol
    // allows; it never stops the server.
    const json request = json::parse(message->get_payload(), nullptr, false);
    if (!request.is_object() || !request.contains("op") || !request["op"].is_string()) return;
    const std::string op = request["op"];
    if (op == "subscribe" && request.contains("subscriptions") && request["subscriptions"].is_array()) {
      for (const json& s : request["subscriptions"]) {
        if (!s.is_object() || !s.contains("id") || !s.contains("channelId")) continue;
        if (!s["id"].is_number_unsigned() || !s["channelId"].is_number_integer()) continue;
        const int channel = s["channelId"];
        if (channel < 1 || channel > kTopicCount) continue;
        client->second[channel] = s["id"].get<std::uint32_t>();
      }
    } else if (op == "unsubscribe" && request.contains("subscriptionIds") && request["subscriptionIds"].is_array()) {
      for (const json& id : request["subscriptionIds"]) {
        if (!id.is_number_unsigned()) continue;
        for (auto it = client->second.begin(); it != client->second.end();) {
          it = it->second == id.get<std::uint32_t>() ? client->second.erase(it) : std::next(it);
        }
      }
    }
  }

  void send(int channel, std::uint64_t time_ns, const std::string& payload) {
    for (auto& [hdl, subscriptions] : clients) {
      const auto subscription = subscriptions.find(channel);
      if (subscription == subscriptions.end()) continue;
      websocketpp::lib::error_code ec;
      Server::connection_ptr connection = server.get_con_from_hdl(hdl, ec);
      if (ec || connection->get_buffered_amount() > kClientQueueBytes) {
        ++dropped;
        continue;
      }
      std::string data(1 + 4 + 8, '\0');
      data[0] = static_cast<char>(kMessageDataOpcode);
      for (int i = 0; i < 4; ++i) data[1 + i] = static_cast<char>((subscription->second >> (8 * i)) & 0xFFu);
      for (int i = 0; i < 8; ++i) data[5 + i] = static_cast<char>((time_ns >> (8 * i)) & 0xFFu);
      data += payload;
      connection->send(data, websocketpp::frame::opcode::binary);
    }
  }
};

FoxgloveServer::FoxgloveServer(std::uint16_t port, const std::string& name) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.name = name;
  s.server.clear_access_channels(websocketpp::log::alevel::all);
  s.server.clear_error_channels(websocketpp::log::elevel::all);
  websocketpp::lib::error_code ec;
  s.server.init_asio(ec);
  if (ec) throw std::runtime_error("the view's server: " + ec.message());
  s.server.set_reuse_addr(true);
  s.server.set_validate_handler([&s](websocketpp::connection_hdl hdl) {
    Server::connection_ptr connection = s.server.get_con_from_hdl(hdl);
    for (const std::string& protocol : connection->get_requested_subprotocols()) {
      if (protocol == kSubprotocol) {
        connection->select_subprotocol(protocol);
        return true;
      }
    }
    return false;  // a client that does not speak the protocol is refused at the handshake
  });
  s.server.set_open_handler([&s](websocketpp::connection_hdl hdl) { s.on_open(hdl); });
  s.server.set_close_handler([&s](websocketpp::connection_hdl hdl) { s.clients.erase(hdl); });
  s.server.set_fail_handler([&s](websocketpp::connection_hdl hdl) { s.clients.erase(hdl); });
  s.server.set_message_handler(
      [&s](websocketpp::connection_hdl hdl, Server::message_ptr message) { s.on_message(hdl, message); });
  s.server.listen(asio::ip::tcp::endpoint(asio::ip::tcp::v4(), port), ec);
  if (ec) throw std::runtime_error("the view cannot listen on port " + std::to_string(port) + ": " + ec.message());
  s.port = s.server.get_local_endpoint(ec).port();
  s.server.start_accept(ec);
  if (ec) throw std::runtime_error("the view's server: " + ec.message());
  s.thread = std::thread([&s] { s.server.run(); });
}

FoxgloveServer::~FoxgloveServer() {
  Impl& s = *impl_;
  asio::post(s.server.get_io_service(), [&s] {
    websocketpp::lib::error_code ec;
    s.server.stop_listening(ec);
    for (auto& [hdl, subscriptions] : s.clients) s.server.close(hdl, websocketpp::close::status::going_away, "", ec);
  });
  // The clients are told; then the loop stops, whatever they answer.
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  s.server.stop();
  if (s.thread.joinable()) s.thread.join();
}

void FoxgloveServer::publish(Topic topic, std::uint64_t time_ns, const std::string& json) {
  Impl& s = *impl_;
  asio::post(s.server.get_io_service(), [&s, channel = channel_id(topic), time_ns, json] { s.send(channel, time_ns, json); });
}

std::uint16_t FoxgloveServer::port() const { return impl_->port; }

long FoxgloveServer::dropped() const { return impl_->dropped; }

}  // namespace cdcr::view

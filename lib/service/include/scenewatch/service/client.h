#pragma once
/// A blocking client of scenewatchd for the CLI and tests. This is the one service header that
/// exposes the protocol's generated types: users link scenewatch::proto as well.
#include <cstdint>
#include <deque>
#include <string>
#include <string_view>
#include <vector>

#include "scenewatch.pb.h"
#include "scenewatch/core/event.h"
#include "scenewatch/core/frame.h"
#include "scenewatch/core/image.h"
#include "scenewatch/core/result.h"
#include "scenewatch/service/frame_parser.h"
#include "scenewatch/service/server_config.h"

namespace scenewatch::service {

/// One connection to the daemon. Transport failures are Errors (code kUnavailable or kIoError,
/// message naming host:port); a request the server refused is an OK Result holding a Response
/// whose status says why (see status_of()). NOT thread safe; movable.
class Client {
 public:
  /// Connects within timeout_s. The error names host:port and suggests starting scenewatchd.
  static Result<Client> connect(const std::string& host, std::uint16_t port, double timeout_s = 5.0,
                                std::size_t max_message_bytes = ServerConfig{}.max_message_bytes);

  Client(Client&& other) noexcept;
  Client& operator=(Client&& other) noexcept;
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;
  ~Client();

  /// The access token call() puts in requests that carry none (see access_token.h).
  void set_token(std::string token) { token_ = std::move(token); }
  /// The token set with set_token() (send() leaves requests as they are: put it in yourself).
  const std::string& token() const { return token_; }

  /// Sends a request (its id is set to the next free one) and waits for the response with that
  /// id; events and localization notices pushed meanwhile are kept for next_event() and
  /// next_pushed(). timeout_s <= 0: wait forever.
  Result<proto::Response> call(proto::Request request, double timeout_s = 0);
  /// call() in two halves, for a client that keeps several requests in flight: start() sends the
  /// request (id and token set as call() sets them) and returns its id; wait_for() waits for the
  /// response with that id. Wait in the order of start(): the daemon answers in that order.
  Result<std::uint64_t> start(proto::Request request);
  Result<proto::Response> wait_for(std::uint64_t id, double timeout_s = 0);

  /// The next pushed event (after a Subscribe call); localization notices on the way are
  /// dropped. timeout_s <= 0: wait forever.
  Result<proto::Event> next_event(double timeout_s = 0);
  /// The next pushed message (after a Subscribe call): a Response with id 0 and either an `event`
  /// or a `localization` (a camera whose localization state changed). timeout_s <= 0: wait forever.
  Result<proto::Response> next_pushed(double timeout_s = 0);

  /// Sends a request as is (its id untouched), without waiting.
  Status send(const proto::Request& request);
  /// Receives the next message of any kind. timeout_s <= 0: wait forever.
  Result<proto::Response> receive(double timeout_s = 0);
  /// Writes raw bytes to the socket (tests of broken framing).
  Status send_raw(std::string_view bytes);

  /// Closes the connection (also done by the destructor).
  void close();
  /// False after close() or once the server closed the connection.
  bool is_open() const { return fd_ >= 0; }
  /// "host:port" as given to connect().
  const std::string& endpoint() const { return endpoint_; }

 private:
  Client(int fd, std::string endpoint, std::size_t max_message_bytes);
  Result<std::string> read_payload(double timeout_s);

  int fd_ = -1;
  std::string endpoint_;
  FrameParser parser_;
  std::uint64_t next_id_ = 1;
  std::string token_;
  std::deque<proto::Response> pushed_;  ///< id 0, with an event or a localization notice
};

/// OK when the response's status is OK, else an Error with its code and message.
Status status_of(const proto::Response& response);

/// Printable name of a status code ("INVALID_ARGUMENT").
std::string to_string(proto::Status::Code code);

/// Builds the IngestFrame message of a frame: cloud (xyz, and rgb when it has colour), pose,
/// intrinsics, stamp and source.
proto::IngestFrame make_ingest_frame(const Frame& frame);
/// Puts a depth image (millimetres) and its colour image (none: grey points) into `msg` in place
/// of a cloud: the daemon back-projects them through msg's intrinsics, which must be set and of
/// the same size. 5 bytes a pixel on the wire where a cloud takes 15.
void set_rgbd_images(const DepthImage& depth, const ColorImage* color, proto::IngestFrame* msg);
/// The wire form of an event (for printing library events the way the daemon's are printed).
proto::Event make_event_message(const Event& event);
/// Decodes a float32 map of a SurpriseMapReply, checking it holds `expected` values.
Result<std::vector<float>> decode_float_map(const std::string& bytes, std::size_t expected, const std::string& field);

}  // namespace scenewatch::service

#include "scenewatch/service/client.h"

#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fcntl.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <optional>
#include <utility>

#include "proto_convert.h"

namespace scenewatch::service {
namespace {

using Clock = std::chrono::steady_clock;

Error unavailable(std::string message) { return {ErrorCode::kUnavailable, std::move(message)}; }

std::string hint() {
  return " (is scenewatchd running there? Start it with: scenewatchd --config config/scenewatchd.yaml; "
         "or pass --host/--port)";
}

/// Milliseconds left until `deadline` for poll(); -1 when there is none.
int poll_timeout_ms(const std::optional<Clock::time_point>& deadline) {
  if (!deadline) return -1;
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(*deadline - Clock::now()).count();
  return static_cast<int>(std::max<long long>(0, left));
}

std::optional<Clock::time_point> deadline_after(double timeout_s) {
  if (!(timeout_s > 0)) return std::nullopt;
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
}

/// What the daemon pushes after Subscribe: id 0 with an event or a localization notice.
bool is_pushed(const proto::Response& r) { return r.id() == 0 && (r.has_event() || r.has_localization()); }

/// Connects one resolved address with a timeout; returns the fd or -1 with errno set.
int connect_one(const addrinfo& ai, double timeout_s) {
  const int fd = ::socket(ai.ai_family, ai.ai_socktype | SOCK_CLOEXEC, ai.ai_protocol);
  if (fd < 0) return -1;
  const int flags = ::fcntl(fd, F_GETFL, 0);
  ::fcntl(fd, F_SETFL, flags | O_NONBLOCK);
  int rc = ::connect(fd, ai.ai_addr, ai.ai_addrlen);
  if (rc != 0 && errno == EINPROGRESS) {
    pollfd p{fd, POLLOUT, 0};
    rc = ::poll(&p, 1, timeout_s > 0 ? static_cast<int>(timeout_s * 1000) : -1);
    if (rc == 0) {
      errno = ETIMEDOUT;
      rc = -1;
    } else if (rc > 0) {
      int err = 0;
      socklen_t len = sizeof err;
      ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len);
      if (err != 0) {
        errno = err;
        rc = -1;
      } else {
        rc = 0;
      }
    }
  }
  if (rc != 0) {
    const int saved = errno;
    ::close(fd);
    errno = saved;
    return -1;
  }
  ::fcntl(fd, F_SETFL, flags);
  const int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  return fd;
}

}  // namespace

Result<Client> Client::connect(const std::string& host, std::uint16_t port, double timeout_s,
                               std::size_t max_message_bytes) {
  const std::string endpoint =
      (host.find(':') != std::string::npos ? "[" + host + "]" : host) + ":" + std::to_string(port);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (const int rc = ::getaddrinfo(host.c_str(), service.c_str(), &hints, &found); rc != 0) {
    return unavailable("cannot connect to " + endpoint + ": cannot resolve '" + host + "': " + ::gai_strerror(rc));
  }
  int fd = -1;
  int last_errno = 0;
  for (addrinfo* ai = found; ai != nullptr && fd < 0; ai = ai->ai_next) {
    fd = connect_one(*ai, timeout_s);
    if (fd < 0) last_errno = errno;
  }
  ::freeaddrinfo(found);
  if (fd < 0) {
    return unavailable("cannot connect to " + endpoint + ": " + std::strerror(last_errno) + hint());
  }
  return Client(fd, endpoint, max_message_bytes);
}

Client::Client(int fd, std::string endpoint, std::size_t max_message_bytes)
    : fd_(fd), endpoint_(std::move(endpoint)), parser_(max_message_bytes) {}

Client::Client(Client&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      endpoint_(std::move(other.endpoint_)),
      parser_(std::move(other.parser_)),
      next_id_(other.next_id_),
      token_(std::move(other.token_)),
      pushed_(std::move(other.pushed_)) {}

Client& Client::operator=(Client&& other) noexcept {
  if (this != &other) {
    close();
    fd_ = std::exchange(other.fd_, -1);
    endpoint_ = std::move(other.endpoint_);
    parser_ = std::move(other.parser_);
    next_id_ = other.next_id_;
    token_ = std::move(other.token_);
    pushed_ = std::move(other.pushed_);
  }
  return *this;
}

Client::~Client() { close(); }

void Client::close() {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
}

Status Client::send_raw(std::string_view bytes) {
  if (fd_ < 0) return unavailable("not connected to " + endpoint_);
  while (!bytes.empty()) {
    const ssize_t n = ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      return unavailable("lost connection to " + endpoint_ + " while sending: " + std::strerror(errno));
    }
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
  return {};
}

Status Client::send(const proto::Request& request) {
  // Serialized once, straight behind room for the frame header (a frame of megabytes is not
  // copied again).
  std::string frame(kFrameHeaderBytes, '\0');
  if (!request.AppendToString(&frame)) return invalid_argument("cannot serialize the request");
  const std::size_t n = frame.size() - kFrameHeaderBytes;
  if (n == 0) {
    // An empty message serializes to nothing, but a frame must not be empty: spell the id out.
    return invalid_argument("cannot send an empty request (no id and no call)");
  }
  if (n > kMaxEncodableFrameBytes) return invalid_argument("request too large for one frame");
  put_frame_header(static_cast<std::uint32_t>(n), frame.data());
  return send_raw(frame);
}

Result<std::string> Client::read_payload(double timeout_s) {
  const auto deadline = deadline_after(timeout_s);
  for (;;) {
    if (auto payload = parser_.next()) return std::move(*payload);
    if (fd_ < 0) return unavailable("not connected to " + endpoint_);
    pollfd p{fd_, POLLIN, 0};
    const int rc = ::poll(&p, 1, poll_timeout_ms(deadline));
    if (rc < 0) {
      if (errno == EINTR) return unavailable("interrupted while waiting for " + endpoint_);
      return Error{ErrorCode::kIoError, std::string("poll failed: ") + std::strerror(errno)};
    }
    if (rc == 0) return unavailable("no answer from " + endpoint_ + " within " + std::to_string(timeout_s) + " s");
    char buffer[64 * 1024];
    const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
    if (n < 0) {
      if (errno == EINTR) return unavailable("interrupted while waiting for " + endpoint_);
      return unavailable("lost connection to " + endpoint_ + ": " + std::strerror(errno));
    }
    if (n == 0) {
      close();
      return unavailable("connection closed by " + endpoint_);
    }
    if (Status s = parser_.feed(std::string_view(buffer, static_cast<std::size_t>(n))); !s) {
      close();
      return Error{ErrorCode::kIoError, "bad data from " + endpoint_ + ": " + s.error().message};
    }
  }
}

Result<proto::Response> Client::receive(double timeout_s) {
  auto payload = read_payload(timeout_s);
  if (!payload) return payload.error();
  proto::Response response;
  if (!response.ParseFromString(*payload)) {
    return Error{ErrorCode::kIoError, "bad data from " + endpoint_ + ": not a scenewatch.proto.Response"};
  }
  return response;
}

Result<proto::Response> Client::call(proto::Request request, double timeout_s) {
  auto id = start(std::move(request));
  if (!id) return id.error();
  return wait_for(*id, timeout_s);
}

Result<std::uint64_t> Client::start(proto::Request request) {
  request.set_id(next_id_++);
  if (request.token().empty() && !token_.empty()) request.set_token(token_);
  if (Status s = send(request); !s) return s.error();
  return request.id();
}

Result<proto::Response> Client::wait_for(std::uint64_t id, double timeout_s) {
  const auto deadline = deadline_after(timeout_s);
  for (;;) {
    double left = 0;
    if (deadline) {
      left = std::chrono::duration<double>(*deadline - Clock::now()).count();
      if (left <= 0) return unavailable("no answer from " + endpoint_ + " within " + std::to_string(timeout_s) + " s");
    }
    auto response = receive(left);
    if (!response) return response.error();
    if (response->id() == id) return response;
    if (is_pushed(*response)) {
      pushed_.push_back(std::move(*response));
      continue;
    }
    if (response->id() == 0 && response->status().code() != proto::Status::OK) {
      return Error{convert::from_proto(response->status().code()),
                   "server " + endpoint_ + ": " + response->status().message()};
    }
    // A response to an earlier request sent with send(): not ours, skip it.
  }
}

Result<proto::Event> Client::next_event(double timeout_s) {
  const auto deadline = deadline_after(timeout_s);
  for (;;) {
    double left = 0;
    if (deadline) {
      left = std::chrono::duration<double>(*deadline - Clock::now()).count();
      if (left <= 0) return unavailable("no event from " + endpoint_ + " within " + std::to_string(timeout_s) + " s");
    }
    auto pushed = next_pushed(deadline ? left : 0);
    if (!pushed) {
      if (deadline && Clock::now() >= *deadline)
        return unavailable("no event from " + endpoint_ + " within " + std::to_string(timeout_s) + " s");
      return pushed.error();
    }
    if (pushed->has_event()) return std::move(*pushed->mutable_event());
  }
}

Result<proto::Response> Client::next_pushed(double timeout_s) {
  const auto deadline = deadline_after(timeout_s);
  for (;;) {
    if (!pushed_.empty()) {
      proto::Response pushed = std::move(pushed_.front());
      pushed_.pop_front();
      return pushed;
    }
    double left = 0;
    if (deadline) {
      left = std::chrono::duration<double>(*deadline - Clock::now()).count();
      if (left <= 0) return unavailable("nothing pushed by " + endpoint_ + " within " + std::to_string(timeout_s) + " s");
    }
    auto response = receive(left);
    if (!response) return response.error();
    if (is_pushed(*response)) return response;
    if (response->id() == 0 && response->status().code() != proto::Status::OK) {
      return Error{convert::from_proto(response->status().code()),
                   "server " + endpoint_ + ": " + response->status().message()};
    }
  }
}

Status status_of(const proto::Response& response) {
  if (response.status().code() == proto::Status::OK) return {};
  return Error{convert::from_proto(response.status().code()), response.status().message()};
}

std::string to_string(proto::Status::Code code) { return proto::Status::Code_Name(code); }

proto::IngestFrame make_ingest_frame(const Frame& frame) {
  proto::IngestFrame msg;
  if (frame.cloud) convert::encode_cloud(*frame.cloud, frame.has_color, msg.mutable_cloud());
  if (frame.T_world_camera) convert::to_proto(*frame.T_world_camera, msg.mutable_pose());
  if (frame.intrinsics) convert::to_proto(*frame.intrinsics, msg.mutable_intrinsics());
  msg.set_stamp_s(frame.stamp_s);
  msg.set_source(frame.source);
  msg.set_camera(frame.camera);
  msg.set_localization(convert::to_proto(frame.localization));
  return msg;
}

void set_rgbd_images(const DepthImage& depth, const ColorImage* color, proto::IngestFrame* msg) {
  msg->clear_cloud();
  convert::encode_rgbd(depth, color, msg->mutable_rgbd());
}

proto::Event make_event_message(const Event& event) {
  proto::Event msg;
  convert::to_proto(event, &msg);
  return msg;
}

Result<std::vector<float>> decode_float_map(const std::string& bytes, std::size_t expected, const std::string& field) {
  auto values = convert::decode_floats(bytes, field);
  if (!values) return values.error();
  if (values->size() != expected)
    return invalid_argument(field + ": " + std::to_string(values->size()) + " values, expected " + std::to_string(expected));
  return values;
}

}  // namespace scenewatch::service

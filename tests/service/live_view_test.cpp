// The live view in the browser: the HTTP request parser on byte splits and bad input, the real
// scenewatchd's HTTP port against raw sockets (bad requests neither stop it nor its TCP API), both
// servers refusing a bad address or a taken port, and headless Chromium on the page after a
// simulated cup was put on the table: the event and the object with its class are in the page's
// DOM, the object's box is drawn in the 3D view of the screenshot, and so are the views the last
// NextBestView suggested, as camera frusta; after the cup's first frame, the change pending is in
// the state as GetPendingChanges lists it, and in the page's list and 3D view.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <filesystem>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
#include <memory>
#include <mutex>
#include <thread>
#include <string>

#include <nlohmann/json.hpp>

#include "daemon_harness.h"
#include "scenewatch.pb.h"
#include "scenewatch/service/http_request.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/service/http_server.h"
#include "scenewatch/service/live_view.h"
#include "scenewatch/service/server.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"

namespace scenewatch::test {
namespace {
namespace fs = std::filesystem;
using service::HttpRequestParser;

// ---- the parser

TEST(HttpRequestParser, ParsesAHeadFedInAnySplit) {
  const std::string head =
      "GET /api/events?since=7&x HTTP/1.1\r\nHost: 127.0.0.1:8080\r\nAccept:  text/event-stream \r\n\r\n";
  for (std::size_t split = 0; split <= head.size(); ++split) {
    SCOPED_TRACE(split);
    HttpRequestParser parser;
    if (split > 0) {
      EXPECT_EQ(parser.feed(head.substr(0, split)),
                split == head.size() ? HttpRequestParser::State::kComplete : HttpRequestParser::State::kIncomplete);
    }
    ASSERT_EQ(parser.feed(head.substr(split)), HttpRequestParser::State::kComplete);
    const auto& r = parser.request();
    EXPECT_EQ(r.method, "GET");
    EXPECT_EQ(r.path, "/api/events");
    EXPECT_EQ(r.query_value("since"), "7");
    EXPECT_TRUE(r.has_query("x"));
    EXPECT_FALSE(r.has_query("y"));
    EXPECT_EQ(r.header("accept"), "text/event-stream");
    EXPECT_EQ(r.header("HOST"), "127.0.0.1:8080");
  }
  HttpRequestParser bare;  // "\n" line ends
  EXPECT_EQ(bare.feed("GET / HTTP/1.0\nHost: x\n\n"), HttpRequestParser::State::kComplete);
  EXPECT_EQ(bare.request().path, "/");
}

TEST(HttpRequestParser, RefusesGarbageAndOversizedHeads) {
  struct Case {
    std::string bytes;
    int status;
  };
  for (const Case& c : {Case{"garbage\r\n\r\n", 400}, Case{"GET /\r\n\r\n", 400}, Case{"GET  / HTTP/1.1\r\n\r\n", 400},
                        Case{"GET http://x/ HTTP/1.1\r\n\r\n", 400}, Case{"GET / FTP/1.0\r\n\r\n", 400},
                        Case{"GET / HTTP/2.0\r\n\r\n", 505}, Case{"GET / HTTP/1.1\r\nno colon\r\n\r\n", 400},
                        Case{"G(T / HTTP/1.1\r\n\r\n", 400}, Case{std::string("GET /\x01 HTTP/1.1\r\n\r\n"), 400}}) {
    SCOPED_TRACE(c.bytes);
    HttpRequestParser parser;
    ASSERT_EQ(parser.feed(c.bytes), HttpRequestParser::State::kError);
    EXPECT_EQ(parser.error_status(), c.status) << parser.error();
    EXPECT_EQ(parser.feed("GET / HTTP/1.1\r\n\r\n"), HttpRequestParser::State::kError) << "stays failed";
  }
  HttpRequestParser parser(1024);
  EXPECT_EQ(parser.feed("GET / HTTP/1.1\r\nX: " + std::string(1000, 'a')), HttpRequestParser::State::kIncomplete);
  EXPECT_EQ(parser.feed(std::string(100, 'a')), HttpRequestParser::State::kError);
  EXPECT_EQ(parser.error_status(), 413);
}

// ---- the daemon's HTTP port

/// Sends raw bytes to 127.0.0.1:port and reads until the server closes (or 20 s pass). With
/// `hang_up`, the client closes its sending side after the bytes.
std::string raw_exchange(std::uint16_t port, const std::string& bytes, bool hang_up = false) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return "socket failed";
  timeval timeout{20, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string out;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0) {
    std::size_t sent = 0;
    while (sent < bytes.size()) {
      const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) break;  // the server may answer and close before it read everything
      sent += static_cast<std::size_t>(n);
    }
    if (hang_up) ::shutdown(fd, SHUT_WR);
    char buffer[65536];
    for (ssize_t n; (n = ::recv(fd, buffer, sizeof buffer, 0)) > 0;) out.append(buffer, static_cast<std::size_t>(n));
  } else {
    out = "connect failed";
  }
  ::close(fd);
  return out;
}

std::string get(std::uint16_t port, const std::string& target) {
  return raw_exchange(port, "GET " + target + " HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n");
}

int status_of(const std::string& response) {
  if (response.rfind("HTTP/1.1 ", 0) != 0 || response.size() < 12) return -1;
  return std::stoi(response.substr(9, 3));
}

std::string body_of(const std::string& response) {
  const std::size_t at = response.find("\r\n\r\n");
  return at == std::string::npos ? std::string() : response.substr(at + 4);
}

class LiveViewTest : public ::testing::Test {
 protected:
  void SetUp() override { tmp_ = make_temp_dir("live-view"); }
  void TearDown() override {
    if (HasFailure()) std::cerr << "---- scenewatchd log ----\n" << daemon_.log() << "-------------------------\n";
    daemon_ = Daemon();
    std::error_code ec;
    fs::remove_all(tmp_, ec);
  }

  /// Starts scenewatchd with `--http 0` and reads the live view's port from its second line;
  /// `server_yaml`: more lines of its server section.
  void start(const std::string& server_yaml = "") {
    ASSERT_NO_FATAL_FAILURE(
        daemon_.start(tmp_, server_yaml + "segmentation:\n  up_vector: [0, 0, 1]\n", {"--http", "0"}));
    const auto line = daemon_.read_line();
    ASSERT_TRUE(line.has_value()) << "no 'live view on' line";
    const std::string prefix = "live view on http://127.0.0.1:";
    ASSERT_EQ(line->rfind(prefix, 0), 0u) << *line;
    http_port_ = static_cast<std::uint16_t>(std::stoi(line->substr(prefix.size())));
  }

  /// The TCP API still answers.
  void expect_api_serves() {
    ASSERT_TRUE(daemon_.running()) << daemon_.log();
    service::Client client = daemon_.connect();
    EXPECT_EQ(call(client, request([](proto::Request& r) { r.mutable_health(); })).status().code(), proto::Status::OK);
  }

  fs::path tmp_;
  Daemon daemon_;
  std::uint16_t http_port_ = 0;
};

TEST_F(LiveViewTest, BadRequestsGetAnErrorAndTheDaemonKeepsServing) {
  ASSERT_NO_FATAL_FAILURE(start());
  // A client that connects and says nothing is answered 408 after the head deadline (10 s); it
  // waits meanwhile, and the others are served.
  auto silent = std::async(std::launch::async, [port = http_port_] { return raw_exchange(port, ""); });
  struct Case {
    const char* what;
    std::string bytes;
    int status;
  };
  for (const Case& c : {Case{"garbage request line", "garbage\r\n\r\n", 400},
                        Case{"binary noise", std::string("\x16\x03\x01\x02\x00\x01\x00\x01\xfc\x03\x03\r\n\r\n", 15), 400},
                        Case{"oversized header", "GET / HTTP/1.1\r\nX-Big: " + std::string(20000, 'x') + "\r\n\r\n", 413},
                        Case{"unknown path", "GET /etc/passwd HTTP/1.1\r\n\r\n", 404},
                        Case{"POST", "POST /api/state HTTP/1.1\r\nContent-Length: 2\r\n\r\n{}", 405},
                        Case{"DELETE", "DELETE / HTTP/1.1\r\n\r\n", 405},
                        Case{"bad since", "GET /api/events?since=-1 HTTP/1.1\r\n\r\n", 400},
                        Case{"HTTP/2", "GET / HTTP/2.0\r\n\r\n", 505}}) {
    SCOPED_TRACE(c.what);
    EXPECT_EQ(status_of(raw_exchange(http_port_, c.bytes)), c.status);
    ASSERT_NO_FATAL_FAILURE(expect_api_serves());
    EXPECT_EQ(status_of(get(http_port_, "/")), 200);
  }
  // A client that connects and hangs up without a word, or half-way through its request.
  EXPECT_EQ(raw_exchange(http_port_, "", true), "") << "no request, no answer";
  EXPECT_EQ(raw_exchange(http_port_, "GET / HT", true), "") << "no whole request, no answer";
  const std::string page = get(http_port_, "/");
  EXPECT_NE(page.find("Content-Type: text/html"), std::string::npos);
  EXPECT_NE(body_of(page).find("scenewatch live view"), std::string::npos);
  const std::string state = get(http_port_, "/api/state");
  EXPECT_EQ(status_of(state), 200);
  EXPECT_NE(body_of(state).find("\"frames_processed\":0"), std::string::npos) << state;
  EXPECT_NE(body_of(state).find("\"voxels\":{"), std::string::npos) << state;
  EXPECT_EQ(body_of(get(http_port_, "/api/state?voxels=0")).find("\"voxels\""), std::string::npos) << "the light poll";
  for (const char* target : {"/api/state", "/api/state?voxels=0"}) {
    EXPECT_EQ(nlohmann::json::parse(body_of(get(http_port_, target))).at("pending"), nlohmann::json::array())
        << target << ": nothing seen, nothing pending";
  }
  EXPECT_EQ(status_of(get(http_port_, "/api/frame.png")), 404) << "no frame yet";
  EXPECT_EQ(body_of(get(http_port_, "/api/events?since=0")), "{\"events\":[]}");
  EXPECT_EQ(status_of(silent.get()), 408);
  ASSERT_NO_FATAL_FAILURE(expect_api_serves());
  ASSERT_EQ(daemon_.terminate(), std::optional<int>(0)) << daemon_.log();
}

/// Connects to 127.0.0.1:port and sends `bytes`; the socket (-1 when that failed).
int connect_and_send(std::uint16_t port, const std::string& bytes) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return -1;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
      ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(bytes.size())) {
    ::close(fd);
    return -1;
  }
  return fd;
}

/// What the server sent so far on `fd`, looked at without reading it (MSG_PEEK): the client stays
/// one that has read nothing. Waits up to timeout_s for `wanted` to be there.
std::string peek_until(int fd, const std::string& wanted, double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  std::string seen;
  while (seen.find(wanted) == std::string::npos && std::chrono::steady_clock::now() < deadline) {
    char buffer[4096];
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, MSG_PEEK | MSG_DONTWAIT);
    if (n == 0) break;
    if (n > 0) seen.assign(buffer, static_cast<std::size_t>(n));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return seen;
}

// Event streams have slots of their own (server.http_max_streams): 32 clients that open a stream
// and never read a byte of it do not take the slots page requests need.
TEST_F(LiveViewTest, ThePageIsServedWhileThirtyTwoIdleStreamsAreOpen) {
  ASSERT_NO_FATAL_FAILURE(start());
  const std::string open_stream = "GET /api/events HTTP/1.1\r\nAccept: text/event-stream\r\n\r\n";
  std::vector<int> streams;
  for (int i = 0; i < 32; ++i) {
    const int fd = connect_and_send(http_port_, open_stream);
    ASSERT_GE(fd, 0);
    streams.push_back(fd);
  }
  int streaming = 0;
  for (const int fd : streams) streaming += peek_until(fd, "text/event-stream", 20.0).find("200 OK") != std::string::npos;
  EXPECT_EQ(streaming, 32) << "each is a stream, unread";
  const std::string page = get(http_port_, "/");
  EXPECT_EQ(status_of(page), 200) << page.substr(0, 200);
  EXPECT_EQ(status_of(get(http_port_, "/api/state?voxels=0")), 200);
  EXPECT_EQ(status_of(get(http_port_, "/api/events?since=0")), 200);
  const std::string one_more = raw_exchange(http_port_, open_stream);
  EXPECT_EQ(status_of(one_more), 503) << one_more.substr(0, 300);
  EXPECT_NE(one_more.find("server.http_max_streams"), std::string::npos) << one_more.substr(0, 300);
  std::printf("32 idle event streams open: the page %d, a 33rd stream %d\n", status_of(page), status_of(one_more));
  for (const int fd : streams) ::close(fd);
  ASSERT_NO_FATAL_FAILURE(expect_api_serves());
}

std::string read_event_stream(std::uint16_t port, const std::string& wanted, double timeout_s);

// A stream with nothing to say still carries a comment line every server.http_heartbeat_s, so
// that a client (and every proxy between) sees it alive, and a peer that is gone is noticed.
TEST_F(LiveViewTest, AQuietStreamCarriesAHeartbeat) {
  ASSERT_NO_FATAL_FAILURE(start("  http_heartbeat_s: 0.5\n"));
  const std::string streamed = read_event_stream(http_port_, "\n\n: heartbeat", 30.0);
  EXPECT_EQ(streamed.rfind("HTTP/1.1 200 OK\r\n", 0), 0u) << streamed;
  EXPECT_NE(streamed.find("\n\n: heartbeat"), std::string::npos) << streamed;
  ASSERT_NO_FATAL_FAILURE(expect_api_serves());
}

// ---- streams of the HTTP server itself, whose handler here sends 3 MiB at once

/// An HttpServer on a free loopback port whose /stream answer sends `bytes` bytes right away; the
/// streams it opened are kept in `streams`.
struct FloodServer {
  explicit FloodServer(std::size_t bytes) {
    service::HttpServerConfig config;
    config.stream_timeout_s = 1.0;
    config.heartbeat_s = 0.25;
    server = std::make_unique<service::HttpServer>(config, [this, bytes](const service::HttpRequest&) {
      service::HttpResponse r;
      r.content_type = "text/event-stream";
      r.heartbeat = ": heartbeat\n\n";
      r.on_stream = [this, bytes](std::shared_ptr<service::HttpStream> stream) {
        for (std::size_t sent = 0; sent < bytes; sent += 64 * 1024) stream->send(std::string(64 * 1024, 'x'));
        std::lock_guard<std::mutex> lock(mutex);
        streams.push_back(std::move(stream));
      };
      return r;
    });
    EXPECT_TRUE(server->listen().ok());
    server->start();
  }
  /// Waits up to timeout_s for the first stream to be closed by the server; whether it was.
  bool first_stream_closed(double timeout_s) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < deadline) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (!streams.empty() && !streams.front()->open()) return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }
  std::mutex mutex;
  std::vector<std::shared_ptr<service::HttpStream>> streams;
  std::unique_ptr<service::HttpServer> server;
};

// A client that stops reading: once the socket buffers between are full, the server's bytes stop
// moving, and after the stream timeout (1 s here; server.http_stream_timeout_s) the stream is
// closed, though less than the 4 MiB that would close it as too slow is queued. A client that
// reads takes the same 3 MiB, and its stream goes on.
TEST(HttpServerStreams, AStreamWhoseClientReadsNothingIsClosedAfterTheTimeout) {
  constexpr std::size_t kBytes = 3u << 20;
  {
    FloodServer flood(kBytes);
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    ASSERT_GE(fd, 0);
    const int small = 4096;
    ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &small, sizeof small);  // before connect: a small window
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(flood.server->port());
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
    const std::string request = "GET /stream HTTP/1.1\r\n\r\n";
    ASSERT_EQ(::send(fd, request.data(), request.size(), MSG_NOSIGNAL), static_cast<ssize_t>(request.size()));
    EXPECT_TRUE(flood.first_stream_closed(30.0)) << "a client that reads nothing holds its stream";
    ::close(fd);
  }
  {
    FloodServer flood(kBytes);
    // The heartbeat follows once the 3 MiB are taken: the stream outlived them.
    const std::string streamed = read_event_stream(flood.server->port(), ": heartbeat\n\n", 30.0);
    EXPECT_GE(streamed.size(), kBytes) << "the reading client got it all";
    EXPECT_NE(streamed.find(": heartbeat\n\n"), std::string::npos) << "and its stream stayed open";
  }
}

// ---- listening: both servers open their port the same way (tcp_endpoint.h)

// An address that is not one names its config key; a port already taken names the endpoint; in
// both cases the server stays closed (port 0) and nothing else is disturbed.
TEST(Listening, ABadAddressNamesItsKeyAndATakenPortNamesTheEndpoint) {
  service::HttpServerConfig http_config;
  http_config.address = "localhost:80";
  service::HttpServer bad_http(http_config, [](const service::HttpRequest&) { return service::HttpResponse{}; });
  auto status = bad_http.listen();
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().message, "server.http_bind: 'localhost:80' is not an IP address");

  http_config.address = "127.0.0.1";
  http_config.port = 0;
  service::HttpServer first(http_config, [](const service::HttpRequest&) { return service::HttpResponse{}; });
  ASSERT_TRUE(first.listen().ok());
  const std::uint16_t taken = first.port();
  ASSERT_NE(taken, 0);

  // reuse_address lets a port in TIME_WAIT be bound again, not one that is listening.
  http_config.port = taken;
  service::HttpServer second(http_config, [](const service::HttpRequest&) { return service::HttpResponse{}; });
  status = second.listen();
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().message.rfind("cannot listen for HTTP on 127.0.0.1:" + std::to_string(taken) + ": ", 0), 0u)
      << status.error().message;
  EXPECT_EQ(second.port(), 0) << "the acceptor is closed again";

  pipeline::WorkingMemory memory{pipeline::Config{}};
  service::ServerConfig api_config;
  api_config.access_token = "a token";  // the server refuses to listen without one
  api_config.address = "::1::";
  service::Server bad_api(api_config, memory, {}, false);
  status = bad_api.listen();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("server.address: '::1::' is not an IP address"), std::string::npos)
      << status.error().message;
  api_config.address = "127.0.0.1";
  api_config.port = taken;
  service::Server busy_api(api_config, memory, {}, false);
  status = busy_api.listen();
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().message.rfind("cannot listen on 127.0.0.1:" + std::to_string(taken) + ": ", 0), 0u)
      << status.error().message;
  EXPECT_EQ(first.port(), taken) << "the first server still listens";
}

// ---- the page in headless Chromium

const char* const kChromium = "/usr/bin/chromium";

/// Renders the simulator's cup_added (320x240, 12 frames per phase) and hands each frame to
/// `ingest`: the table's phase, then the first `cup_frames` of the cup's. Returns the ground truth
/// of where the cup was put.
template <class Ingest>
Eigen::Vector3d render_cup_added(int cup_frames, const std::string& camera, Ingest ingest) {
  auto loaded = sim::load_scenario(source_dir() / "sample_clouds/scenarios/cup_added.yaml");
  EXPECT_TRUE(loaded.ok()) << loaded.error().message;
  if (!loaded.ok()) return {};
  const sim::Scenario scenario = sim::with_frames(sim::with_resolution(*loaded, 320, 240), 12);
  auto simulator = sim::Simulator::create(scenario);
  EXPECT_TRUE(simulator.ok()) << simulator.error().message;
  if (!simulator.ok()) return {};
  double stamp = 0;
  for (std::size_t phase = 0; phase < simulator->phase_count(); ++phase) {
    const int frames = phase == 1 ? std::min(cup_frames, simulator->frame_count(phase)) : simulator->frame_count(phase);
    for (int f = 0; f < frames; ++f) {
      auto frame = sim::as_frame(simulator->render(phase, f), scenario.intrinsics, stamp += 1.0 / 30);
      EXPECT_TRUE(frame.ok());
      if (!frame.ok()) return {};
      frame->camera = camera;
      ingest(*frame);
    }
  }
  return simulator->changes().at(0).added.at(0).T_world_object.translation();
}

/// Streams cup_added into the daemon, the cup's phase up to `cup_frames` (see render_cup_added).
Eigen::Vector3d ingest_cup_added(const Daemon& daemon, int cup_frames = 12, const std::string& camera = "") {
  service::Client client = daemon.connect();
  return render_cup_added(cup_frames, camera, [&](const Frame& frame) {
    proto::Request r;
    *r.mutable_ingest_frame() = service::make_ingest_frame(frame);
    EXPECT_EQ(call(client, r).status().code(), proto::Status::OK);
  });
}

/// Reads /api/events (Server-Sent Events) until `wanted` came or timeout_s passed; returns what came.
std::string read_event_stream(std::uint16_t port, const std::string& wanted, double timeout_s) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return "socket failed";
  timeval tick{0, 200000};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tick, sizeof tick);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string out;
  const std::string request = "GET /api/events HTTP/1.1\r\nAccept: text/event-stream\r\n\r\n";
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0 &&
      ::send(fd, request.data(), request.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(request.size())) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    char buffer[65536];
    while (out.find(wanted) == std::string::npos && std::chrono::steady_clock::now() < deadline) {
      const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
      if (n == 0) break;
      if (n > 0) out.append(buffer, static_cast<std::size_t>(n));
    }
  }
  ::close(fd);
  return out;
}

/// Headless Chromium on a URL with the given output flag (--dump-dom, --screenshot=FILE).
CommandResult run_chromium(const fs::path& work_dir, const std::string& url, const std::string& output_flag) {
  return run_command({kChromium, "--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
                      "--use-angle=swiftshader", "--user-data-dir=" + (work_dir / "chromium-profile").string(),
                      "--window-size=1280,800", "--hide-scrollbars", output_flag, url},
                     work_dir, 240.0);
}

/// The 3D view of a headless Chromium screenshot of `url` (saved at `shot`): right of the 440 px
/// side column, below the header. Empty when there is none (the test has failed then).
cv::Mat screenshot_3d_view(const fs::path& work_dir, const std::string& url, const fs::path& shot) {
  const CommandResult screenshot = run_chromium(work_dir, url, "--screenshot=" + shot.string());
  if (screenshot.exit_code != 0) {
    ADD_FAILURE() << screenshot.err;
    return {};
  }
  const cv::Mat image = cv::imread(shot.string(), cv::IMREAD_COLOR);
  if (image.empty()) {
    ADD_FAILURE() << "no screenshot at " << shot;
    return {};
  }
  EXPECT_EQ(image.cols, 1280);
  return image(cv::Rect(450, 40, image.cols - 450, image.rows - 40));
}

/// The pixels of a BGR image that `match` takes.
template <class Match>
int count_pixels(const cv::Mat& bgr_image, Match match) {
  int n = 0;
  for (int y = 0; y < bgr_image.rows; ++y)
    for (int x = 0; x < bgr_image.cols; ++x) n += match(bgr_image.at<cv::Vec3b>(y, x)) ? 1 : 0;
  return n;
}

// The views the last NextBestView suggested are in the state (both polls), as the API gave them,
// and stay there when a later request fails.
void expect_suggested_views_in_state(std::uint16_t http_port, const proto::NextBestViewReply& reply, std::uint64_t answer) {
  for (const char* target : {"/api/state", "/api/state?voxels=0"}) {
    SCOPED_TRACE(target);
    const nlohmann::json views = nlohmann::json::parse(body_of(get(http_port, target))).at("views");
    EXPECT_EQ(views.at("answer").get<std::uint64_t>(), answer);
    EXPECT_EQ(views.at("measure").get<std::string>(), reply.measure());
    // The planner's default camera: 640 x 480 at 525 px.
    EXPECT_NEAR(views.at("horizontal_fov_deg").get<double>(), 2 * std::atan(320.0 / 525.0) * 180 / M_PI, 1e-9);
    ASSERT_EQ(views.at("views").size(), static_cast<std::size_t>(reply.views_size()));
    for (int k = 0; k < reply.views_size(); ++k) {
      const auto& pose = views.at("views")[k].at("pose");
      ASSERT_EQ(pose.size(), 16u);
      // Within 1e-9: the pose went through the API's decoding, which checks it is rigid.
      for (int i = 0; i < 16; ++i) EXPECT_NEAR(pose[i].get<double>(), reply.views(k).pose().matrix(i), 1e-9) << "view " << k;
      EXPECT_DOUBLE_EQ(views.at("views")[k].at("score").get<double>(), reply.views(k).score());
    }
  }
}

TEST_F(LiveViewTest, ChromiumShowsTheObjectTheEventAndTheSuggestedViewsAfterACupIsPutOnTheTable) {
  ASSERT_NO_FATAL_FAILURE(start());
  // A stream opened before the frames hears the event as it is emitted.
  auto stream = std::async(std::launch::async, [port = http_port_] {
    return read_event_stream(port, "\"kind\":\"OBJECT_ADDED\"", 120.0);
  });
  // The event comes seconds later (after the second phase's frames): the stream is open by then.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ingest_cup_added(daemon_);
  const std::string streamed = stream.get();
  EXPECT_EQ(streamed.rfind("HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\n", 0), 0u) << streamed;
  EXPECT_NE(streamed.find("\nid: 1\ndata: {"), std::string::npos) << streamed;
  EXPECT_NE(streamed.find("\"kind\":\"OBJECT_ADDED\""), std::string::npos) << streamed;
  EXPECT_EQ(streamed.find("indices_after"), std::string::npos) << "point indices are left out";
  // The event is in the backlog and the object in the state before the browser looks.
  const std::string events = body_of(get(http_port_, "/api/events?since=0"));
  ASSERT_NE(events.find("OBJECT_ADDED"), std::string::npos) << events;
  const std::string state = body_of(get(http_port_, "/api/state"));
  ASSERT_NE(state.find("\"objects\":[{"), std::string::npos) << state;
  // The daemon's classes describe the objects in the whole state (as GetObjects does); the
  // cheap poll leaves them out.
  EXPECT_NE(state.find("\"class\":\"cup\""), std::string::npos) << state;
  EXPECT_EQ(body_of(get(http_port_, "/api/state?voxels=0")).find("\"class\":"), std::string::npos);
  const std::string frame = get(http_port_, "/api/frame.png");
  ASSERT_EQ(status_of(frame), 200);
  EXPECT_EQ(body_of(frame).substr(1, 3), "PNG");
  // Where to look at the workspace next: three views, drawn as frusta.
  EXPECT_EQ(nlohmann::json::parse(body_of(get(http_port_, "/api/state?voxels=0"))).at("views").at("answer"), 0) << "none yet";
  service::Client client = daemon_.connect();
  const auto nbv = call(client, request([](proto::Request& r) {
    r.mutable_next_best_view()->set_workspace(true);
    r.mutable_next_best_view()->set_n(3);
  }));
  ASSERT_EQ(nbv.status().code(), proto::Status::OK) << nbv.status().message();
  ASSERT_EQ(nbv.next_best_view().views_size(), 3);
  expect_suggested_views_in_state(http_port_, nbv.next_best_view(), 1);
  const auto unknown = call(client, request([](proto::Request& r) { r.mutable_next_best_view()->set_object_id(999999); }));
  EXPECT_EQ(unknown.status().code(), proto::Status::NOT_FOUND);
  expect_suggested_views_in_state(http_port_, nbv.next_best_view(), 1);

  if (!fs::exists(kChromium)) {
    GTEST_SKIP() << "headless Chromium is not installed (" << kChromium
                 << "; Debian package chromium, which scripts/install-deps installs): the browser part is skipped";
  }
  const std::string url = "http://127.0.0.1:" + std::to_string(http_port_) + "/";
  const CommandResult dom = run_chromium(tmp_, url, "--dump-dom");
  ASSERT_EQ(dom.exit_code, 0) << dom.err;
  EXPECT_NE(dom.out.find("class=\"event OBJECT_ADDED\""), std::string::npos) << dom.out;
  EXPECT_NE(dom.out.find("class=\"object\">object "), std::string::npos) << dom.out;
  EXPECT_NE(dom.out.find(" (cup, score "), std::string::npos) << "the object's class is listed:\n" << dom.out;
  EXPECT_NE(dom.out.find("id=\"three-error\" hidden"), std::string::npos) << "three.js or WebGL missing:\n" << dom.out;
  EXPECT_NE(dom.out.find("3 suggested views (" + nbv.next_best_view().measure() + "), best first"), std::string::npos) << dom.out;

  const fs::path shot = tmp_ / "live-view.png";
  const cv::Mat view = screenshot_3d_view(tmp_, url, shot);
  ASSERT_FALSE(view.empty());
  // The boxes are drawn in pure magenta, a colour nothing else on the page has (the heatmap is a
  // jet colour map over grey, and in the side column besides).
  const int magenta = count_pixels(view, [](const cv::Vec3b& bgr) { return bgr[2] > 230 && bgr[0] > 230 && bgr[1] < 40; });
  EXPECT_GT(magenta, 1000) << "the object's box is not drawn in the 3D view: " << shot;
  // The suggested views' frusta are drawn in cyan (#00e5ff, the best view; #00a0b4 the others),
  // a colour nothing else on the page has either (the voxels' lit blue-grey keeps some red).
  const int cyan = count_pixels(view, [](const cv::Vec3b& bgr) { return bgr[2] < 50 && bgr[1] > 140 && bgr[0] > 160; });
  EXPECT_GT(cyan, 200) << "the suggested views are not drawn in the 3D view: " << shot;
  std::printf("3D view: %d magenta pixels (the objects), %d cyan (the suggested views)\n", magenta, cyan);
  if (const char* keep = std::getenv("SCENEWATCH_LIVE_VIEW_SCREENSHOT")) fs::copy_file(shot, keep, fs::copy_options::overwrite_existing);
  ASSERT_EQ(daemon_.terminate(), std::optional<int>(0)) << daemon_.log();
}

// ---- the changes seen but not yet confirmed (issue 31, item 4)

/// The state's pending changes are those GetPendingChanges listed from the same snapshot, field
/// for field; the numbers exactly (JSON keeps a double's shortest form that reads back the same).
void expect_pending_as_listed(const nlohmann::json& pending, const proto::PendingChangesReply& listed) {
  ASSERT_EQ(pending.size(), static_cast<std::size_t>(listed.changes_size())) << pending;
  const auto xyz = [](const proto::Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
  for (int k = 0; k < listed.changes_size(); ++k) {
    SCOPED_TRACE("pending change " + std::to_string(k));
    const proto::PendingChange& c = listed.changes(k);
    const nlohmann::json& s = pending[k];
    EXPECT_EQ(s.at("id").get<std::uint64_t>(), c.id());
    EXPECT_EQ(s.at("kind").get<std::string>(), proto::PendingChange::Kind_Name(c.kind()));
    EXPECT_EQ(s.at("box_world").at("min"), xyz(c.box_world().min()));
    EXPECT_EQ(s.at("box_world").at("max"), xyz(c.box_world().max()));
    EXPECT_EQ(s.at("centroid_world"), xyz(c.centroid_world()));
    EXPECT_EQ(s.at("hits").get<std::uint32_t>(), c.hits());
    EXPECT_EQ(s.at("hits_needed").get<std::uint32_t>(), c.hits_needed());
    EXPECT_EQ(s.at("camera").get<std::string>(), c.camera());
  }
}

/// The page's line over its list: "N pending changes (k KIND, ...)", the kinds in the order they
/// first come; "0 pending changes" alone.
std::string pending_line(const proto::PendingChangesReply& listed) {
  std::vector<std::pair<std::string, int>> kinds;
  for (const auto& c : listed.changes()) {
    const std::string name = proto::PendingChange::Kind_Name(c.kind());
    const auto it = std::find_if(kinds.begin(), kinds.end(), [&](const auto& k) { return k.first == name; });
    if (it == kinds.end()) kinds.emplace_back(name, 1);
    else ++it->second;
  }
  const int n = listed.changes_size();
  std::string line = std::to_string(n) + " pending change" + (n == 1 ? "" : "s");
  for (std::size_t k = 0; k < kinds.size(); ++k) {
    line += (k == 0 ? " (" : ", ") + std::to_string(kinds[k].second) + " " + kinds[k].first;
  }
  return kinds.empty() ? line : line + ")";
}

// After the cup's first frame the cup is a pending addition, seen in 1 of the 3 frames it needs
// (next_view_test follows it to its event). The state lists the pending changes as
// GetPendingChanges does, in both polls; the page lists them and draws their boxes in lavender.
// Before any frame nothing is pending, and the page says so.
TEST_F(LiveViewTest, ChromiumShowsTheChangesPendingAfterTheCupsFirstFrame) {
  ASSERT_NO_FATAL_FAILURE(start());
  const std::string url = "http://127.0.0.1:" + std::to_string(http_port_) + "/";
  const bool have_chromium = fs::exists(kChromium);
  if (have_chromium) {
    const CommandResult empty = run_chromium(tmp_, url, "--dump-dom");
    ASSERT_EQ(empty.exit_code, 0) << empty.err;
    EXPECT_NE(empty.out.find("class=\"note\">0 pending changes</div>"), std::string::npos) << empty.out;
    EXPECT_EQ(empty.out.find("class=\"pending\""), std::string::npos) << empty.out;
  }

  const Eigen::Vector3d cup = ingest_cup_added(daemon_, 1, "table-cam");
  service::Client client = daemon_.connect();
  const auto listed = call(client, request([](proto::Request& r) { r.mutable_get_pending_changes(); }));
  ASSERT_EQ(listed.status().code(), proto::Status::OK) << listed.status().message();
  const proto::PendingChangesReply& reply = listed.pending_changes();
  EXPECT_EQ(reply.frames_processed(), 13u) << "12 of the table, 1 of the cup";
  const proto::PendingChange* at_cup = nullptr;
  for (const auto& c : reply.changes()) {
    const auto& b = c.box_world();
    const Eigen::Vector2d centre(0.5 * (b.min().x() + b.max().x()), 0.5 * (b.min().y() + b.max().y()));
    if (c.kind() == proto::PendingChange::ADDED && (centre - cup.head<2>()).norm() < 0.04) at_cup = &c;
  }
  ASSERT_NE(at_cup, nullptr) << "no pending addition within the cup's radius of it: " << reply.DebugString();
  EXPECT_EQ(at_cup->hits(), 1u);
  EXPECT_EQ(at_cup->hits_needed(), 3u) << "change.persistence_frames";
  EXPECT_EQ(at_cup->camera(), "table-cam");
  for (const char* target : {"/api/state", "/api/state?voxels=0"}) {
    SCOPED_TRACE(target);
    const nlohmann::json state = nlohmann::json::parse(body_of(get(http_port_, target)));
    ASSERT_EQ(state.at("frames_processed").get<std::uint64_t>(), reply.frames_processed()) << "the same snapshot";
    expect_pending_as_listed(state.at("pending"), reply);
  }

  if (!have_chromium) {
    GTEST_SKIP() << "headless Chromium is not installed (" << kChromium
                 << "; Debian package chromium, which scripts/install-deps installs): the browser part is skipped";
  }
  const CommandResult dom = run_chromium(tmp_, url, "--dump-dom");
  ASSERT_EQ(dom.exit_code, 0) << dom.err;
  EXPECT_NE(dom.out.find("class=\"note\">" + pending_line(reply) + "</div>"), std::string::npos)
      << pending_line(reply) << "\n" << dom.out;
  const std::string item = "class=\"pending\">#" + std::to_string(at_cup->id()) + " ADDED: seen in 1 of 3 frames, ";
  const std::size_t at = dom.out.find(item);
  ASSERT_NE(at, std::string::npos) << item << "\n" << dom.out;
  const std::string li = dom.out.substr(at, dom.out.find("</li>", at) - at);
  EXPECT_NE(li.find(" by camera table-cam"), std::string::npos) << li;

  const fs::path shot = tmp_ / "live-view-pending.png";
  const cv::Mat view = screenshot_3d_view(tmp_, url, shot);
  ASSERT_FALSE(view.empty());
  // Lavender (#b28cff) has a blue no lit voxel reaches (their #7d97b8 at most 1.15 times) and a
  // red and green that neither the magenta boxes, the cyan frusta nor grey text have. Measured
  // 394 for the cup's box.
  const int lavender = count_pixels(view, [](const cv::Vec3b& bgr) {
    return bgr[0] > 225 && bgr[2] > 140 && bgr[2] < 215 && bgr[1] > 110 && bgr[1] < 175;
  });
  EXPECT_GT(lavender, 300) << "the pending changes' boxes are not drawn in the 3D view: " << shot;
  std::printf("pending changes: %d; 3D view: %d lavender pixels (their boxes)\n", reply.changes_size(), lavender);
  ASSERT_EQ(daemon_.terminate(), std::optional<int>(0)) << daemon_.log();
}

// A camera's name is the frames' own (only control characters are refused): one that is not
// UTF-8 must not cost the page its state. The live view on a working memory of its own (as the
// daemon wires them), fed the same frames under such a name; the state agrees with the snapshot.
TEST(LiveView, AStateWithACameraNameThatIsNotUtf8IsStillServed) {
  pipeline::Config config;
  config.segmentation.up = Eigen::Vector3d::UnitZ();
  pipeline::WorkingMemory memory(config);
  service::LiveView live(memory, {});
  render_cup_added(1, "cam\xff", [&](const Frame& frame) {
    auto processed = memory.process(frame);
    EXPECT_TRUE(processed.ok()) << processed.error().message;
  });
  const auto snapshot = memory.snapshot();
  ASSERT_FALSE(snapshot->pending.empty()) << "the cup's first frame leaves a change pending";
  service::HttpRequest request;
  request.method = "GET";
  request.path = "/api/state";
  const service::HttpResponse response = live.handle(request);
  ASSERT_EQ(response.status, 200) << response.body;
  const nlohmann::json pending = nlohmann::json::parse(response.body).at("pending");
  ASSERT_EQ(pending.size(), snapshot->pending.size());
  for (std::size_t k = 0; k < pending.size(); ++k) {
    const change::PendingChange& c = snapshot->pending[k].change;
    EXPECT_EQ(pending[k].at("id").get<std::uint64_t>(), c.id);
    EXPECT_EQ(pending[k].at("box_world").at("min"), nlohmann::json::array({c.box_world.min.x(), c.box_world.min.y(), c.box_world.min.z()}));
    EXPECT_EQ(pending[k].at("hits").get<int>(), c.hits);
    EXPECT_EQ(pending[k].at("camera").get<std::string>(), "cam\xef\xbf\xbd") << "U+FFFD in place of the byte";
  }
}

}  // namespace
}  // namespace scenewatch::test

#pragma once
// Starts the real scenewatchd for integration tests, on a free port, with a config written to a
// temporary folder; the process is killed when the harness goes away.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "child_process.h"
#include "scenewatch/service/access_token.h"
#include "scenewatch/service/client.h"
#include "test_data.h"

namespace scenewatch::test {

inline std::filesystem::path daemon_binary() { return binary_dir() / "apps" / "scenewatchd" / "scenewatchd"; }
inline std::filesystem::path cli_binary() { return binary_dir() / "apps" / "scenewatch" / "scenewatch"; }

/// Generous limits: they only bound a hung test, they never judge speed.
inline constexpr double kStartTimeoutS = 60.0;
inline constexpr double kCallTimeoutS = 60.0;

class Daemon {
 public:
  /// `server_yaml`: lines of the server section (indented by two spaces), `port: 0` is added, and
  /// `token_file: WORK_DIR/token` unless it names one. `extra_args` go on the command line.
  void start(const std::filesystem::path& work_dir, const std::string& server_yaml,
             const std::vector<std::string>& extra_args = {}) {
    work_dir_ = work_dir;
    if (server_yaml.find("token_file:") == std::string::npos) token_file_ = work_dir / "token";
    const auto config = work_dir / ("scenewatchd-" + std::to_string(++starts_) + ".yaml");
    std::ofstream(config) << "server:\n  address: 127.0.0.1\n  port: 0\n"
                          << (token_file_.empty() ? "" : "  token_file: " + token_file_.string() + "\n") << server_yaml;
    std::vector<std::string> argv = command_prefix_;
    argv.insert(argv.end(), {daemon_binary().string(), "--config", config.string(), "--port", "0"});
    argv.insert(argv.end(), extra_args.begin(), extra_args.end());
    auto child = ChildProcess::start(argv, work_dir / ("scenewatchd-" + std::to_string(starts_) + ".log"));
    ASSERT_TRUE(child.has_value()) << "cannot start " << daemon_binary();
    process_ = std::move(*child);
    const auto line = process_->read_line(kStartTimeoutS);
    ASSERT_TRUE(line.has_value()) << "scenewatchd did not say it was listening; its log:\n" << log();
    const std::string prefix = "listening on 127.0.0.1:";
    ASSERT_EQ(line->rfind(prefix, 0), 0u) << *line;
    port_ = static_cast<std::uint16_t>(std::stoi(line->substr(prefix.size())));
    ASSERT_GT(port_, 0);
    if (!token_file_.empty()) {
      auto token = service::read_token_file(token_file_);
      ASSERT_TRUE(token.ok()) << token.error().message;
      token_ = *token;
    }
  }

  /// Runs the daemon through a command that execs its arguments (`unshare -rm ...`); set before start().
  void set_command_prefix(std::vector<std::string> prefix) { command_prefix_ = std::move(prefix); }

  /// SIGTERM, then waits; returns the exit code (nothing if it did not exit).
  std::optional<int> terminate() {
    if (!process_) return std::nullopt;
    process_->signal(SIGTERM);
    return process_->wait(kStartTimeoutS);
  }

  /// The next line the daemon prints on stdout after "listening on ..." (nothing on timeout).
  std::optional<std::string> read_line(double timeout_s = kStartTimeoutS) {
    return process_ ? process_->read_line(timeout_s) : std::nullopt;
  }

  /// True while the process runs.
  bool running() { return process_ && !process_->wait(0.0).has_value(); }

  std::uint16_t port() const { return port_; }
  /// The daemon's process id (0 before start).
  pid_t pid() const { return process_ ? process_->pid() : 0; }
  std::string log() const { return process_ ? process_->stderr_text() : std::string(); }

  /// The daemon's access token (read from its token file after start).
  const std::string& token() const { return token_; }

  /// The token file the daemon was given (empty when the test's yaml named its own).
  const std::filesystem::path& token_file() const { return token_file_; }

  /// A connected client that sends the daemon's token (the test fails when connecting fails).
  service::Client connect() const {
    service::Client client = connect_without_token();
    client.set_token(token_);
    return client;
  }

  /// A connected client that sends no token: calls that change the model are refused.
  service::Client connect_without_token() const {
    auto client = service::Client::connect("127.0.0.1", port_, 10.0);
    EXPECT_TRUE(client.ok()) << client.error().message;
    if (!client.ok()) throw std::runtime_error(client.error().message);
    return std::move(*client);
  }

 private:
  std::filesystem::path work_dir_;
  std::optional<ChildProcess> process_;
  std::uint16_t port_ = 0;
  std::filesystem::path token_file_;
  std::string token_;
  int starts_ = 0;
  std::vector<std::string> command_prefix_;
};

/// Makes one call; a transport error fails the test and yields an empty Response.
inline proto::Response call(service::Client& client, proto::Request request) {
  auto response = client.call(std::move(request), kCallTimeoutS);
  EXPECT_TRUE(response.ok()) << response.error().message;
  return response.ok() ? std::move(*response) : proto::Response();
}

/// A request with just the given call set, e.g. request([](auto& r) { r.mutable_health(); }).
template <typename F>
proto::Request request(F&& set) {
  proto::Request r;
  set(r);
  return r;
}

}  // namespace scenewatch::test

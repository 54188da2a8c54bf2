#pragma once
// The real scenewatchd for benchmarks, started as a user starts it (POSIX; the bench only).
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "scenewatch/service/access_token.h"

namespace scenewatch::bench {

// scenewatchd on a free port; stops it (SIGTERM) when destroyed.
class Daemon {
 public:
  /// `config_name`: a file of the source tree's config/ folder.
  bool start(const std::filesystem::path& model_dir, const std::string& config_name = "scenewatchd.yaml") {
    const std::string binary = std::string(SCENEWATCH_BINARY_DIR) + "/apps/scenewatchd/scenewatchd";
    const std::string config = std::string(SCENEWATCH_SOURCE_DIR) + "/config/" + config_name;
    int out[2];
    if (::pipe(out) != 0) return false;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(out[1], STDOUT_FILENO);
      ::close(out[0]);
      const std::string dir = model_dir.string();
      const std::string token = token_file_of(model_dir).string();
      ::execl(binary.c_str(), binary.c_str(), "--config", config.c_str(), "--port", "0", "--model-dir", dir.c_str(),
              "--token-file", token.c_str(), static_cast<char*>(nullptr));
      std::_Exit(127);
    }
    ::close(out[1]);
    std::string line;
    char c;
    pollfd p{out[0], POLLIN, 0};
    while (::poll(&p, 1, 20000) > 0 && ::read(out[0], &c, 1) == 1) {
      if (c == '\n') break;
      line += c;
    }
    ::close(out[0]);
    const std::string prefix = "listening on 127.0.0.1:";
    if (line.rfind(prefix, 0) != 0) return false;
    port_ = static_cast<std::uint16_t>(std::stoi(line.substr(prefix.size())));
    auto token = service::read_token_file(token_file_of(model_dir));
    if (!token) return false;
    token_ = *token;
    return true;
  }
  ~Daemon() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  std::uint16_t port() const { return port_; }
  /// The daemon's access token (ingest needs it).
  const std::string& token() const { return token_; }

 private:
  pid_t pid_ = -1;
  std::uint16_t port_ = 0;
  std::string token_;

  /// Beside the model directory, so that a benchmark never touches ~/.scenewatch/token.
  static std::filesystem::path token_file_of(const std::filesystem::path& model_dir) {
    return model_dir.string() + ".token";
  }
};


}  // namespace scenewatch::bench

#pragma once
// Runs the real binaries for integration tests: a child process with its stdout on a pipe (or a
// file) and stderr in a file. The child is killed when the test ends, even on failure: by the
// destructor, and by the kernel (PR_SET_PDEATHSIG) if the test process dies.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace scenewatch::test {

class ChildProcess {
 public:
  /// Starts `argv[0]` with arguments; stdout goes to a pipe read by read_line(), stderr to
  /// `stderr_path`. Returns nothing when fork fails.
  static std::optional<ChildProcess> start(const std::vector<std::string>& argv,
                                           const std::filesystem::path& stderr_path) {
    int out[2];
    if (::pipe2(out, O_CLOEXEC) != 0) return std::nullopt;
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    const std::string err_path = stderr_path.string();
    const pid_t parent = ::getpid();
    const pid_t pid = ::fork();
    if (pid < 0) return std::nullopt;
    if (pid == 0) {
      // Child: only async-signal-safe calls until exec.
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (::getppid() != parent) ::_exit(127);
      const int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(out[1], STDOUT_FILENO);
      if (err >= 0) ::dup2(err, STDERR_FILENO);
      ::execv(args[0], args.data());
      ::_exit(127);
    }
    ::close(out[1]);
    ChildProcess child;
    child.pid_ = pid;
    child.stdout_fd_ = out[0];
    child.stderr_path_ = stderr_path;
    return child;
  }

  ChildProcess() = default;
  ChildProcess(ChildProcess&& o) noexcept { *this = std::move(o); }
  ChildProcess& operator=(ChildProcess&& o) noexcept {
    std::swap(pid_, o.pid_);
    std::swap(stdout_fd_, o.stdout_fd_);
    std::swap(stderr_path_, o.stderr_path_);
    std::swap(buffer_, o.buffer_);
    std::swap(exit_code_, o.exit_code_);
    return *this;
  }
  ~ChildProcess() { kill_now(); }

  pid_t pid() const { return pid_; }

  /// The next line of the child's stdout, waiting at most timeout_s; nothing on EOF or timeout.
  std::optional<std::string> read_line(double timeout_s) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    for (;;) {
      if (auto pos = buffer_.find('\n'); pos != std::string::npos) {
        std::string line = buffer_.substr(0, pos);
        buffer_.erase(0, pos + 1);
        return line;
      }
      if (stdout_fd_ < 0) return std::nullopt;
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) return std::nullopt;
      pollfd p{stdout_fd_, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
      char chunk[4096];
      const ssize_t n = ::read(stdout_fd_, chunk, sizeof chunk);
      if (n <= 0) {
        ::close(stdout_fd_);
        stdout_fd_ = -1;
        continue;
      }
      buffer_.append(chunk, static_cast<std::size_t>(n));
    }
  }

  /// Stdout bytes received after the last complete line.
  std::string take_rest() { return std::exchange(buffer_, std::string()); }

  /// Sends a signal (by pid, to this child only).
  void signal(int sig) {
    if (pid_ > 0 && !exit_code_) ::kill(pid_, sig);
  }

  /// Waits for the child to exit; its exit code (128 + signal when killed), or nothing on timeout.
  std::optional<int> wait(double timeout_s) {
    if (exit_code_) return exit_code_;
    if (pid_ <= 0) return std::nullopt;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    for (;;) {
      int status = 0;
      const pid_t r = ::waitpid(pid_, &status, WNOHANG);
      if (r == pid_) {
        exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        return exit_code_;
      }
      if (r < 0 || std::chrono::steady_clock::now() > deadline) return std::nullopt;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }

  /// Everything the child wrote to stderr so far.
  std::string stderr_text() const {
    std::ifstream in(stderr_path_);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }

  /// Kills the child (SIGKILL) if it still runs, and reaps it.
  void kill_now() {
    if (pid_ > 0 && !exit_code_) {
      ::kill(pid_, SIGKILL);
      int status = 0;
      ::waitpid(pid_, &status, 0);
      exit_code_ = 128 + SIGKILL;
    }
    if (stdout_fd_ >= 0) {
      ::close(stdout_fd_);
      stdout_fd_ = -1;
    }
  }

 private:
  pid_t pid_ = -1;
  int stdout_fd_ = -1;
  std::filesystem::path stderr_path_;
  std::string buffer_;
  std::optional<int> exit_code_;
};

/// Result of running a command to completion.
struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};

/// Runs a command, waits at most timeout_s (then kills it), and returns its output.
inline CommandResult run_command(const std::vector<std::string>& argv, const std::filesystem::path& work_dir,
                                 double timeout_s = 60.0) {
  static int counter = 0;
  const auto err_path = work_dir / ("cmd-" + std::to_string(++counter) + ".stderr");
  CommandResult result;
  auto child = ChildProcess::start(argv, err_path);
  if (!child) return result;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (auto line = child->read_line(std::max(0.0, std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count()))) {
    result.out += *line + "\n";
  }
  result.out += child->take_rest();
  const auto code = child->wait(std::max(0.1, std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count()));
  result.exit_code = code.value_or(-1);
  result.err = child->stderr_text();
  return result;
}

}  // namespace scenewatch::test

#pragma once
/// The bridge's counters and latency samples, for its stats line: frames in, sent, dropped (by
/// reason), messages out, and the latency it adds (sample arrival to the request on the wire;
/// reply to the outgoing messages). Thread safe.
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace scenewatch::ros {

class BridgeStats {
 public:
  /// Counts one event of `name` ("frames_sent", "dropped.no_tf", ...); returns the new count.
  std::uint64_t count(const std::string& name, std::uint64_t n = 1);
  /// Adds one latency sample (milliseconds) to the series `name`.
  void sample_ms(const std::string& name, double ms);
  /// One line: every counter, then per series n, median, p95 and max in ms.
  std::string line() const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, std::uint64_t> counters_;
  std::map<std::string, std::vector<double>> series_;
};

/// True for the counts worth a log line (1..10, then powers of two): a steady failure is reported
/// without flooding the log.
inline bool worth_logging(std::uint64_t n) { return n <= 10 || (n & (n - 1)) == 0; }

/// A time or stamp in seconds for a log line, to the microsecond ("12.345678").
std::string seconds(double t);

}  // namespace scenewatch::ros

#pragma once
/// Logging hook: library code never prints; the daemon passes a sink that writes to stderr.
#include <functional>
#include <string>

namespace scenewatch::service {

/// Severity of a log line.
enum class LogLevel { kDebug, kInfo, kWarning, kError };

/// Printable name ("DEBUG", "INFO", "WARN", "ERROR").
const char* to_string(LogLevel level);

/// Receives log lines; called from any server thread, so it must be thread safe.
using LogSink = std::function<void(LogLevel level, const std::string& message)>;

}  // namespace scenewatch::service

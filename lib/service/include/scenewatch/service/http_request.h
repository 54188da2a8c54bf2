#pragma once
/// The head of an HTTP/1.x request and its incremental parser. Socket-free, so it is unit tested
/// on arbitrary byte splits; the live view's server (http_server.h) feeds it what it reads.
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace scenewatch::service {

/// The request line and headers; a body, if any, is not read.
struct HttpRequest {
  std::string method;   ///< "GET"
  std::string target;   ///< "/api/events?since=3"
  std::string path;     ///< "/api/events"
  std::string query;    ///< "since=3" (without the '?')
  std::string version;  ///< "HTTP/1.1"
  std::vector<std::pair<std::string, std::string>> headers;  ///< names as sent, values trimmed

  /// The first header of that name (case-insensitive), or "".
  std::string header(std::string_view name) const;
  /// The value of `name=value` in the query (not percent-decoded), or "" when absent.
  std::string query_value(std::string_view name) const;
  /// True when the query has `name` (with or without a value).
  bool has_query(std::string_view name) const;
};

/// Incremental parser of a request head (request line, headers, blank line). Bare "\n" line ends
/// are accepted as well as "\r\n". After a result other than kIncomplete it stays there. NOT
/// thread safe.
class HttpRequestParser {
 public:
  enum class State { kIncomplete, kComplete, kError };

  /// Heads larger than `max_head_bytes` are refused (413) as soon as that many bytes came without
  /// the blank line.
  explicit HttpRequestParser(std::size_t max_head_bytes = 8192);

  /// Appends bytes; returns the state after them. Bytes after the head are ignored.
  State feed(std::string_view bytes);

  State state() const { return state_; }
  /// The request; valid once feed() returned kComplete.
  const HttpRequest& request() const { return request_; }
  /// The status to answer with once feed() returned kError: 400, 413 or 505.
  int error_status() const { return error_status_; }
  /// What was wrong, for the reply's body and the log.
  const std::string& error() const { return error_; }

 private:
  State fail(int status, std::string message);
  State parse_head(std::string_view head);

  std::size_t max_head_bytes_;
  std::string buffer_;
  std::size_t scanned_ = 0;  ///< bytes of buffer_ already searched for the blank line
  State state_ = State::kIncomplete;
  HttpRequest request_;
  int error_status_ = 0;
  std::string error_;
};

}  // namespace scenewatch::service

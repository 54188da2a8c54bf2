#include "scenewatch/service/http_request.h"

#include <algorithm>
#include <cctype>

namespace scenewatch::service {

namespace {

constexpr std::size_t kMaxHeaders = 100;

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

/// RFC 9110 token characters (method and header names).
bool is_token(std::string_view s) {
  if (s.empty()) return false;
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (std::isalnum(u)) continue;
    if (std::string_view("!#$%&'*+-.^_`|~").find(c) == std::string_view::npos) return false;
  }
  return true;
}

/// Visible ASCII only: no spaces, controls or bytes above 0x7e in a request target.
bool is_target(std::string_view s) {
  if (s.empty() || s.front() != '/') return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return c > 0x20 && c < 0x7f; });
}

/// Splits off the next line (without its "\r\n" or "\n").
std::string_view next_line(std::string_view& rest) {
  const std::size_t end = rest.find('\n');
  std::string_view line = rest.substr(0, end);
  rest.remove_prefix(end == std::string_view::npos ? rest.size() : end + 1);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  return line;
}

/// Calls f(name, value) for each `name[=value]` of a query string.
template <typename F>
void for_each_query(std::string_view query, F&& f) {
  while (!query.empty()) {
    const std::size_t amp = query.find('&');
    std::string_view item = query.substr(0, amp);
    query.remove_prefix(amp == std::string_view::npos ? query.size() : amp + 1);
    const std::size_t eq = item.find('=');
    if (f(item.substr(0, eq), eq == std::string_view::npos ? std::string_view() : item.substr(eq + 1))) return;
  }
}

}  // namespace

std::string HttpRequest::header(std::string_view name) const {
  for (const auto& [key, value] : headers)
    if (iequals(key, name)) return value;
  return {};
}

std::string HttpRequest::query_value(std::string_view name) const {
  std::string out;
  for_each_query(query, [&](std::string_view key, std::string_view value) {
    if (key != name) return false;
    out = std::string(value);
    return true;
  });
  return out;
}

bool HttpRequest::has_query(std::string_view name) const {
  bool found = false;
  for_each_query(query, [&](std::string_view key, std::string_view) { return found = key == name; });
  return found;
}

HttpRequestParser::HttpRequestParser(std::size_t max_head_bytes) : max_head_bytes_(max_head_bytes) {}

HttpRequestParser::State HttpRequestParser::fail(int status, std::string message) {
  state_ = State::kError;
  error_status_ = status;
  error_ = std::move(message);
  buffer_.clear();
  return state_;
}

HttpRequestParser::State HttpRequestParser::feed(std::string_view bytes) {
  if (state_ != State::kIncomplete) return state_;
  // Only what can still belong to the head is kept: one byte past the limit tells "too large".
  const std::size_t room = max_head_bytes_ + 1 - std::min(buffer_.size(), max_head_bytes_ + 1);
  buffer_.append(bytes.substr(0, room));
  // The head ends at the first empty line: "\n\n" or "\n\r\n". Search from a little before the
  // previous end so that a terminator split across feeds is found.
  const std::size_t from = scanned_ >= 2 ? scanned_ - 2 : 0;
  std::size_t end = std::string::npos;
  for (std::size_t i = buffer_.find('\n', from); i != std::string::npos; i = buffer_.find('\n', i + 1)) {
    if (i + 1 < buffer_.size() && buffer_[i + 1] == '\n') {
      end = i + 2;
      break;
    }
    if (i + 2 < buffer_.size() && buffer_[i + 1] == '\r' && buffer_[i + 2] == '\n') {
      end = i + 3;
      break;
    }
  }
  scanned_ = buffer_.size();
  if (end == std::string::npos || end > max_head_bytes_) {
    if (buffer_.size() > max_head_bytes_) {
      return fail(413, "request head larger than " + std::to_string(max_head_bytes_) + " bytes");
    }
    return state_;
  }
  return parse_head(std::string_view(buffer_).substr(0, end));
}

HttpRequestParser::State HttpRequestParser::parse_head(std::string_view head) {
  std::string_view line = next_line(head);
  // Request line: METHOD SP target SP HTTP/x.y
  const std::size_t sp1 = line.find(' ');
  const std::size_t sp2 = sp1 == std::string_view::npos ? sp1 : line.find(' ', sp1 + 1);
  if (sp2 == std::string_view::npos || line.find(' ', sp2 + 1) != std::string_view::npos) {
    return fail(400, "malformed request line (expected 'METHOD /path HTTP/1.1')");
  }
  const std::string_view method = line.substr(0, sp1);
  const std::string_view target = line.substr(sp1 + 1, sp2 - sp1 - 1);
  const std::string_view version = line.substr(sp2 + 1);
  if (!is_token(method)) return fail(400, "malformed method in the request line");
  if (!is_target(target)) return fail(400, "malformed request target (expected an absolute path)");
  if (version.substr(0, 5) != "HTTP/") return fail(400, "malformed HTTP version in the request line");
  if (version != "HTTP/1.1" && version != "HTTP/1.0") return fail(505, "only HTTP/1.0 and HTTP/1.1 are served");
  request_.method = std::string(method);
  request_.target = std::string(target);
  const std::size_t q = target.find('?');
  request_.path = std::string(target.substr(0, q));
  request_.query = q == std::string_view::npos ? std::string() : std::string(target.substr(q + 1));
  request_.version = std::string(version);

  while (!head.empty()) {
    line = next_line(head);
    if (line.empty()) break;
    if (request_.headers.size() == kMaxHeaders) return fail(413, "more than " + std::to_string(kMaxHeaders) + " headers");
    const std::size_t colon = line.find(':');
    if (colon == std::string_view::npos || !is_token(line.substr(0, colon))) {
      return fail(400, "malformed header line");
    }
    const std::string_view value = trim(line.substr(colon + 1));
    if (std::any_of(value.begin(), value.end(), [](char c) { return c == '\r' || c == '\0'; })) {
      return fail(400, "malformed header value");
    }
    request_.headers.emplace_back(std::string(line.substr(0, colon)), std::string(value));
  }
  buffer_.clear();
  state_ = State::kComplete;
  return state_;
}

}  // namespace scenewatch::service

// The live view's HTTP request parser: arbitrary bytes, fed in arbitrary chunks, as a browser's
// (or anyone's) socket delivers them to the HTTP port. Input: byte 0 picks the chunk size (1..64,
// or all at once), the rest is the stream.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "scenewatch/service/http_request.h"

namespace {
using scenewatch::service::HttpRequest;
using scenewatch::service::HttpRequestParser;

bool visible_ascii(std::string_view s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return c > 0x20 && c < 0x7f; });
}

// What a parsed request promises the live view: a token method, an absolute path of visible
// characters without its query, HTTP/1.0 or 1.1, header names without ':' and values without CR or
// NUL; and the look-ups the live view makes never fail.
void check_request(const HttpRequest& r) {
  if (r.method.empty() || !visible_ascii(r.method)) std::abort();
  if (r.path.empty() || r.path[0] != '/' || !visible_ascii(r.path) || r.path.find('?') != std::string::npos) std::abort();
  if (r.target != r.path + (r.target.size() > r.path.size() ? "?" + r.query : "")) std::abort();
  if (r.version != "HTTP/1.0" && r.version != "HTTP/1.1") std::abort();
  for (const auto& [name, value] : r.headers) {
    if (name.empty() || name.find(':') != std::string::npos) std::abort();
    if (value.find('\r') != std::string::npos || value.find('\0') != std::string::npos) std::abort();
  }
  (void)r.header("accept");
  (void)r.query_value("since");
  (void)r.query_value("voxels");
  (void)r.has_query("since");
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::size_t chunk = data[0] == 0 ? size : (data[0] % 64) + 1;
  constexpr std::size_t kMaxHead = 1024;
  HttpRequestParser parser(kMaxHead);
  const std::string_view stream(reinterpret_cast<const char*>(data + 1), size - 1);
  HttpRequestParser::State state = HttpRequestParser::State::kIncomplete;
  std::size_t fed = 0;
  for (std::size_t at = 0; at < stream.size() && state == HttpRequestParser::State::kIncomplete; at += chunk) {
    const std::string_view piece = stream.substr(at, chunk);
    state = parser.feed(piece);
    fed += piece.size();
    if (parser.state() != state) std::abort();
    // A head is answered (complete or refused) by the time more than the cap has arrived.
    if (state == HttpRequestParser::State::kIncomplete && fed > kMaxHead) std::abort();
  }
  if (state == HttpRequestParser::State::kError) {
    const int status = parser.error_status();
    if ((status != 400 && status != 413 && status != 505) || parser.error().empty()) std::abort();
  }
  if (state == HttpRequestParser::State::kComplete) check_request(parser.request());
  // The answer is final: more bytes change nothing.
  if (state != HttpRequestParser::State::kIncomplete && parser.feed("GET / HTTP/1.1\r\n\r\n") != state) std::abort();
  return 0;
}

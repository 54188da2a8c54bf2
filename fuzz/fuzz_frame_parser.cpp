// The wire framing: arbitrary bytes, fed in arbitrary chunks, as a client's socket delivers them.
// Input: byte 0 picks the chunk size (1..64, or all at once), the rest is the stream.
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "scenewatch/service/frame_parser.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using scenewatch::service::FrameParser;
  if (size < 1) return 0;
  const std::size_t chunk = data[0] == 0 ? size : (data[0] % 64) + 1;
  constexpr std::size_t kMaxPayload = 4096;
  FrameParser parser(kMaxPayload);
  const std::string_view stream(reinterpret_cast<const char*>(data + 1), size - 1);
  std::size_t payload_bytes = 0;
  for (std::size_t at = 0; at < stream.size() && !parser.failed(); at += chunk) {
    const auto fed = parser.feed(stream.substr(at, chunk));
    // A failed feed is final; an accepted one never holds more than one frame's bytes.
    if (!fed.ok() && !parser.failed()) std::abort();
    if (parser.buffered_bytes() > kMaxPayload + scenewatch::service::kFrameHeaderBytes) std::abort();
    while (auto payload = parser.next()) {
      if (payload->empty() || payload->size() > kMaxPayload) std::abort();
      // The payload re-encodes to the bytes it came from.
      const std::string framed = scenewatch::service::encode_frame(*payload);
      if (framed.size() != payload->size() + scenewatch::service::kFrameHeaderBytes) std::abort();
      payload_bytes += framed.size();
    }
  }
  if (payload_bytes > stream.size()) std::abort();
  return 0;
}

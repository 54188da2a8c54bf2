#pragma once
// Recognises a live IngestFrame (IngestFrame.live) in a serialized Request without decoding it:
// the wire format is walked field by field and the cloud's bytes are skipped, not copied, so a
// session can look at every frame waiting in its queue for the cost of a few varints each.
#include <cstdint>
#include <string>
#include <string_view>

namespace scenewatch::service {

struct LiveFramePeek {
  bool frame = false;    ///< an IngestFrame, live or not
  bool live = false;     ///< an IngestFrame with live = true
  std::uint64_t id = 0;  ///< the request's id
  std::string token;     ///< the request's access token (Request.token)
};

/// What the payload says; a payload that is not a well-formed Request is not live.
LiveFramePeek peek_live_frame(std::string_view payload);

}  // namespace scenewatch::service

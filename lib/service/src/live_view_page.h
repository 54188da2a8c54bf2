#pragma once
// The live view's page (lib/service/web/live_view.html), embedded in the binary at configure
// time, so the daemon serves it from the build tree and from an install alike.
#include <string_view>

namespace scenewatch::service {

/// The HTML of the page, with its script and style inline.
std::string_view live_view_page();

}  // namespace scenewatch::service

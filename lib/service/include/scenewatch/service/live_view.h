#pragma once
/// The live view in the browser: the one page and its read-only endpoints, answered from the
/// working memory (http_server.h carries them; this side knows no sockets).
///
///   GET /                  the page (embedded in the binary)
///   GET /three.min.js      three.js, read from Debian's libjs-three (LiveViewConfig::three_js)
///   GET /api/state         frames, stats, planes (hulls), objects (boxes, and their class when
///                          LiveViewConfig::classes is set), the last NextBestView's suggested
///                          views (LiveViewConfig::suggested_views), the pending changes (as
///                          GetPendingChanges answers them), occupied voxels (JSON);
///                          (?voxels=0: without the voxels and the classes: the page's cheap poll)
///   GET /api/frame.png     the last colour frame with the surprise heatmap laid over it
///   GET /api/events        the events as they are emitted (Server-Sent Events)
///   GET /api/events?since=N  the logged events with id > N (JSON)
#include <cstddef>
#include <filesystem>
#include <memory>

#include "scenewatch/core/frame.h"
#include "scenewatch/core/result.h"
#include "scenewatch/service/http_server.h"
#include "scenewatch/service/suggested_views.h"

namespace scenewatch::ontology {
class ClassCatalog;
}  // namespace scenewatch::ontology

namespace scenewatch::pipeline {
class WorkingMemory;
struct FrameResult;
}  // namespace scenewatch::pipeline

namespace scenewatch::service {

/// Where libjs-three puts the minified build on Debian 12.
inline constexpr const char* kDefaultThreeJs = "/usr/share/javascript/three/three.min.js";

struct LiveViewConfig {
  std::filesystem::path three_js = kDefaultThreeJs;  ///< served as /three.min.js
  std::size_t max_voxels = 200000;     ///< more occupied voxels are thinned to every k-th
  std::size_t max_backlog_events = 1000;  ///< events per /api/events?since=N answer
  /// The classes the objects are described by in /api/state (each new description is recorded
  /// in the catalog, as GetObjects records it); null: the objects carry no class.
  std::shared_ptr<ontology::ClassCatalog> classes;
  /// The views the last NextBestView answer suggested, drawn as camera frusta; null: none.
  std::shared_ptr<SuggestedViews> suggested_views;
};

/// Thread safe. `memory` must outlive it; it subscribes to the memory's events and unsubscribes
/// in its destructor, so it must go before the memory does.
class LiveView {
 public:
  LiveView(pipeline::WorkingMemory& memory, LiveViewConfig config);
  ~LiveView();
  LiveView(const LiveView&) = delete;
  LiveView& operator=(const LiveView&) = delete;

  /// Keeps the frame (its cloud is shared, not copied) and its surprise for /api/frame.png.
  /// Called after each processed frame, on the processing thread; quick.
  void observe(const Frame& frame, const pipeline::FrameResult& result);

  /// Answers one GET request.
  HttpResponse handle(const HttpRequest& request);

  /// Whether three.js can be read; the message says what to install or configure.
  Status check_three_js() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scenewatch::service

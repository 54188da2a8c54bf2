#pragma once
/// Request dispatch: decodes one Request payload, calls the working memory and encodes the
/// Response payload. Socket-free (the session hands it bytes and sends back bytes), so it is unit
/// tested against a real WorkingMemory; protobuf stays inside its .cpp.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "scenewatch/core/result.h"

namespace scenewatch {
struct Frame;
}  // namespace scenewatch
namespace scenewatch::pipeline {
class WorkingMemory;
struct FrameResult;
}  // namespace scenewatch::pipeline
namespace scenewatch::ontology {
class ClassCatalog;
}  // namespace scenewatch::ontology

namespace scenewatch::service {

class SuggestedViews;

/// What the handler may touch on the server's file system.
struct HandlerConfig {
  std::vector<std::filesystem::path> data_roots;  ///< IngestFile reads only below these
  std::filesystem::path model_dir;                ///< SaveModel / LoadModel target (empty: none)
  std::uint64_t max_file_bytes = 512ull << 20;    ///< IngestFile refuses larger files unread
  std::size_t keep_snapshots = 3;                 ///< SaveModel keeps this many snapshots
  /// Calls that change the model (ingest, clear, reset, save, load) must carry this token; empty:
  /// they need none (in-process use only: scenewatchd always sets one).
  std::string token;
  /// The object classes (DefineClass, ListClasses); null: those calls answer FAILED_PRECONDITION.
  std::shared_ptr<ontology::ClassCatalog> classes;
  /// Where NextBestView answers are recorded for the live view; null: nowhere.
  std::shared_ptr<SuggestedViews> suggested_views;
};

/// The answer to one request.
struct Reply {
  std::string payload;   ///< serialized Response, without the length prefix
  std::string call;      ///< name of the call ("ingest_frame"), for logs
  bool ok = true;        ///< false when the status is an error
  std::string error;     ///< the error message when !ok, for logs
};

/// Per-connection state the handler may use: where pushed events go once subscribed.
struct SessionContext {
  /// Receives each event as a serialized Response (id 0). Called on the processing thread: it
  /// must only hand the bytes over (post them to the connection), never block.
  std::function<void(std::string payload)> event_sink;
  int subscription = -1;  ///< WorkingMemory subscription token, -1 when not subscribed
};

/// Sees each frame an ingest call processed, with what it produced (the live view keeps the last
/// one's colour). Called on the processing thread: it must be quick.
using FrameObserver = std::function<void(const Frame& frame, const pipeline::FrameResult& result)>;

/// Runs a piece of work somewhere (a worker thread, a strand); the default runs it inline.
using Executor = std::function<void(std::function<void()> task)>;

/// Thread safe. Cheap calls (Health, GetPlanes, GetObjects, GetEvents, Subscribe) are answered
/// on the calling thread; calls that may wait for a frame being processed run on `query`
/// (QueryOccupancy, Stats) and calls that change the model on `mutate` (ingest, clear, reset,
/// save, load, define class), which must run one task at a time. `memory` must outlive the handler, and the
/// handler must outlive every task it gave to an executor.
class RequestHandler {
 public:
  /// Empty executors run their calls inline.
  RequestHandler(pipeline::WorkingMemory& memory, HandlerConfig config, Executor mutate = {},
                 Executor query = {});
  ~RequestHandler();
  RequestHandler(const RequestHandler&) = delete;
  RequestHandler& operator=(const RequestHandler&) = delete;

  /// Handles one request payload; `done` is called exactly once, on the calling thread or on an
  /// executor's thread. `context` is only used before handle() returns.
  void handle(std::string payload, SessionContext& context, std::function<void(Reply)> done);

  /// True when the payload is an IngestFrame (live or not), read without decoding it.
  bool is_ingest_frame(std::string_view payload) const;
  /// True when the payload is a live IngestFrame (IngestFrame.live) carrying the right token, read
  /// without decoding it.
  bool is_live_frame(std::string_view payload) const;
  /// The answer to a live frame that a newer live frame of its connection supersedes: OK with
  /// IngestReply.skipped, nothing processed; counted in Stats.frames_skipped. Thread safe.
  Reply skip_live_frame(std::string_view payload);
  /// Handles one request synchronously on the calling thread, ignoring the executors.
  Reply handle_now(const std::string& payload, SessionContext& context);

  /// Ends a connection's subscription, if any. Thread safe.
  void unsubscribe(SessionContext& context);

  /// A connection-level error Response (id 0, no result), e.g. for a broken framing.
  std::string error_payload(ErrorCode code, const std::string& message) const;

  /// Counts connected clients for Stats; set before serving.
  void set_connection_counter(std::function<std::size_t()> counter);

  /// Sees each processed frame; set before serving.
  void set_frame_observer(FrameObserver observer);

  /// From now on, requests that change the model (also those already queued) are answered
  /// UNAVAILABLE because the server is stopping. Thread safe.
  void shutdown();

  /// The configuration, with data roots canonicalised.
  const HandlerConfig& config() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scenewatch::service

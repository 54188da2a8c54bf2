#pragma once
// RequestHandler's state and its calls, one method a call. Private to the service: the methods are
// defined by concept in request_handler.cpp (decode, route, reply), request_handler_frames.cpp
// (ingest), request_handler_queries.cpp (reads) and request_handler_model.cpp (save, load, classes).
#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "localization_notices.h"
#include "scenewatch.pb.h"
#include "scenewatch/core/files.h"
#include "scenewatch/core/result.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/service/request_handler.h"

namespace scenewatch::service {

inline Error permission_denied(std::string message) { return {ErrorCode::kPermissionDenied, std::move(message)}; }
inline Error unavailable(std::string message) { return {ErrorCode::kUnavailable, std::move(message)}; }

/// Thread safety as RequestHandler's: the calls run on the executors the daemon gave it.
struct RequestHandler::Impl {
  pipeline::WorkingMemory& memory;
  HandlerConfig config;
  Executor mutate, query;
  std::function<std::size_t()> connections;
  FrameObserver frame_observer;
  std::atomic<bool> stopping{false};
  std::atomic<std::uint64_t> frames_skipped{0};  // live frames superseded by newer ones
  LocalizationNotices localization_notices;
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();

  Impl(pipeline::WorkingMemory& m, HandlerConfig c, Executor mu, Executor q);

  double uptime_s() const;

  // --- request_handler.cpp
  /// Decodes a request and runs it inline or on its executor; see RequestHandler::handle().
  void handle(std::string payload, SessionContext& context, std::function<void(Reply)> done, bool use_executors);
  /// Runs one call and encodes its response. `context` is null off the connection's thread;
  /// `decoded`, when given, is the request's IngestFrame decoded already.
  Reply execute(const proto::Request& request, SessionContext* context, const Result<Frame>* decoded = nullptr);
  /// Calls the method of the request's call.
  Status dispatch(const proto::Request& request, SessionContext* context, proto::Response& response,
                  const Result<Frame>* decoded);

  // --- request_handler_frames.cpp
  /// The frame of an IngestFrame message, checked (cloud, pose, intrinsics, stamp, mode).
  static Result<Frame> decode_frame(const proto::IngestFrame& msg);
  static Result<Frame> decode_rgbd_frame(const proto::IngestFrame& msg);
  Status ingest_frame(const proto::IngestFrame& msg, proto::Response& response);
  Status get_surprise_map(const proto::GetSurpriseMap& msg, proto::Response& response);
  /// Opens a client's absolute path beneath the data root it names.
  Result<FileBeneath> open_under_roots(const std::filesystem::path& requested) const;
  Status ingest_file(const proto::IngestFile& msg, proto::Response& response);
  /// Processes one frame in the memory and fills the IngestReply.
  Status process(const Frame& frame, proto::Response& response);

  // --- request_handler_queries.cpp
  Status health(proto::Response& response);
  Status stats(proto::Response& response);
  Status get_localization(const proto::GetLocalization& msg, proto::Response& response);
  Status get_planes(proto::Response& response);
  Status get_map(proto::Response& response);
  Status get_objects(const proto::GetObjects& msg, proto::Response& response);
  Status get_hands(proto::Response& response);
  Status get_pending_changes(proto::Response& response);
  Status query_occupancy(const proto::QueryOccupancy& msg, proto::Response& response);
  static proto::OccupancyState to_proto(background::Occupancy state);
  Status subscribe(SessionContext* context, proto::Response& response);
  Status get_events(const proto::GetEvents& msg, proto::Response& response);

  // --- request_handler_model.cpp
  Status clear_box(const proto::ClearBox& msg, proto::Response& response);
  Status require_model_dir() const;
  Status save_model(proto::Response& response);
  Status load_model(proto::Response& response);
  Status require_classes() const;
  Status define_class(const proto::DefineClass& msg, proto::Response& response);
  Status list_classes(proto::Response& response);
};

}  // namespace scenewatch::service

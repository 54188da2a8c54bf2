#include "scenewatch/service/request_handler.h"

// The handler's front: decoding a request, routing it to its executor, the token check, and
// encoding the reply. The calls themselves are in request_handler_frames.cpp (ingest),
// request_handler_queries.cpp (reads) and request_handler_model.cpp (save, load, classes).
#include <chrono>
#include <exception>
#include <system_error>

#include "live_frame.h"
#include "next_best_view_call.h"
#include "proto_convert.h"
#include "request_handler_impl.h"
#include "scenewatch/service/access_token.h"
#include "scenewatch/pipeline/working_memory.h"

namespace scenewatch::service {
namespace fs = std::filesystem;

namespace {

/// Where a call runs: see the class comment of RequestHandler.
enum class Route { kInline, kQuery, kMutate };

Route route_of(proto::Request::CallCase call) {
  switch (call) {
    case proto::Request::kQueryOccupancy:
    case proto::Request::kStats:
    case proto::Request::kGetLocalization:
    case proto::Request::kGetSurpriseMap:
    case proto::Request::kNextBestView:
    case proto::Request::kGetMap:
      return Route::kQuery;
    case proto::Request::kIngestFrame:
    case proto::Request::kIngestFile:
    case proto::Request::kClearBox:
    case proto::Request::kReset:
    case proto::Request::kSaveModel:
    case proto::Request::kLoadModel:
    case proto::Request::kDefineClass:
      return Route::kMutate;
    default:
      return Route::kInline;
  }
}

/// Name of the request's call as in the .proto ("ingest_frame"), for messages and logs.
std::string call_name(const proto::Request& request) {
  if (request.call_case() == proto::Request::CALL_NOT_SET) return "none";
  const auto* field = proto::Request::descriptor()->FindFieldByNumber(request.call_case());
  return field != nullptr ? field->name() : "unknown";
}

/// Absolute, symlink-resolved, without a trailing separator.
fs::path canonical_root(const fs::path& root) {
  std::error_code ec;
  fs::path out = fs::weakly_canonical(fs::absolute(root, ec), ec);
  if (ec) out = fs::absolute(root).lexically_normal();
  if (!out.has_filename() && out.has_relative_path()) out = out.parent_path();
  return out;
}

Reply finish(proto::Response& response, std::string call) {
  Reply reply;
  reply.call = std::move(call);
  reply.ok = response.status().code() == proto::Status::OK;
  if (!reply.ok) reply.error = response.status().message();
  response.SerializeToString(&reply.payload);
  return reply;
}

Reply error_reply(std::uint64_t id, proto::Status::Code code, const std::string& message, std::string call) {
  proto::Response response;
  response.set_id(id);
  response.mutable_status()->set_code(code);
  response.mutable_status()->set_message(convert::valid_utf8(message));
  return finish(response, std::move(call));
}

}  // namespace

RequestHandler::Impl::Impl(pipeline::WorkingMemory& m, HandlerConfig c, Executor mu, Executor q)
    : memory(m), config(std::move(c)), mutate(std::move(mu)), query(std::move(q)) {
  for (auto& root : config.data_roots) root = canonical_root(root);
}

double RequestHandler::Impl::uptime_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
}

void RequestHandler::Impl::handle(std::string payload, SessionContext& context, std::function<void(Reply)> done,
                                  bool use_executors) {
  auto request = std::make_shared<proto::Request>();
  if (!request->ParseFromString(payload)) {
    done(error_reply(0, proto::Status::INVALID_ARGUMENT,
                     "request of " + std::to_string(payload.size()) +
                         " bytes is not a valid scenewatch.proto.Request message",
                     "unparseable"));
    return;
  }
  if (request->call_case() == proto::Request::CALL_NOT_SET) {
    done(error_reply(request->id(), proto::Status::UNKNOWN_REQUEST,
                     "request " + std::to_string(request->id()) +
                         " has no call set (empty, or a call this server does not know)",
                     "none"));
    return;
  }
  payload = std::string();  // an ingest payload can be large: free it before the work is queued
  const Route route = route_of(request->call_case());
  if (route == Route::kMutate && !config.token.empty() && !tokens_equal(request->token(), config.token)) {
    const std::string call = call_name(*request);
    done(error_reply(request->id(), proto::Status::PERMISSION_DENIED,
                     call + ": this call changes the model and needs the daemon's token (Request.token, the "
                     "contents of the daemon's token file; the CLI reads it with --token-file): " +
                         (request->token().empty() ? std::string("the request carries none")
                                                   : std::string("the request's token is wrong")),
                     call));
    return;
  }
  const Executor& executor = route == Route::kMutate ? mutate : query;
  if (!use_executors || route == Route::kInline || !executor) {
    done(execute(*request, &context));
    return;
  }
  if (request->call_case() == proto::Request::kIngestFrame) {
    // Decoded here, on the connection's thread, while the frame before it may still be
    // processing on the model's strand (a client may send the next frame before the reply).
    auto frame = std::make_shared<const Result<Frame>>(decode_frame(request->ingest_frame()));
    executor([this, request, frame, done = std::move(done)] { done(execute(*request, nullptr, frame.get())); });
    return;
  }
  executor([this, request, done = std::move(done)] { done(execute(*request, nullptr)); });
}

Reply RequestHandler::Impl::execute(const proto::Request& request, SessionContext* context, const Result<Frame>* decoded) {
  proto::Response response;
  response.set_id(request.id());
  std::string call = call_name(request);
  Status status;
  try {
    status = dispatch(request, context, response, decoded);
  } catch (const std::exception& e) {
    // A bug or out of memory: answer the client, keep serving the others.
    status = Error{ErrorCode::kInternal, std::string("unexpected exception: ") + e.what()};
  }
  if (!status) {
    response.clear_result();
    const Error& e = status.error();
    response.mutable_status()->set_code(convert::to_proto(e.code));
    response.mutable_status()->set_message(convert::valid_utf8(call + ": " + e.message));
  }
  return finish(response, std::move(call));
}

Status RequestHandler::Impl::dispatch(const proto::Request& request, SessionContext* context,
                                      proto::Response& response, const Result<Frame>* decoded) {
  if (route_of(request.call_case()) == Route::kMutate && stopping) {
    return unavailable("the server is shutting down");
  }
  switch (request.call_case()) {
    case proto::Request::kHealth: return health(response);
    case proto::Request::kStats: return stats(response);
    case proto::Request::kIngestFrame:
      if (decoded == nullptr) return ingest_frame(request.ingest_frame(), response);
      if (!*decoded) return decoded->error();
      return process(**decoded, response);
    case proto::Request::kIngestFile: return ingest_file(request.ingest_file(), response);
    case proto::Request::kGetPlanes: return get_planes(response);
    case proto::Request::kGetObjects: return get_objects(request.get_objects(), response);
    case proto::Request::kGetHands: return get_hands(response);
    case proto::Request::kGetPendingChanges: return get_pending_changes(response);
    case proto::Request::kQueryOccupancy: return query_occupancy(request.query_occupancy(), response);
    case proto::Request::kClearBox: return clear_box(request.clear_box(), response);
    case proto::Request::kReset:
      memory.reset();
      localization_notices.forget_cameras();
      response.mutable_reset();
      return {};
    case proto::Request::kSaveModel: return save_model(response);
    case proto::Request::kLoadModel: return load_model(response);
    case proto::Request::kSubscribe: return subscribe(context, response);
    case proto::Request::kGetEvents: return get_events(request.get_events(), response);
    case proto::Request::kGetSurpriseMap: return get_surprise_map(request.get_surprise_map(), response);
    case proto::Request::kDefineClass: return define_class(request.define_class(), response);
    case proto::Request::kListClasses: return list_classes(response);
    case proto::Request::kGetLocalization: return get_localization(request.get_localization(), response);
    case proto::Request::kGetMap: return get_map(response);
    case proto::Request::kNextBestView:
      return service::next_best_view(memory, request.next_best_view(), config.classes.get(), response.mutable_next_best_view(),
                                     config.suggested_views.get());
    case proto::Request::CALL_NOT_SET: break;
  }
  // Not reached for a known call: the empty oneof is answered by the caller.
  return Error{ErrorCode::kInternal, "unhandled call"};
}

RequestHandler::RequestHandler(pipeline::WorkingMemory& memory, HandlerConfig config, Executor mutate,
                               Executor query)
    : impl_(std::make_unique<Impl>(memory, std::move(config), std::move(mutate), std::move(query))) {}

RequestHandler::~RequestHandler() = default;

void RequestHandler::handle(std::string payload, SessionContext& context, std::function<void(Reply)> done) {
  impl_->handle(std::move(payload), context, std::move(done), /*use_executors=*/true);
}

bool RequestHandler::is_ingest_frame(std::string_view payload) const { return peek_live_frame(payload).frame; }

bool RequestHandler::is_live_frame(std::string_view payload) const {
  // A frame without the right token is not skipped: it is refused like any other.
  const LiveFramePeek peek = peek_live_frame(payload);
  return peek.live && (impl_->config.token.empty() || tokens_equal(peek.token, impl_->config.token));
}

Reply RequestHandler::skip_live_frame(std::string_view payload) {
  proto::Response response;
  response.set_id(peek_live_frame(payload).id);
  auto* out = response.mutable_ingest();
  out->set_skipped(true);
  out->set_frames_skipped(++impl_->frames_skipped);
  return finish(response, "ingest_frame (live, skipped: a newer frame was waiting)");
}

Reply RequestHandler::handle_now(const std::string& payload, SessionContext& context) {
  Reply out;
  impl_->handle(payload, context, [&out](Reply reply) { out = std::move(reply); }, /*use_executors=*/false);
  return out;
}

void RequestHandler::unsubscribe(SessionContext& context) {
  if (context.subscription >= 0) {
    impl_->memory.unsubscribe(context.subscription);
    impl_->localization_notices.remove(context.subscription);
    context.subscription = -1;
  }
}

std::string RequestHandler::error_payload(ErrorCode code, const std::string& message) const {
  return error_reply(0, convert::to_proto(code), message, "connection").payload;
}

void RequestHandler::set_frame_observer(FrameObserver observer) { impl_->frame_observer = std::move(observer); }

void RequestHandler::set_connection_counter(std::function<std::size_t()> counter) {
  impl_->connections = std::move(counter);
}

void RequestHandler::shutdown() { impl_->stopping = true; }

const HandlerConfig& RequestHandler::config() const { return impl_->config; }

}  // namespace scenewatch::service

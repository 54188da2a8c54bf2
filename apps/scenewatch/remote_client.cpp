// Connecting to the daemon and making one call, for the commands that talk to it.
#include "remote_client.h"

#include <iostream>

#include "scenewatch/service/client.h"

namespace scenewatch::cli {
namespace {

constexpr double kConnectTimeoutS = 5.0;

/// Why the token could not be read (empty when it was), for the message of a refused call.
std::string g_token_problem;

}  // namespace

// Connects and, when the token file can be read, sends its token with the calls that need it.
Result<service::Client> connect_remote(const RemoteOptions& options) {
  auto client = service::Client::connect(options.host, static_cast<std::uint16_t>(options.port), kConnectTimeoutS);
  if (!client) return client;
  auto token = service::read_token_file(options.token_file);
  if (token) {
    client->set_token(std::move(*token));
  } else {
    g_token_problem = token.error().message;
  }
  return client;
}

std::string refusal(const proto::Status& status) {
  std::string message = service::to_string(status.code()) + ": " + status.message();
  if (status.code() == proto::Status::PERMISSION_DENIED && !g_token_problem.empty()) {
    message += " (no token sent: " + g_token_problem + ")";
  }
  return message;
}

std::optional<proto::Response> call(service::Client& client, proto::Request request, const RemoteOptions& options) {
  auto response = client.call(std::move(request), options.timeout_s);
  if (!response) {
    fail(response.error().message);
    return std::nullopt;
  }
  if (response->status().code() != proto::Status::OK) {
    fail(refusal(response->status()));
    return std::nullopt;
  }
  return std::move(*response);
}

int simple_call(const RemoteOptions& options, proto::Request request,
                const std::function<void(const proto::Response&)>& print) {
  auto client = connect_remote(options);
  if (!client) return fail(client.error().message);
  auto response = call(*client, std::move(request), options);
  if (!response) return kExitError;
  print(*response);
  return kExitOk;
}

void print_json(const nlohmann::json& j) { std::cout << j.dump(2) << std::endl; }

void set_box(proto::Box* out, const std::vector<double>& box) {
  out->mutable_min()->set_x(box[0]);
  out->mutable_min()->set_y(box[1]);
  out->mutable_min()->set_z(box[2]);
  out->mutable_max()->set_x(box[3]);
  out->mutable_max()->set_y(box[4]);
  out->mutable_max()->set_z(box[5]);
}

std::string plural(std::size_t n, const std::string& word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

Result<RemoteSurprise> fetch_surprise(const RemoteOptions& options, const Frame* observed) {
  auto client = connect_remote(options);
  if (!client) return client.error();
  proto::Request request;
  auto* msg = request.mutable_get_surprise_map();
  if (observed) *msg->mutable_frame() = service::make_ingest_frame(*observed);
  auto response = client->call(std::move(request), options.timeout_s);
  if (!response) return response.error();
  if (response->status().code() != proto::Status::OK) {
    const auto code = response->status().code() == proto::Status::NOT_FOUND ? ErrorCode::kNotFound : ErrorCode::kInvalidArgument;
    return Error{code, service::to_string(response->status().code()) + ": " + response->status().message()};
  }
  if (!response->has_surprise_map()) return Error{ErrorCode::kInternal, "the daemon answered without a surprise map"};
  const auto& reply = response->surprise_map();
  RemoteSurprise out;
  out.width = static_cast<int>(reply.width());
  out.height = static_cast<int>(reply.height());
  auto total = service::decode_float_map(reply.total(), static_cast<std::size_t>(out.width) * out.height, "surprise_map.total");
  if (!total) return total.error();
  out.total = std::move(*total);
  out.known_pixels = reply.known_pixels();
  out.reference_views = reply.reference_views();
  out.regions.assign(reply.regions().begin(), reply.regions().end());
  out.compute_ms = reply.compute_ms();
  return out;
}

}  // namespace scenewatch::cli

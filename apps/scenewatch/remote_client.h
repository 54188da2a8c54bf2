#pragma once
// What the commands that talk to the daemon share: connecting with the token, one call with its
// error printed, and the small pieces of their output.
#include <functional>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "format.h"

namespace scenewatch::cli {

/// The daemon's message, with why no token was sent when it asked for one.
std::string refusal(const proto::Status& status);

/// Sends one request; prints the problem and returns nothing on a transport error or an error
/// status.
std::optional<proto::Response> call(service::Client& client, proto::Request request, const RemoteOptions& options);

/// Connects, makes one call and prints its result with `print`.
int simple_call(const RemoteOptions& options, proto::Request request,
                const std::function<void(const proto::Response&)>& print);

void print_json(const nlohmann::json& j);

/// A reply's list of messages (planes, objects, events, ...): with `json`, `fields` and under `key`
/// each item's to_json(); else `headline`, then each item's text() on a line of its own.
template <typename Items>
void print_list(bool json, nlohmann::json fields, const std::string& key, const Items& items, const std::string& headline) {
  if (json) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& item : items) list.push_back(to_json(item));
    fields[key] = std::move(list);
    return print_json(fields);
  }
  std::cout << headline << "\n";
  for (const auto& item : items) std::cout << text(item) << "\n";
  std::cout << std::flush;
}

/// MINX MINY MINZ MAXX MAXY MAXZ into `out`.
void set_box(proto::Box* out, const std::vector<double>& box);

/// "1 frame", "2 frames".
std::string plural(std::size_t n, const std::string& word);

}  // namespace scenewatch::cli

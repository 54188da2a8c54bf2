// The daemon's events: those in its log, and those it pushes as they happen (watch).
#include <signal.h>

#include <iostream>
#include <memory>

#include "commands.h"
#include "format.h"
#include "remote_client.h"
#include "subcommand.h"

namespace scenewatch::cli {
using nlohmann::json;

namespace {

volatile sig_atomic_t g_interrupted = 0;

void on_interrupt(int) { g_interrupted = 1; }

}  // namespace

int run_events(const RemoteOptions& options, std::uint64_t since, std::uint32_t max_count) {
  proto::Request request;
  request.mutable_get_events()->set_since(since);
  request.mutable_get_events()->set_max_count(max_count);
  return simple_call(options, request, [&](const proto::Response& r) {
    print_list(options.json, json::object(), "events", r.events().events(),
               plural(r.events().events_size(), "event") + (since > 0 ? " after " + std::to_string(since) : ""));
  });
}

int run_watch(const RemoteOptions& options) {
  auto client = connect_remote(options);
  if (!client) return fail(client.error().message);
  proto::Request request;
  request.mutable_subscribe();
  auto response = call(*client, std::move(request), options);
  if (!response) return kExitError;

  // Ctrl-C ends the wait (no SA_RESTART: the blocking poll returns EINTR).
  struct sigaction action {};
  action.sa_handler = on_interrupt;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);
  if (!options.json) {
    std::cerr << "watching events of " << client->endpoint() << " (after event "
              << response->subscribe().last_event_id() << "); Ctrl-C to stop" << std::endl;
  }
  while (!g_interrupted) {
    auto pushed = client->next_pushed();
    if (!pushed) {
      if (g_interrupted) break;
      return fail(pushed.error().message);
    }
    if (pushed->has_event()) {
      std::cout << (options.json ? to_json(pushed->event()).dump() : text(pushed->event()).substr(2)) << std::endl;
      continue;
    }
    // A camera whose localization state changed (lost, found, homed).
    for (const auto& camera : pushed->localization().cameras()) {
      if (options.json) {
        std::cout << nlohmann::json{{"localization", to_json(camera)}}.dump() << std::endl;
      } else {
        const std::string line = text(camera);
        std::cout << "localization: " << line.substr(0, line.find('\n')) << std::endl;
      }
    }
  }
  return kExitOk;
}

void add_event_commands(CLI::App& app, RemoteOptions& remote, Action& action) {
  struct Range {
    std::uint64_t since = 0;
    std::uint32_t max_count = 0;
  };
  auto range = std::make_shared<Range>();
  auto* events = app.add_subcommand("events", "events from the daemon's log");
  events->add_option("--since", range->since, "only events with a larger id")->capture_default_str();
  events->add_option("--max", range->max_count, "at most this many (0: the daemon's default, 1000)");
  add_remote_options(events, remote);
  on_parsed(events, action, [&remote, range] { return run_events(remote, range->since, range->max_count); });

  add_daemon_command(app, "watch",
                     "print events as they happen until Ctrl-C (--json: one per line), and each change of a camera's "
                     "localization state (lost, found, homed; --json: {\"localization\": ...})",
                     remote, action, run_watch);
}

}  // namespace scenewatch::cli

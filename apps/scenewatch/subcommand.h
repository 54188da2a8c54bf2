#pragma once
// How a subcommand joins the scenewatch CLI: each file that runs a command also adds it (its
// options, help texts and footer) to the CLI11 app, through one add_*_command(s) function; main
// calls them in the order below, which is the order `scenewatch --help` lists the commands in.
#include <CLI/CLI.hpp>

#include <functional>
#include <optional>

#include "commands.h"

namespace scenewatch::cli {

/// What the command given on the command line runs, set by its callback once parsing succeeded.
using Action = std::function<int()>;

/// Sets `action` to `run` when `command` is the one parsed.
void on_parsed(CLI::App* command, Action& action, Action run);

/// --host, --port, --timeout, --json and --token-file, into `options`.
void add_remote_options(CLI::App* command, RemoteOptions& options);
/// The flags of the commands that read ROS bags (replay, ingest, fit): topics and TF frames.
void add_bag_options(CLI::App* command, io::BagOptions& bag);
/// --depth-scale for every command that reads RGB-D sequence folders.
void add_depth_scale_option(CLI::App* command, std::optional<double>& depth_scale_m);
/// A daemon command with no flags but the daemon's: `run(remote)` when it is the one parsed.
void add_daemon_command(CLI::App& app, const std::string& name, const std::string& description, RemoteOptions& remote,
                        Action& action, int (*run)(const RemoteOptions&));

// In the order of `scenewatch --help`. `remote`: the daemon flags, one set shared with the
// top-level app (`scenewatch --port 7879 health` as well as `scenewatch health --port 7879`).

/// health, stats, localization (remote_queries.cpp).
void add_status_commands(CLI::App& app, RemoteOptions& remote, Action& action);
/// ingest, live or not (remote_frames.cpp).
void add_ingest_command(CLI::App& app, RemoteOptions& remote, Action& action);
/// planes, objects, hands, occupancy (remote_queries.cpp).
void add_scene_commands(CLI::App& app, RemoteOptions& remote, Action& action);
/// clear-box (remote_model.cpp).
void add_clear_box_command(CLI::App& app, RemoteOptions& remote, Action& action);
/// classes, define-class (remote_classes.cpp).
void add_class_commands(CLI::App& app, RemoteOptions& remote, Action& action);
/// reset, save, load (remote_model.cpp).
void add_model_commands(CLI::App& app, RemoteOptions& remote, Action& action);
/// events, watch (remote_events.cpp).
void add_event_commands(CLI::App& app, RemoteOptions& remote, Action& action);
/// pending (remote_pending.cpp).
void add_pending_command(CLI::App& app, RemoteOptions& remote, Action& action);
/// next-view (remote_next_view.cpp).
void add_next_view_command(CLI::App& app, RemoteOptions& remote, Action& action);
/// segment (segment_command.cpp).
void add_segment_command(CLI::App& app, Action& action);
/// fit (fit_command.cpp).
void add_fit_command(CLI::App& app, Action& action);
/// diff (diff_command.cpp).
void add_diff_command(CLI::App& app, Action& action);
/// replay, of recordings or of a scenario script (replay_command.cpp).
void add_replay_command(CLI::App& app, Action& action);
/// surprise, offline or from the daemon (surprise_command.cpp).
void add_surprise_command(CLI::App& app, RemoteOptions& remote, Action& action);

}  // namespace scenewatch::cli

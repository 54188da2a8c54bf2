// scenewatch: the command-line client of scenewatchd, plus offline tools that work on files.
// Each command adds itself (options, help) from the file that runs it; see subcommand.h.
#include <CLI/CLI.hpp>

#include "commands.h"
#include "subcommand.h"

int main(int argc, char** argv) {
  using namespace scenewatch::cli;
  CLI::App app{"scenewatch - talk to the scenewatchd perception service, or work on cloud files offline.\n"
               "Exit codes: 0 ok, 1 error (message on stderr), 2 usage."};
  app.set_version_flag("--version", "scenewatch " SCENEWATCH_VERSION);
  app.require_subcommand(1);
  RemoteOptions remote;
  // Accepted before the command too: `scenewatch --port 7879 health` as well as `scenewatch health --port 7879`.
  add_remote_options(&app, remote);
  Action action;

  // In this order in `scenewatch --help`.
  add_status_commands(app, remote, action);  // health, stats, localization
  add_ingest_command(app, remote, action);
  add_scene_commands(app, remote, action);   // planes, objects, hands, occupancy
  add_clear_box_command(app, remote, action);
  add_class_commands(app, remote, action);   // classes, define-class
  add_model_commands(app, remote, action);   // reset, save, load
  add_event_commands(app, remote, action);   // events, watch
  add_pending_command(app, remote, action);
  add_next_view_command(app, remote, action);
  add_segment_command(app, action);
  add_fit_command(app, action);
  add_diff_command(app, action);
  add_replay_command(app, action);
  add_surprise_command(app, remote, action);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return action ? action() : kExitUsage;
}

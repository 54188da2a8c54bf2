// pending: the changes the daemon has seen but not yet confirmed (GetPendingChanges), each a
// target of `next-view --pending ID` until it is confirmed or dropped.
#include "commands.h"
#include "remote_client.h"
#include "subcommand.h"

namespace scenewatch::cli {

int run_pending(const RemoteOptions& options) {
  proto::Request request;
  request.mutable_get_pending_changes();
  return simple_call(options, request, [&](const proto::Response& r) {
    const auto& pending = r.pending_changes();
    print_list(options.json, {{"frames_processed", pending.frames_processed()}}, "changes", pending.changes(),
               plural(pending.changes_size(), "pending change") + " after " + plural(pending.frames_processed(), "frame"));
  });
}

void add_pending_command(CLI::App& app, RemoteOptions& remote, Action& action) {
  add_daemon_command(app, "pending",
                     "changes seen but not yet confirmed (not yet events): id, kind, box, frames seen of those needed; "
                     "look at one with next-view --pending ID",
                     remote, action, run_pending);
}

}  // namespace scenewatch::cli

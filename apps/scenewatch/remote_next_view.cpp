// next-view: where to look next, the camera poses that would see most of a target's unknown side.
#include <iostream>
#include <memory>

#include "commands.h"
#include "format.h"
#include "remote_client.h"
#include "subcommand.h"

namespace scenewatch::cli {
using nlohmann::json;

int run_next_view(const RemoteOptions& options, const NextViewOptions& next) {
  proto::Request request;
  auto* q = request.mutable_next_best_view();
  if (next.object_id) q->set_object_id(*next.object_id);
  if (next.event_id) q->set_event_id(*next.event_id);
  if (next.pending_id) q->set_pending_id(*next.pending_id);
  if (next.box.size() == 6) set_box(q->mutable_box(), next.box);
  if (next.workspace) q->set_workspace(true);
  q->set_measure(next.measure);
  q->set_n(next.n);
  q->set_radius_m(next.radius_m);
  return simple_call(options, request, [&](const proto::Response& r) {
    const auto& reply = r.next_best_view();
    if (options.json) {
      json views = json::array();
      for (const auto& v : reply.views()) {
        views.push_back({{"pose", to_json(v.pose())},
                         {"score", v.score()},
                         {"expected_coverage", v.expected_coverage()},
                         {"unknown_voxels", v.unknown_voxels()},
                         {"rear_side_voxels", v.rear_side_voxels()},
                         {"motion_m", v.motion_m()},
                         {"why", v.why()}});
      }
      return print_json({{"views", std::move(views)},
                         {"target", to_json(reply.target())},
                         {"target_description", reply.target_description()},
                         {"measure", reply.measure()},
                         {"coverage", reply.coverage()},
                         {"target_voxels", reply.target_voxels()},
                         {"candidates", reply.candidates()}});
    }
    std::cout << "target " << text(reply.target().min()) << " .. " << text(reply.target().max()) << ", " << reply.target_voxels()
              << " voxels, coverage " << reply.coverage() << "; " << reply.candidates() << " candidates by " << reply.measure()
              << "\n";
    if (!reply.target_description().empty()) std::cout << "   (" << reply.target_description() << ")\n";
    for (int i = 0; i < reply.views_size(); ++i) {
      const auto& v = reply.views(i);
      const auto& m = v.pose().matrix();
      std::cout << i + 1 << ". camera at (" << m[3] << ", " << m[7] << ", " << m[11] << ") score " << v.score()
                << ", expected coverage " << v.expected_coverage() << "\n   " << v.why() << "\n";
    }
    std::cout << std::flush;
  });
}

void add_next_view_command(CLI::App& app, RemoteOptions& remote, Action& action) {
  struct Target {
    NextViewOptions next_view;
    std::uint64_t object = 0, event = 0, pending = 0;
  };
  auto target = std::make_shared<Target>();
  NextViewOptions& next_view = target->next_view;
  auto* next = app.add_subcommand("next-view", "where to look next: camera poses that would see most of a target's unknown side");
  auto* object_opt = next->add_option("--object", target->object, "a tracked object's id (complete its model)");
  auto* event_opt = next->add_option("--event", target->event, "an event's id (confirm or dismiss it)");
  auto* pending_opt = next->add_option("--pending", target->pending,
                                       "a pending change's id (`scenewatch pending`: seen, not yet confirmed; confirm or "
                                       "dismiss it)");
  auto* box_opt = next->add_option("--box", next_view.box, "MINX MINY MINZ MAXX MAXY MAXZ (world)")->expected(6);
  auto* workspace_opt = next->add_flag("--workspace", next_view.workspace, "every tracked object");
  next->add_option("--measure", next_view.measure,
                   "unobserved, rear_side, rear_side_entropy, occlusion_aware, visible; or the seed's planner for --object: "
                   "covariance (rule 3.23), covariance_321, covariance_322 (one view on the --radius sphere)");
  next->add_option("-n", next_view.n, "views to return")->capture_default_str()->check(CLI::Range(1, 1000));
  next->add_option("--radius", next_view.radius_m, "distance from the target's centre, m (0: the daemon's 0.7)");
  add_remote_options(next, remote);
  on_parsed(next, action, [&remote, target, object_opt, event_opt, pending_opt, box_opt, workspace_opt] {
    // count() is the number of values given (six for --box), not of times the option was named.
    const int targets = (object_opt->count() > 0) + (event_opt->count() > 0) + (pending_opt->count() > 0) +
                        (box_opt->count() > 0) + (workspace_opt->count() > 0);
    if (targets != 1) {
      std::cerr << "scenewatch next-view: give exactly one of --object, --event, --pending, --box, --workspace\n";
      return kExitUsage;
    }
    if (object_opt->count()) target->next_view.object_id = target->object;
    if (event_opt->count()) target->next_view.event_id = target->event;
    if (pending_opt->count()) target->next_view.pending_id = target->pending;
    return run_next_view(remote, target->next_view);
  });
}

}  // namespace scenewatch::cli

// Commands that change the daemon's model: clear a box, forget everything, save and load it.
#include <iostream>
#include <memory>
#include <vector>

#include "commands.h"
#include "remote_client.h"
#include "subcommand.h"

namespace scenewatch::cli {

int run_clear_box(const RemoteOptions& options, const std::vector<double>& box) {
  proto::Request request;
  set_box(request.mutable_clear_box()->mutable_box(), box);
  return simple_call(options, request, [&](const proto::Response& r) {
    if (options.json) return print_json({{"voxels_changed", r.clear_box().voxels_changed()}});
    std::cout << "cleared: " << plural(r.clear_box().voxels_changed(), "voxel") << " changed" << std::endl;
  });
}

int run_reset(const RemoteOptions& options) {
  proto::Request request;
  request.mutable_reset();
  return simple_call(options, request, [&](const proto::Response&) {
    if (options.json) return print_json({{"status", "OK"}});
    std::cout << "reset: the model is empty" << std::endl;
  });
}

int run_save(const RemoteOptions& options) {
  proto::Request request;
  request.mutable_save_model();
  return simple_call(options, request, [&](const proto::Response& r) {
    if (options.json) return print_json({{"model_dir", r.save_model().model_dir()}});
    std::cout << "saved the model to " << r.save_model().model_dir() << std::endl;
  });
}

int run_load(const RemoteOptions& options) {
  proto::Request request;
  request.mutable_load_model();
  return simple_call(options, request, [&](const proto::Response& r) {
    if (options.json) return print_json({{"model_dir", r.load_model().model_dir()}, {"objects", r.load_model().objects()}});
    std::cout << "loaded the model from " << r.load_model().model_dir() << " ("
              << plural(r.load_model().objects(), "object") << ")" << std::endl;
  });
}

void add_clear_box_command(CLI::App& app, RemoteOptions& remote, Action& action) {
  auto box = std::make_shared<std::vector<double>>();
  auto* clear = app.add_subcommand("clear-box", "mark the known voxels in a world box free");
  clear->add_option("box", *box, "MINX MINY MINZ MAXX MAXY MAXZ")->expected(6)->required();
  add_remote_options(clear, remote);
  on_parsed(clear, action, [&remote, box] { return run_clear_box(remote, *box); });
}

void add_model_commands(CLI::App& app, RemoteOptions& remote, Action& action) {
  add_daemon_command(app, "reset", "forget everything: map, objects, events", remote, action, run_reset);
  add_daemon_command(app, "save", "save the model to the daemon's model directory", remote, action, run_save);
  add_daemon_command(app, "load", "reload the model from the daemon's model directory", remote, action, run_load);
}

}  // namespace scenewatch::cli

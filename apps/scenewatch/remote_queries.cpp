// Commands that ask the daemon what it knows: its health and counters, where its cameras are, the
// planes, objects and hands of the scene, and the occupancy of points and boxes.
#include <iomanip>
#include <iostream>
#include <memory>
#include <vector>

#include "commands.h"
#include "format.h"
#include "remote_client.h"
#include "subcommand.h"

namespace scenewatch::cli {
using nlohmann::json;

int run_health(const RemoteOptions& options) {
  proto::Request request;
  request.mutable_health();
  return simple_call(options, request, [&](const proto::Response& r) {
    if (options.json) return print_json(to_json(r.health()));
    std::cout << "ok: scenewatchd " << r.health().version() << " at " << options.host << ":" << options.port
              << ", up " << static_cast<long>(r.health().uptime_s()) << " s, "
              << plural(r.health().frames_processed(), "frame") << " processed" << std::endl;
  });
}

int run_stats(const RemoteOptions& options) {
  proto::Request request;
  request.mutable_stats();
  return simple_call(options, request, [&](const proto::Response& r) {
    if (options.json) return print_json(to_json(r.stats()));
    const auto& s = r.stats();
    std::cout << "frames processed   " << s.frames_processed() << "\n"
              << "frames skipped     " << s.frames_skipped() << " (live frames a newer one superseded)\n"
              << "points processed   " << s.points_processed() << "\n"
              << "events emitted     " << s.events_emitted() << " (since the daemon started; reset does not restart it)\n"
              << "tracked objects    " << s.tracked_objects() << "\n"
              << "map                " << s.map_occupied_leaves() << " occupied of " << s.map_leaf_nodes()
              << " leaves at " << s.map_resolution_m() << " m, " << s.map_memory_bytes() / 1024 << " KiB\n"
              << "appearance         " << s.keyframes() << " keyframes, " << s.mesh_triangles() << " mesh triangles, "
              << s.appearance_memory_bytes() / (1024 * 1024) << " MiB\n"
              << "frame time         last " << s.last_frame_ms() << " ms, mean " << s.mean_frame_ms() << " ms\n"
              << "connections        " << s.connections() << "\n"
              << "uptime             " << static_cast<long>(s.uptime_s()) << " s" << std::endl;
  });
}

int run_localization(const RemoteOptions& options) {
  proto::Request request;
  if (!options.camera.empty()) request.mutable_get_localization()->set_camera(options.camera);
  else request.mutable_get_localization();
  return simple_call(options, request, [&](const proto::Response& r) {
    if (options.json) return print_json(to_json(r.localization()));
    if (r.localization().cameras_size() == 0) std::cout << "no camera has sent a frame since the start or the last load\n";
    for (const auto& c : r.localization().cameras()) std::cout << text(c);
    std::cout << std::flush;
  });
}

int run_planes(const RemoteOptions& options) {
  proto::Request request;
  request.mutable_get_planes();
  return simple_call(options, request, [&](const proto::Response& r) {
    const auto& planes = r.planes();
    print_list(options.json, {{"frames_processed", planes.frames_processed()}, {"last_stamp_s", planes.last_stamp_s()}},
               "planes", planes.planes(),
               plural(planes.planes_size(), "plane") + " in the last frame (" + std::to_string(planes.frames_processed()) +
                   " processed)");
  });
}

int run_objects(const RemoteOptions& options, bool describe) {
  proto::Request request;
  request.mutable_get_objects()->set_describe(describe);
  return simple_call(options, request, [&](const proto::Response& r) {
    const auto& objects = r.objects();
    print_list(options.json, {{"frames_processed", objects.frames_processed()}}, "objects", objects.objects(),
               plural(objects.objects_size(), "tracked object"));
  });
}

int run_hands(const RemoteOptions& options) {
  proto::Request request;
  request.mutable_get_hands();
  return simple_call(options, request, [&](const proto::Response& r) {
    const auto& hands = r.hands();
    auto box_json = [](const proto::Box& b) { return json{{"min", to_json(b.min())}, {"max", to_json(b.max())}}; };
    if (options.json) {
      json list = json::array();
      for (const auto& h : hands.hands()) {
        list.push_back({{"box_world", box_json(h.box_world())}, {"tip_world", to_json(h.tip_world())}, {"score", h.score()},
                        {"pixels", h.pixels()}, {"enters_from_border", h.enters_from_border()}});
      }
      json j = {{"frame_index", hands.frame_index()}, {"stamp_s", hands.stamp_s()}, {"hands", std::move(list)},
                {"person_pixels", hands.person_pixels()}};
      if (hands.has_person_box_world()) j["person_box_world"] = box_json(hands.person_box_world());
      return print_json(j);
    }
    std::cout << plural(hands.hands_size(), "hand") << " in frame " << hands.frame_index() << "\n";
    for (const auto& h : hands.hands()) {
      std::cout << "  hand at " << text(h.tip_world()) << ", box " << text(h.box_world().min()) << " .. " << text(h.box_world().max())
                << ", " << h.pixels() << " pixels, score " << std::setprecision(2) << h.score() << "\n";
    }
    if (hands.person_pixels() > 0) std::cout << "  person: " << hands.person_pixels() << " pixels\n";
    std::cout << std::flush;
  });
}

int run_occupancy(const RemoteOptions& options, const std::vector<double>& points, const std::vector<double>& box) {
  proto::Request request;
  auto* query = request.mutable_query_occupancy();
  for (std::size_t i = 0; i + 2 < points.size(); i += 3) {
    auto* p = query->add_points();
    p->set_x(points[i]);
    p->set_y(points[i + 1]);
    p->set_z(points[i + 2]);
  }
  if (box.size() == 6) set_box(query->mutable_box(), box);
  return simple_call(options, request, [&](const proto::Response& r) {
    const auto& occupancy = r.occupancy();
    if (options.json) {
      json list = json::array();
      for (int i = 0; i < occupancy.states_size() && i < query->points_size(); ++i) {
        list.push_back({{"point", to_json(query->points(i))}, {"state", occupancy_name(occupancy.states(i))}});
      }
      json j = {{"points", std::move(list)}};
      j["box"] = occupancy.has_box() ? to_json(occupancy.box()) : json(nullptr);
      return print_json(j);
    }
    for (int i = 0; i < occupancy.states_size() && i < query->points_size(); ++i) {
      std::cout << text(query->points(i)) << ": " << occupancy_name(occupancy.states(i)) << "\n";
    }
    if (occupancy.has_box()) {
      const auto& b = occupancy.box();
      std::cout << "box: " << occupancy_name(b.state()) << " (" << b.occupied_voxels() << " occupied, "
                << b.free_voxels() << " free, " << b.unknown_voxels() << " unknown voxels)\n";
    }
    std::cout << std::flush;
  });
}

void add_status_commands(CLI::App& app, RemoteOptions& remote, Action& action) {
  add_daemon_command(app, "health", "check that the daemon answers", remote, action, run_health);
  add_daemon_command(app, "stats", "counters of the daemon and its map", remote, action, run_stats);
  auto* where = app.add_subcommand("localization", "where each camera is: state, T_world_odom, last correction, quality");
  where->add_option("--camera", remote.camera, "this camera only (an error when it sent no frame)");
  add_remote_options(where, remote);
  on_parsed(where, action, [&remote] { return run_localization(remote); });
}

void add_scene_commands(CLI::App& app, RemoteOptions& remote, Action& action) {
  add_daemon_command(app, "planes", "supporting planes of the last frame", remote, action, run_planes);

  auto* objects = app.add_subcommand("objects", "the tracked objects");
  add_remote_options(objects, remote);
  auto describe = std::make_shared<bool>(false);
  objects->add_flag("--describe", *describe,
                    "also each object's class, fitted primitive and grasps (the ontology; about 20 ms per object)");
  on_parsed(objects, action, [&remote, describe] { return run_objects(remote, *describe); });

  add_daemon_command(app, "hands", "the hands and the person seen in the last frame (where not to reach)", remote, action,
                     run_hands);

  struct Query {
    std::vector<double> points, box;
  };
  auto query = std::make_shared<Query>();
  auto* occupancy = app.add_subcommand("occupancy", "occupancy of world points (X Y Z ...) and/or a box");
  occupancy->add_option("point", query->points, "X Y Z, possibly several points");
  occupancy->add_option("--box", query->box, "MINX MINY MINZ MAXX MAXY MAXZ")->expected(6);
  add_remote_options(occupancy, remote);
  on_parsed(occupancy, action, [&remote, query] {
    if (query->points.size() % 3 != 0) {
      std::cerr << "scenewatch occupancy: points need 3 coordinates each, got " << query->points.size() << " numbers\n";
      return kExitUsage;
    }
    if (query->points.empty() && query->box.empty()) {
      std::cerr << "scenewatch occupancy: give a point X Y Z and/or --box\n";
      return kExitUsage;
    }
    return run_occupancy(remote, query->points, query->box);
  });
}

}  // namespace scenewatch::cli

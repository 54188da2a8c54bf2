// Commands that talk to the daemon through scenewatch::service::Client.
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <deque>
#include <filesystem>
#include <functional>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <optional>
#include <thread>
#include <tuple>

#include "commands.h"
#include "format.h"
#include "frame_spec.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/service/client.h"

namespace scenewatch::cli {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr double kConnectTimeoutS = 5.0;

/// Why the token could not be read (empty when it was), for the message of a refused call.
std::string g_token_problem;

/// Connects and, when the token file can be read, sends its token with the calls that need it.
Result<service::Client> connect(const RemoteOptions& options) {
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

/// The daemon's message, with why no token was sent when it asked for one.
std::string refusal(const proto::Status& status) {
  std::string message = service::to_string(status.code()) + ": " + status.message();
  if (status.code() == proto::Status::PERMISSION_DENIED && !g_token_problem.empty()) {
    message += " (no token sent: " + g_token_problem + ")";
  }
  return message;
}

/// Sends one request; prints the problem and returns nothing on a transport error or an error
/// status.
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

/// Connects, makes one call and prints its result with `print`.
int simple_call(const RemoteOptions& options, proto::Request request,
                const std::function<void(const proto::Response&)>& print) {
  auto client = connect(options);
  if (!client) return fail(client.error().message);
  auto response = call(*client, std::move(request), options);
  if (!response) return kExitError;
  print(*response);
  return kExitOk;
}

void print_json(const json& j) { std::cout << j.dump(2) << std::endl; }

std::string plural(std::size_t n, const std::string& word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

/// The message, prefixed with the path unless it names it already.
std::string naming(const std::string& path, const std::string& message) {
  return message.find(path) != std::string::npos ? message : path + ": " + message;
}

void print_ingest(const RemoteOptions& options, const std::string& source, const proto::IngestReply& reply) {
  if (options.json) {
    json j = to_json(reply);
    j["source"] = source;
    std::cout << j.dump() << std::endl;
    return;
  }
  std::cout << "frame " << reply.frame_index() << " " << source << ": " << plural(reply.planes_size(), "plane") << ", "
            << plural(reply.clusters_size(), "object") << ", " << plural(reply.events_size(), "event") << " ("
            << reply.points() << " points, " << static_cast<long>(reply.total_ms()) << " ms)";
  const auto& where = reply.localization();
  if (!where.state().empty() && where.state() != "given")
    std::cout << ", " << where.mode() << ": " << where.state() << (where.reason().empty() ? "" : " (" + where.reason() + ")");
  std::cout << "\n";
  for (const auto& event : reply.events()) std::cout << text(event) << "\n";
  std::cout << std::flush;
}

volatile sig_atomic_t g_interrupted = 0;

void on_interrupt(int) { g_interrupted = 1; }

}  // namespace

Result<RemoteSurprise> fetch_surprise(const RemoteOptions& options, const Frame* observed) {
  auto client = connect(options);
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

int fail(const std::string& message) {
  std::cerr << "scenewatch: " << message << std::endl;
  return kExitError;
}

Result<service::Client> connect_remote(const RemoteOptions& options) { return connect(options); }

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

std::string camera_name(const std::string& given, const std::vector<std::string>& paths) {
  if (!given.empty()) return given;
  std::string folder = "camera";
  if (!paths.empty()) {
    fs::path p = fs::path(paths.front()).lexically_normal();
    if (p.filename().empty()) p = p.parent_path();  // "dir/"
    if (!fs::is_directory(p)) p = p.parent_path();
    const fs::path absolute = fs::absolute(p).lexically_normal();
    if (!absolute.filename().empty()) folder = absolute.filename().string();
  }
  return folder + "#" + std::to_string(::getpid());
}

int run_ingest(const RemoteOptions& options, const std::vector<std::string>& paths, bool server_side,
               const std::optional<double>& depth_scale_m, const std::string& trajectory_path,
               const io::BagOptions& bag) {
  const std::string camera = camera_name(options.camera, paths);
  auto client = connect(options);
  if (!client) return fail(client.error().message);
  const bool show_progress = !options.json && ::isatty(STDOUT_FILENO) == 1;
  int failures = 0;
  std::vector<io::StampedPose> trajectory;  // the poses the memory used (--trajectory)

  // The answer to one request; false when the connection is gone (no point going on).
  auto take = [&](Result<proto::Response> response, const std::string& source, ProgressBar* bar, double stamp_s = 0.0) {
    if (bar != nullptr) bar->clear();
    if (!response) {
      fail(response.error().message);
      ++failures;
      return false;
    }
    if (response->status().code() != proto::Status::OK) {
      fail(naming(source, refusal(response->status())));
      ++failures;
      return true;
    }
    print_ingest(options, source, response->ingest());
    const auto& where = response->ingest().localization();
    if (where.state() != "lost" && where.pose().matrix_size() == 16) {
      Eigen::Matrix4d m;
      for (int k = 0; k < 16; ++k) m(k / 4, k % 4) = where.pose().matrix(k);
      trajectory.push_back({stamp_s, pose_from_matrix(m)});
    }
    return true;
  };
  auto send = [&](proto::Request request, const std::string& source, ProgressBar* bar, double stamp_s = 0.0) {
    return take(client->call(std::move(request), options.timeout_s), source, bar, stamp_s);
  };
  auto finish = [&] {
    if (!trajectory_path.empty()) {
      if (auto st = io::write_tum(trajectory_path, trajectory); !st) return fail("--trajectory: " + st.error().message);
    }
    return failures == 0 ? kExitOk : kExitError;
  };

  for (const std::string& path : paths) {
    std::error_code ec;
    if (server_side) {
      if (fs::is_directory(path, ec)) {
        fail(path + ": --server-side takes cloud files (.pcd/.ply), not folders");
        ++failures;
        continue;
      }
      proto::Request request;
      request.mutable_ingest_file()->set_path(fs::absolute(path).lexically_normal().string());
      if (!send(std::move(request), path, nullptr)) return kExitError;
      continue;
    }
    // A sequence folder or a bag, or some of its frames (SEQDIR:N, SEQDIR:A-B, SEQDIR/frame-NNNNNN, BAG:A-B).
    cli::InputOptions inputs(cli::sequence_options(depth_scale_m));
    inputs.bag = bag;
    auto span = cli::sequence_span(path, inputs);
    if (!span) {
      fail(naming(path, span.error().message));
      ++failures;
      continue;
    }
    if (*span) {
      const cli::SequenceSpan& seq = **span;
      if (auto skipped = seq.skipped(inputs); !skipped.empty()) {
        std::cerr << "scenewatch: " << seq.folder << ": " << skipped << "\n";
      }
      // Two frames in flight: the next frame is read from disk, sent and decoded by the daemon
      // while the one before it is processed; the answers come in the order sent.
      ProgressBar bar(show_progress);
      const std::size_t total = seq.last - seq.first + 1;
      std::deque<std::tuple<std::uint64_t, std::string, double>> in_flight;  // request id, source, stamp
      auto answer_oldest = [&] {
        const auto [id, source, stamp_s] = in_flight.front();
        in_flight.pop_front();
        return take(client->wait_for(id, options.timeout_s), source, &bar, stamp_s);
      };
      for (std::size_t i = seq.first; i <= seq.last; ++i) {
        const std::string source = seq.frame_name(i);
        bar.draw(i - seq.first, total, fs::path(source).filename().string());
        auto frame = seq.load(i);
        if (!frame) {
          bar.clear();
          fail(naming(source, frame.error().message));
          ++failures;
          continue;
        }
        frame->source = source;
        frame->camera = camera;
        frame->localization = options.localization;
        proto::Request request;
        *request.mutable_ingest_frame() = service::make_ingest_frame(*frame);
        auto id = client->start(std::move(request));
        if (!id) return fail(id.error().message);
        in_flight.emplace_back(*id, source, frame->stamp_s);
        if (in_flight.size() >= 2 && !answer_oldest()) return kExitError;
      }
      while (!in_flight.empty()) {
        if (!answer_oldest()) return kExitError;
      }
      continue;
    }
    auto frame = io::load_cloud_frame(path);
    if (!frame) {
      fail(naming(path, frame.error().message));
      ++failures;
      continue;
    }
    frame->source = path;
    frame->camera = camera;
    frame->localization = options.localization;
    proto::Request request;
    *request.mutable_ingest_frame() = service::make_ingest_frame(*frame);
    if (!send(std::move(request), path, nullptr, frame->stamp_s)) return kExitError;
  }
  return finish();
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

int run_live_ingest(const RemoteOptions& options, const std::vector<std::string>& paths, double fps, bool preload,
                    const std::optional<double>& depth_scale_m, const io::BagOptions& bag) {
  const std::string camera = camera_name(options.camera, paths);
  auto client = connect(options);
  if (!client) return fail(client.error().message);
  // A live sensor: frames leave at `fps` whether or not the daemon has answered; the daemon skips
  // a frame when a newer one is already waiting (IngestFrame.live). Replies are read as they come.
  std::uint64_t sent = 0, answered = 0, processed = 0, skipped = 0, events = 0;
  std::vector<std::string> sources(1);  // by request id
  int failures = 0;
  auto take_reply = [&](double timeout_s) {
    auto reply = client->receive(timeout_s);
    if (!reply) return false;
    if (reply->id() == 0) return true;  // a pushed event or notice: not an answer
    ++answered;
    if (reply->status().code() != proto::Status::OK) {
      fail("frame " + std::to_string(reply->id()) + ": " + service::to_string(reply->status().code()) + ": " +
           reply->status().message());
      ++failures;
    } else if (reply->ingest().skipped()) {
      ++skipped;
    } else {
      ++processed;
      events += static_cast<std::uint64_t>(reply->ingest().events_size());
      print_ingest(options, reply->id() < sources.size() ? sources[reply->id()] : std::string(), reply->ingest());
    }
    return true;
  };
  // The frames to send, as (name, loader). With `preload` every frame is decoded before the clock
  // starts, so they leave at `fps` as from a sensor, not at the pace of the disk and the decoder.
  struct Pending {
    std::string name;
    std::function<Result<proto::IngestFrame>()> load;
  };
  auto encode = [&](Result<Frame> frame) -> Result<proto::IngestFrame> {
    if (!frame) return frame.error();
    frame->camera = camera;
    frame->localization = options.localization;
    return service::make_ingest_frame(*frame);
  };
  std::vector<Pending> pending;
  for (const std::string& path : paths) {
    cli::InputOptions inputs(cli::sequence_options(depth_scale_m));
    inputs.bag = bag;
    auto span = cli::sequence_span(path, inputs);
    if (!span) return fail(naming(path, span.error().message + " (--live takes RGB-D sequence folders and bags)"));
    if (!*span) return fail(naming(path, "not a sequence folder nor a bag (--live takes RGB-D sequence folders and bags)"));
    auto seq = std::make_shared<cli::SequenceSpan>(std::move(**span));
    for (std::size_t i = seq->first; i <= seq->last; ++i)
      pending.push_back({seq->frame_name(i), [seq, i, &encode] { return encode(seq->load(i)); }});
  }
  if (preload) {
    for (Pending& p : pending) {
      auto frame = std::make_shared<Result<proto::IngestFrame>>(p.load());
      p.load = [frame] { return std::move(*frame); };
    }
  }
  const auto start = std::chrono::steady_clock::now();
  auto last_sent = start;
  for (Pending& p : pending) {
    auto frame = p.load();
    if (!frame) {
      fail(naming(p.name, frame.error().message));
      ++failures;
      continue;
    }
    std::this_thread::sleep_until(start + std::chrono::duration<double>(sent / fps));
    proto::Request request;
    *request.mutable_ingest_frame() = std::move(*frame);
    request.mutable_ingest_frame()->set_live(true);
    request.set_token(client->token());
    request.set_id(++sent);
    sources.push_back(p.name);
    if (auto st = client->send(request); !st) return fail(st.error().message);
    last_sent = std::chrono::steady_clock::now();
    while (answered < sent && take_reply(0.001)) {
    }
  }
  // The rate the frames really left at: below `fps` when reading and decoding a frame takes longer
  // than 1/fps (then --preload helps).
  const double send_s = std::chrono::duration<double>(last_sent - start).count();
  const double fps_achieved = sent > 1 && send_s > 0 ? static_cast<double>(sent - 1) / send_s : fps;
  while (answered < sent) {
    if (!take_reply(options.timeout_s > 0 ? options.timeout_s : 0)) return fail("the daemon stopped answering");
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (options.json) {
    std::cout << json{{"sent", sent}, {"processed", processed}, {"skipped", skipped}, {"events", events},
                      {"fps_sent", fps}, {"fps_achieved", fps_achieved}, {"seconds", wall_s}}
                     .dump()
              << std::endl;
  } else {
    std::cout << sent << " frames sent live at " << fps << " frames/s (achieved " << fps_achieved << ") in " << wall_s
              << " s: " << processed
              << " processed, " << skipped << " skipped (a newer frame was waiting), " << plural(events, "event") << "\n";
  }
  return failures == 0 ? kExitOk : kExitError;
}

int run_planes(const RemoteOptions& options) {
  proto::Request request;
  request.mutable_get_planes();
  return simple_call(options, request, [&](const proto::Response& r) {
    const auto& planes = r.planes();
    if (options.json) {
      json list = json::array();
      for (const auto& p : planes.planes()) list.push_back(to_json(p));
      return print_json({{"frames_processed", planes.frames_processed()},
                         {"last_stamp_s", planes.last_stamp_s()},
                         {"planes", std::move(list)}});
    }
    std::cout << plural(planes.planes_size(), "plane") << " in the last frame (" << planes.frames_processed()
              << " processed)\n";
    for (const auto& p : planes.planes()) std::cout << text(p) << "\n";
    std::cout << std::flush;
  });
}

int run_objects(const RemoteOptions& options, bool describe) {
  proto::Request request;
  request.mutable_get_objects()->set_describe(describe);
  return simple_call(options, request, [&](const proto::Response& r) {
    const auto& objects = r.objects();
    if (options.json) {
      json list = json::array();
      for (const auto& o : objects.objects()) list.push_back(to_json(o));
      return print_json({{"frames_processed", objects.frames_processed()}, {"objects", std::move(list)}});
    }
    std::cout << plural(objects.objects_size(), "tracked object") << "\n";
    for (const auto& o : objects.objects()) std::cout << text(o) << "\n";
    std::cout << std::flush;
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
  if (box.size() == 6) {
    auto* b = query->mutable_box();
    b->mutable_min()->set_x(box[0]);
    b->mutable_min()->set_y(box[1]);
    b->mutable_min()->set_z(box[2]);
    b->mutable_max()->set_x(box[3]);
    b->mutable_max()->set_y(box[4]);
    b->mutable_max()->set_z(box[5]);
  }
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

int run_clear_box(const RemoteOptions& options, const std::vector<double>& box) {
  proto::Request request;
  auto* b = request.mutable_clear_box()->mutable_box();
  b->mutable_min()->set_x(box[0]);
  b->mutable_min()->set_y(box[1]);
  b->mutable_min()->set_z(box[2]);
  b->mutable_max()->set_x(box[3]);
  b->mutable_max()->set_y(box[4]);
  b->mutable_max()->set_z(box[5]);
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

int run_classes(const RemoteOptions& options) {
  proto::Request request;
  request.mutable_list_classes();
  return simple_call(options, request, [&](const proto::Response& r) {
    const auto& reply = r.list_classes();
    if (options.json) {
      json classes = json::array();
      for (const auto& c : reply.classes()) {
        json grasps = json::array();
        for (const auto& g : c.grasps()) grasps.push_back({{"name", g.name()}, {"kind", g.kind()}, {"height_fraction", g.height_fraction()}});
        json j = {{"name", c.name()}, {"shape", c.shape()}, {"axis", c.axis()}, {"top", c.top()}, {"grasps", grasps},
                  {"allowed_dofs", std::vector<std::string>(c.allowed_dofs().begin(), c.allowed_dofs().end())},
                  {"defined_dofs", std::vector<std::string>(c.defined_dofs().begin(), c.defined_dofs().end())},
                  {"learnt_free_dofs", std::vector<std::string>(c.learnt_free_dofs().begin(), c.learnt_free_dofs().end())},
                  {"learnt_frozen_dofs", std::vector<std::string>(c.learnt_frozen_dofs().begin(), c.learnt_frozen_dofs().end())}};
        if (c.has_radius_m()) j["radius_m"] = {c.radius_m().min(), c.radius_m().max()};
        if (c.has_height_m()) j["height_m"] = {c.height_m().min(), c.height_m().max()};
        if (c.has_taper_deg()) j["taper_deg"] = {c.taper_deg().min(), c.taper_deg().max()};
        json sizes = json::array();
        for (const auto& range : c.size_m()) sizes.push_back({range.min(), range.max()});
        if (!sizes.empty()) j["size_m"] = sizes;
        classes.push_back(std::move(j));
      }
      return print_json({{"classes", classes}});
    }
    std::cout << reply.classes_size() << (reply.classes_size() == 1 ? " class" : " classes") << "\n";
    auto mm = [](const proto::Range& range) {
      return std::to_string(static_cast<int>(std::lround(range.min() * 1000))) + ".." +
             std::to_string(static_cast<int>(std::lround(range.max() * 1000))) + " mm";
    };
    for (const auto& c : reply.classes()) {
      std::cout << "  " << c.name() << ": " << c.shape();
      if (c.has_radius_m()) std::cout << ", radius " << mm(c.radius_m());
      if (c.has_height_m()) std::cout << ", height " << mm(c.height_m());
      for (int i = 0; i < c.size_m_size(); ++i) std::cout << (i == 0 ? ", sides " : " x ") << mm(c.size_m(i));
      std::cout << ", axis " << c.axis() << ", top " << c.top() << "; grasps";
      for (const auto& g : c.grasps()) std::cout << " " << g.name() << " (" << g.kind() << ")";
      // Allowed motions: those defined (config, DefineClass), then those only learnt from handled
      // instances, then what handling never moved.
      std::cout << "; motions";
      for (const auto& d : c.defined_dofs()) std::cout << " " << d;
      std::cout << (c.defined_dofs_size() == 0 ? " none defined" : " (defined)");
      std::string learnt_only;
      for (const auto& d : c.learnt_free_dofs())
        if (std::find(c.defined_dofs().begin(), c.defined_dofs().end(), d) == c.defined_dofs().end()) learnt_only += " " + d;
      if (!learnt_only.empty()) std::cout << " +" << learnt_only << " (learnt)";
      if (c.learnt_free_dofs_size() + c.learnt_frozen_dofs_size() > 0) {
        std::cout << "; learnt from handling: free";
        for (const auto& d : c.learnt_free_dofs()) std::cout << " " << d;
        std::cout << ", frozen";
        for (const auto& d : c.learnt_frozen_dofs()) std::cout << " " << d;
        if (c.learnt_frozen_dofs_size() == 0) std::cout << " none";
      }
      std::cout << "\n";
    }
    std::cout << std::flush;
  });
}

int run_define_class(const RemoteOptions& options, const std::string& yaml_file) {
  std::ifstream in(yaml_file);
  if (!in) return fail(yaml_file + ": cannot open the classes file");
  std::stringstream text;
  text << in.rdbuf();
  proto::Request request;
  request.mutable_define_class()->set_yaml(text.str());
  return simple_call(options, request, [&](const proto::Response& r) {
    const auto& reply = r.define_class();
    const std::vector<std::string> names(reply.defined().begin(), reply.defined().end());
    if (options.json) return print_json({{"defined", names}, {"persisted", reply.persisted()}});
    std::cout << "defined";
    for (const auto& n : names) std::cout << " " << n;
    std::cout << (reply.persisted() ? " (stored in the daemon's ontology.sqlite)" : " (the daemon has no model directory: until it stops)")
              << std::endl;
  });
}

int run_events(const RemoteOptions& options, std::uint64_t since, std::uint32_t max_count) {
  proto::Request request;
  request.mutable_get_events()->set_since(since);
  request.mutable_get_events()->set_max_count(max_count);
  return simple_call(options, request, [&](const proto::Response& r) {
    if (options.json) {
      json list = json::array();
      for (const auto& e : r.events().events()) list.push_back(to_json(e));
      return print_json({{"events", std::move(list)}});
    }
    std::cout << plural(r.events().events_size(), "event") << (since > 0 ? " after " + std::to_string(since) : "")
              << "\n";
    for (const auto& e : r.events().events()) std::cout << text(e) << "\n";
    std::cout << std::flush;
  });
}

int run_watch(const RemoteOptions& options) {
  auto client = connect(options);
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

}  // namespace scenewatch::cli

namespace scenewatch::cli {

int run_next_view(const RemoteOptions& options, const NextViewOptions& next) {
  proto::Request request;
  auto* q = request.mutable_next_best_view();
  if (next.object_id) q->set_object_id(*next.object_id);
  if (next.event_id) q->set_event_id(*next.event_id);
  if (next.box.size() == 6) {
    auto* b = q->mutable_box();
    b->mutable_min()->set_x(next.box[0]);
    b->mutable_min()->set_y(next.box[1]);
    b->mutable_min()->set_z(next.box[2]);
    b->mutable_max()->set_x(next.box[3]);
    b->mutable_max()->set_y(next.box[4]);
    b->mutable_max()->set_z(next.box[5]);
  }
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
                         {"measure", reply.measure()},
                         {"coverage", reply.coverage()},
                         {"target_voxels", reply.target_voxels()},
                         {"candidates", reply.candidates()}});
    }
    std::cout << "target " << text(reply.target().min()) << " .. " << text(reply.target().max()) << ", " << reply.target_voxels()
              << " voxels, coverage " << reply.coverage() << "; " << reply.candidates() << " candidates by " << reply.measure()
              << "\n";
    for (int i = 0; i < reply.views_size(); ++i) {
      const auto& v = reply.views(i);
      const auto& m = v.pose().matrix();
      std::cout << i + 1 << ". camera at (" << m[3] << ", " << m[7] << ", " << m[11] << ") score " << v.score()
                << ", expected coverage " << v.expected_coverage() << "\n   " << v.why() << "\n";
    }
    std::cout << std::flush;
  });
}

}  // namespace scenewatch::cli

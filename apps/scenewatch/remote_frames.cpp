// ingest: frames to the daemon, from cloud files, RGB-D sequence folders and ROS bags, one answer
// at a time or streamed as a live sensor would (--live).
#include <unistd.h>

#include <chrono>
#include <deque>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>
#include <tuple>

#include "commands.h"
#include "format.h"
#include "frame_spec.h"
#include "remote_client.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/service/client.h"
#include "subcommand.h"

namespace scenewatch::cli {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

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

/// The IngestFrame request of `frame`, named `source`, from `camera`.
proto::Request ingest_request(Frame& frame, const std::string& source, const std::string& camera,
                              const RemoteOptions& options) {
  frame.source = source;
  frame.camera = camera;
  frame.localization = options.localization;
  proto::Request request;
  *request.mutable_ingest_frame() = service::make_ingest_frame(frame);
  return request;
}

/// The flags of ingest besides the daemon's.
struct IngestArgs {
  std::vector<std::string> paths;
  bool server_side = false;
  std::optional<double> depth_scale_m;
  std::optional<double> live_fps;
  bool live_preload = false;
  std::string localization;
  std::string trajectory;
  io::BagOptions bag;
};

}  // namespace

std::string camera_name(const std::string& given, const std::vector<std::string>& paths) {
  if (!given.empty()) return given;
  std::string folder = "camera";
  if (!paths.empty()) {
    fs::path p = fs::path(paths.front()).lexically_normal();
    if (p.filename().empty()) p = p.parent_path();  // "dir/"
    if (!fs::is_directory(p)) p = p.parent_path();
    if (p.empty()) p = ".";  // a file name alone (or one that does not exist): the current folder
    std::error_code ec;
    fs::path absolute = fs::absolute(p, ec).lexically_normal();
    if (absolute.filename().empty()) absolute = absolute.parent_path();  // "/here/." is "/here/"
    if (!ec && !absolute.filename().empty()) folder = absolute.filename().string();
  }
  return folder + "#" + std::to_string(::getpid());
}

int run_ingest(const RemoteOptions& options, const std::vector<std::string>& paths, bool server_side,
               const std::optional<double>& depth_scale_m, const std::string& trajectory_path,
               const io::BagOptions& bag) {
  const std::string camera = camera_name(options.camera, paths);
  auto client = connect_remote(options);
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
        auto id = client->start(ingest_request(*frame, source, camera, options));
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
    if (!send(ingest_request(*frame, path, camera, options), path, nullptr, frame->stamp_s)) return kExitError;
  }
  return finish();
}

int run_live_ingest(const RemoteOptions& options, const std::vector<std::string>& paths, double fps, bool preload,
                    const std::optional<double>& depth_scale_m, const io::BagOptions& bag) {
  const std::string camera = camera_name(options.camera, paths);
  auto client = connect_remote(options);
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
  // The frames to send. With `preload` every frame is decoded and encoded before the clock starts,
  // so they leave at `fps` as from a sensor, not at the pace of the disk and the decoder.
  struct Pending {
    std::string name;
    std::shared_ptr<const cli::SequenceSpan> seq;
    std::size_t index = 0;
    std::optional<Result<proto::Request>> preloaded;
  };
  auto encode = [&](const Pending& p) -> Result<proto::Request> {
    auto frame = p.seq->load(p.index);
    if (!frame) return frame.error();
    const std::string source = frame->source;  // the file it came from, as before
    return ingest_request(*frame, source, camera, options);
  };
  std::vector<Pending> pending;
  for (const std::string& path : paths) {
    cli::InputOptions inputs(cli::sequence_options(depth_scale_m));
    inputs.bag = bag;
    auto span = cli::sequence_span(path, inputs);
    if (!span) return fail(naming(path, span.error().message + " (--live takes RGB-D sequence folders and bags)"));
    if (!*span) return fail(naming(path, "not a sequence folder nor a bag (--live takes RGB-D sequence folders and bags)"));
    auto seq = std::make_shared<const cli::SequenceSpan>(std::move(**span));
    for (std::size_t i = seq->first; i <= seq->last; ++i) pending.push_back({seq->frame_name(i), seq, i, std::nullopt});
  }
  if (preload) {
    std::cerr << "decoding " << pending.size() << " frames before the first is sent (--preload)" << std::endl;
    for (Pending& p : pending) p.preloaded = encode(p);
  }
  const auto start = std::chrono::steady_clock::now();
  auto last_sent = start;
  for (Pending& p : pending) {
    auto encoded = p.preloaded ? std::move(*p.preloaded) : encode(p);
    p.preloaded.reset();
    if (!encoded) {
      fail(naming(p.name, encoded.error().message));
      ++failures;
      continue;
    }
    std::this_thread::sleep_until(start + std::chrono::duration<double>(sent / fps));
    proto::Request request = std::move(*encoded);
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

void add_ingest_command(CLI::App& app, RemoteOptions& remote, Action& action) {
  auto args = std::make_shared<IngestArgs>();
  auto* ingest = app.add_subcommand(
      "ingest", "send cloud files or RGB-D sequence folders, frame by frame (--json: one object per line)");
  ingest->footer(
      "Sequence folders: the 7-Scenes layout (frame-NNNNNN.color.png|.jpg, .depth.png, .pose.txt,\n"
      "camera-intrinsics.txt) or the TUM RGB-D layout (rgb.txt, depth.txt, groundtruth.txt), told apart by\n"
      "their files. Depth in mm (TUM: 1/5000 m) unless depth-scale.txt or --depth-scale says otherwise.\n"
      "ROS bags (ROS 1 .bag; rosbag2 .db3 or its folder): depth and colour images, CameraInfo and TF, topics\n"
      "guessed from their types or named by --depth-topic and the other bag flags.\n"
      "A sequence's frames go two at a time: the next frame is read and sent while the daemon processes the\n"
      "one before it; every frame is processed, in order, and the answers are printed in that order.");
  ingest->add_option("paths", args->paths, "cloud files, sequence folders and/or ROS bags (BAG, BAG:N, BAG:A-B)")->required();
  ingest->add_flag("--server-side", args->server_side,
                   "let the daemon read the files itself (absolute paths under its data roots)");
  ingest->add_option("--live", args->live_fps,
                     "stream sequence folders as a live sensor: FPS frames per second without waiting for replies; "
                     "the daemon skips a frame when a newer one is already waiting, and the summary counts them")
      ->check(CLI::Range(0.1, 1000.0));
  ingest->add_flag("--preload", args->live_preload,
                   "with --live: decode every frame before the first is sent, so frames leave at FPS as from a "
                   "sensor and not at the pace of reading and decoding them (the frames as they are sent, about 4.6 MB of memory per VGA frame); "
                   "the summary gives the rate achieved either way");
  ingest->add_option("--camera", remote.camera,
                     "the name of the camera the frames come from; frames of several cameras may feed one daemon at "
                     "once, each run its own camera (default: the first path's folder and this process's id, "
                     "e.g. redkitchen#4242)");
  ingest->add_option("--localization", args->localization,
                     "how the daemon finds each frame's pose: given, refine or track (no poses needed); "
                     "overrides its localization.mode for these frames")
      ->check(CLI::IsMember({"given", "refine", "track"}))
      ->each([&remote](const std::string& m) {
        remote.localization = m == "given" ? LocalizationMode::kGiven : m == "refine" ? LocalizationMode::kRefine : LocalizationMode::kTrack;
      });
  ingest->add_option("--trajectory", args->trajectory,
                     "write the poses the memory used (frames not lost) as a TUM trajectory: t tx ty tz qx qy qz qw");
  add_depth_scale_option(ingest, args->depth_scale_m);
  add_bag_options(ingest, args->bag);
  add_remote_options(ingest, remote);
  on_parsed(ingest, action, [&remote, args] {
    const IngestArgs& a = *args;
    if (a.live_fps) {
      if (a.server_side) return fail("--live and --server-side do not go together");
      if (!a.trajectory.empty()) return fail("--trajectory and --live do not go together (live replies may be skipped)");
      return run_live_ingest(remote, a.paths, *a.live_fps, a.live_preload, a.depth_scale_m, a.bag);
    }
    if (a.live_preload) return fail("--preload goes with --live");
    return run_ingest(remote, a.paths, a.server_side, a.depth_scale_m, a.trajectory, a.bag);
  });
}

}  // namespace scenewatch::cli

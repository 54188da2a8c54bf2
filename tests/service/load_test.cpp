// Load: the real scenewatchd on loopback serving many well-behaved clients while frames are
// ingested and hostile connections (idle, or dripping a frame one byte at a time) are held open.
// No request of the well-behaved clients may be lost; p99 latency and the daemon's RSS are
// printed, and the RSS is bounded. Then rounds of bursts: idle connections and half frames, with
// the RSS before, at the peak and after each round.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <thread>
#include <vector>

#include "burst.h"
#include "daemon_harness.h"
#include "scenewatch/core/memory.h"
#include "scenewatch.pb.h"
#include "scenewatch/io/sequence.h"

namespace scenewatch::test {
namespace {
namespace fs = std::filesystem;
using service::Client;

const char* const kMug = "pcl/table_scene_mug_stereo_textured.pcd";

/// The well-behaved clients, requests each, hostile connections (half idle, half dripping).
constexpr int kClients = 256;
constexpr int kRequestsPerClient = 50;
constexpr int kHostile = 64;
/// Room for all of them plus the ingester: at max_connections the quietest connection would be
/// closed to make room, and a well-behaved client between two requests can be the quietest.
constexpr int kMaxConnections = kClients + kHostile + 16;
/// The daemon's VmRSS at its peak during the run, bound: 204 to 214 MiB measured in three runs on
/// the development machine (104 MiB at start, most of it the pages of the shared libraries the
/// foreground's registration and the ontology link in, PCL features and registration, GDAL through
/// OpenCV; the mug frames being processed are most of the rise).
constexpr double kMaxRssMiB = 230;


TEST(DaemonLoadTest, NoRequestLostUnderLoadWithHostileConnectionsHeld) {
  SCENEWATCH_REQUIRE_DATA(kMug);
  const fs::path tmp = make_temp_dir("load");
  Daemon daemon;
  ASSERT_NO_FATAL_FAILURE(daemon.start(tmp, "  max_connections: " + std::to_string(kMaxConnections) + "\n"));
  auto frame = io::load_cloud_frame(data_dir() / kMug);
  ASSERT_TRUE(frame.ok()) << frame.error().message;
  proto::Request ingest;
  *ingest.mutable_ingest_frame() = service::make_ingest_frame(*frame);
  const double rss_start_mib = resident_mib(daemon.pid());

  // Hostile connections first: they hold their slots for the whole run.
  std::vector<Client> hostile;
  for (int i = 0; i < kHostile; ++i) hostile.push_back(daemon.connect_without_token());
  const std::string header("\x00\x00\x10\x00", 4);  // 4096 bytes announced, dripped one at a time
  for (int i = kHostile / 2; i < kHostile; ++i) ASSERT_TRUE(hostile[i].send_raw(header).ok());

  std::vector<Client> clients;
  for (int i = 0; i < kClients; ++i) clients.push_back(daemon.connect_without_token());

  std::atomic<bool> done{false};
  std::atomic<int> drips{0};
  std::thread dripper([&] {
    while (!done) {
      for (int i = kHostile / 2; i < kHostile; ++i) {
        if (hostile[i].send_raw("x").ok()) ++drips;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
  });
  std::atomic<int> frames_ingested{0}, ingest_failures{0};
  std::thread ingester([&] {
    Client client = daemon.connect();
    while (!done && frames_ingested < 100) {
      auto r = client.call(ingest, kCallTimeoutS);
      if (r.ok() && r->status().code() == proto::Status::OK) {
        ++frames_ingested;
      } else {
        ++ingest_failures;
      }
    }
  });
  double peak_rss_mib = rss_start_mib;
  std::thread sampler([&] {
    while (!done) {
      peak_rss_mib = std::max(peak_rss_mib, resident_mib(daemon.pid()));
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });

  // Every client waits at the gate, then all ask at once.
  std::mutex gate_mutex;
  std::condition_variable gate;
  bool open = false;
  std::vector<std::vector<double>> latency_ms(kClients);
  std::atomic<int> lost{0}, refused{0};
  std::vector<std::thread> threads;
  for (int c = 0; c < kClients; ++c) {
    threads.emplace_back([&, c] {
      {
        std::unique_lock<std::mutex> lock(gate_mutex);
        gate.wait(lock, [&] { return open; });
      }
      for (int i = 0; i < kRequestsPerClient; ++i) {
        proto::Request request;
        switch ((c + i) % 4) {
          case 0: request.mutable_health(); break;
          case 1: request.mutable_stats(); break;
          case 2: request.mutable_get_objects(); break;
          default: request.mutable_get_planes(); break;
        }
        const auto start = std::chrono::steady_clock::now();
        auto r = clients[c].call(request, kCallTimeoutS);
        latency_ms[c].push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        if (!r.ok()) {
          ++lost;
        } else if (r->status().code() != proto::Status::OK) {
          ++refused;
        }
      }
    });
  }
  // Open the gate once the first frame is in, so the requests meet frames being processed.
  for (int i = 0; i < 6000 && frames_ingested == 0 && ingest_failures == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const auto started = std::chrono::steady_clock::now();
  {
    std::lock_guard<std::mutex> lock(gate_mutex);
    open = true;
  }
  gate.notify_all();
  for (auto& t : threads) t.join();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  done = true;
  ingester.join();
  dripper.join();
  sampler.join();

  std::vector<double> all;
  for (const auto& l : latency_ms) all.insert(all.end(), l.begin(), l.end());
  std::sort(all.begin(), all.end());
  const auto at = [&](double q) { return all[std::min(all.size() - 1, static_cast<std::size_t>(q * all.size()))]; };
  std::cout << "load: " << kClients << " clients x " << kRequestsPerClient << " requests in " << wall_s << " s ("
            << all.size() / wall_s << " requests/s) with " << kHostile << " hostile connections held ("
            << drips.load() << " bytes dripped) and " << frames_ingested.load() << " frames ingested; latency p50 "
            << at(0.50) << " ms, p99 " << at(0.99) << " ms, max " << all.back() << " ms; daemon VmRSS " << rss_start_mib
            << " MiB at start, " << peak_rss_mib << " MiB peak" << std::endl;

  EXPECT_EQ(all.size(), static_cast<std::size_t>(kClients * kRequestsPerClient));
  EXPECT_EQ(lost.load(), 0) << "requests without a reply";
  EXPECT_EQ(refused.load(), 0) << "requests answered with an error";
  EXPECT_GE(frames_ingested.load(), 1) << "frames were ingested meanwhile";
  EXPECT_EQ(ingest_failures.load(), 0);
  EXPECT_TRUE(daemon.running());
  EXPECT_GT(peak_rss_mib, 0.0) << "VmRSS of the daemon could not be read";
  EXPECT_LT(peak_rss_mib, kMaxRssMiB);
  // The idle ones are still connected and the daemon still answers on a new connection.
  Client probe = daemon.connect_without_token();
  auto alive = probe.call([] {
    proto::Request r;
    r.mutable_health();
    return r;
  }(), kCallTimeoutS);
  ASSERT_TRUE(alive.ok()) << alive.error().message;
  EXPECT_EQ(alive->status().code(), proto::Status::OK);
  if (HasFailure()) std::cerr << "---- scenewatchd log (tail) ----\n" << daemon.log().substr(daemon.log().size() > 4000 ? daemon.log().size() - 4000 : 0) << "\n";
  std::error_code ec;
  fs::remove_all(tmp, ec);
}

// Bursts a hostile client sends, round after round (issue 34 saw the same four times): 300 idle
// connections opened at once, then 20 clients each sending half of a 30 MiB frame and vanishing.
// Per round, the daemon's VmRSS before, at the peak and after: the peak within the unfinished
// frames' budget (server.max_buffered_bytes, 256 MiB) plus an allowance for what else a burst costs
// (sessions and their read buffers, the allocator's rounding), and after each round back within a
// smaller allowance of where the run started: no round leaves memory behind for the next. The
// closed sessions' read buffers are given back (session.cpp): 2-7 MiB stay after a round, measured;
// 25-32 MiB stayed before that, which the earlier allowance of 32 MiB hid until a loaded CI run
// went past it.
constexpr int kRounds = 4;
constexpr double kBurstBudgetMiB = 256;
constexpr double kBurstPeakAllowanceMiB = 64;
constexpr double kBurstAfterAllowanceMiB = 16;

TEST(DaemonLoadTest, RoundsOfConnectionAndHalfFrameBurstsKeepMemoryBounded) {
  const fs::path tmp = make_temp_dir("load-bursts");
  Daemon daemon;
  ASSERT_NO_FATAL_FAILURE(daemon.start(tmp, "  max_connections: 64\n"));
  ASSERT_EQ(connections_now(daemon), 1u);
  const double start_mib = resident_mib(daemon.pid());
  for (int round = 1; round <= kRounds; ++round) {
    const double before_mib = resident_mib(daemon.pid());
    double peak_mib = before_mib;
    std::uint32_t most_connections = 0;
    {
      RssSampler rss(daemon.pid());
      std::vector<Client> idle = open_idle_connections(daemon, 300);
      most_connections = connections_now(daemon);
      idle.clear();
      peak_mib = rss.stop();
    }
    ASSERT_EQ(wait_for_connections(daemon, 1), 1u) << "round " << round << ": the idle ones are gone";
    const HalfFrames halves = send_half_frames_and_vanish(daemon, 20, 30u << 20);
    ASSERT_EQ(wait_for_connections(daemon, 1), 1u) << "round " << round << ": the halves' clients are gone";
    peak_mib = std::max(peak_mib, halves.peak_mib);
    const double after_mib = resident_mib(daemon.pid());
    std::printf("burst round %d: 300 idle connections (stats said %u, max_connections 64), 20 half frames of 30 MiB "
                "(%d told busy); daemon VmRSS %.0f MiB before, %.0f MiB at the peak, %.0f MiB after (%.0f MiB at the "
                "start of the run)\n",
                round, most_connections, halves.busy, before_mib, peak_mib, after_mib, start_mib);
    EXPECT_LE(most_connections, 64u) << "round " << round;
    EXPECT_LE(peak_mib, start_mib + kBurstBudgetMiB + kBurstPeakAllowanceMiB) << "round " << round;
    EXPECT_LE(after_mib, start_mib + kBurstAfterAllowanceMiB) << "round " << round;
  }
  service::Client probe = daemon.connect_without_token();
  EXPECT_EQ(call(probe, request([](proto::Request& r) { r.mutable_health(); })).status().code(), proto::Status::OK);
  if (HasFailure()) std::cerr << daemon.log().substr(daemon.log().size() > 4000 ? daemon.log().size() - 4000 : 0);
  std::error_code ec;
  fs::remove_all(tmp, ec);
}

}  // namespace
}  // namespace scenewatch::test

// The daemon's limits under the bursts of issue 34, on the real scenewatchd over loopback: 300
// idle connections opened at once stay within server.max_connections, and 20 clients each sending
// half of a 30 MiB frame and vanishing are held to server.max_buffered_bytes, with the memory
// given back once they are gone.
#include <gtest/gtest.h>

#include <cstdio>

#include "burst.h"
#include "daemon_harness.h"

namespace scenewatch::test {
namespace {
namespace fs = std::filesystem;

constexpr int kMaxConnections = 64;

TEST(DaemonLimitsTest, ThreeHundredIdleConnectionsAtOnceStayWithinMaxConnections) {
  TempDir tmp("limits-connections");
  Daemon daemon;
  ASSERT_NO_FATAL_FAILURE(daemon.start(tmp, "  max_connections: " + std::to_string(kMaxConnections) + "\n"));
  std::vector<service::Client> idle = open_idle_connections(daemon, 300);
  // Asked while the burst is being admitted and after: never above the limit.
  std::uint32_t most = 0;
  for (int i = 0; i < 10; ++i) {
    most = std::max(most, connections_now(daemon));
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const IdleOutcome outcome = idle_outcome(idle, 0.05);
  const std::uint32_t settled = connections_now(daemon);
  std::printf("300 idle connections at once, max_connections %d: stats said at most %u connections, then %u; "
              "%d of the 300 were closed (made room or turned away), %d still open\n",
              kMaxConnections, most, settled, outcome.closed, outcome.still_open);
  EXPECT_LE(most, static_cast<std::uint32_t>(kMaxConnections));
  EXPECT_LE(settled, static_cast<std::uint32_t>(kMaxConnections));
  EXPECT_LT(outcome.still_open, kMaxConnections) << "the probes took slots of their own";
  EXPECT_EQ(outcome.closed + outcome.still_open, 300);
  EXPECT_TRUE(daemon.running());
  if (HasFailure()) std::cerr << daemon.log().substr(daemon.log().size() > 4000 ? daemon.log().size() - 4000 : 0);
}

// The daemon's VmRSS with 20 clients each holding half of a 30 MiB frame: at its peak the
// unfinished frames' buffers within max_buffered_bytes (256 MiB) plus an allowance for what else a
// burst costs (sessions, read buffers, the allocator's rounding); once they are gone, back to where
// it started within a smaller allowance (the heap's bookkeeping and what glibc does not hand back).
constexpr std::uint32_t kFrameBytes = 30u << 20;
constexpr double kBudgetMiB = 256;
constexpr double kPeakAllowanceMiB = 64;
constexpr double kAfterAllowanceMiB = 32;

TEST(DaemonLimitsTest, TwentyHalfFramesAreHeldToTheBudgetAndGivenBackWhenTheirClientsGo) {
  TempDir tmp("limits-frames");
  Daemon daemon;
  ASSERT_NO_FATAL_FAILURE(daemon.start(tmp, ""));
  ASSERT_EQ(connections_now(daemon), 1u);
  const double before_mib = resident_mib(daemon.pid());
  const HalfFrames burst = send_half_frames_and_vanish(daemon, 20, kFrameBytes);
  ASSERT_EQ(wait_for_connections(daemon, 1), 1u) << "the 20 are gone";
  const double after_mib = resident_mib(daemon.pid());
  std::printf("20 clients x half of a 30 MiB frame, max_buffered_bytes 256 MiB: %d told busy, %d cut off while "
              "sending; daemon VmRSS %.0f MiB before, %.0f MiB at the peak, %.0f MiB after they left\n",
              burst.busy, burst.send_failed, before_mib, burst.peak_mib, after_mib);
  EXPECT_GT(before_mib, 0.0) << "VmRSS of the daemon could not be read";
  const int held = 20 - burst.busy - burst.send_failed;
  EXPECT_LE(held * 15.0, kBudgetMiB) << held << " halves of 15 MiB held at once";
  EXPECT_LE(burst.peak_mib, before_mib + kBudgetMiB + kPeakAllowanceMiB);
  EXPECT_LE(after_mib, before_mib + kAfterAllowanceMiB) << "the frames' memory is given back";
  service::Client client = daemon.connect_without_token();
  EXPECT_EQ(call(client, request([](proto::Request& r) { r.mutable_health(); })).status().code(), proto::Status::OK);
  if (HasFailure()) std::cerr << daemon.log().substr(daemon.log().size() > 4000 ? daemon.log().size() - 4000 : 0);
}

}  // namespace
}  // namespace scenewatch::test

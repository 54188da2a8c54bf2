// The daemon's limits under the bursts of issue 34, on the real scenewatchd over loopback: 300
// idle connections opened at once stay within server.max_connections.
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

}  // namespace
}  // namespace scenewatch::test

// Request latency over loopback against the real scenewatchd, started as a user starts it:
// GetObjects (the scene snapshot, serialised) next to Health (the transport's floor), after a
// real Kinect frame has been ingested so that there are objects to return.
#include "bench.h"

#ifdef SCENEWATCH_BENCH_HAS_SERVICE
#include <unistd.h>

#include <string>

#include "bench_daemon.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/service/client.h"

namespace scenewatch::bench {

int run_latency(const Options& o) {
  const auto model_dir = std::filesystem::temp_directory_path() / ("scenewatch-bench-" + std::to_string(::getpid()));
  Daemon daemon;
  if (!daemon.start(model_dir)) {
    std::fprintf(stderr, "latency: could not start scenewatchd (build it first: scripts/build --target scenewatchd)\n");
    return 1;
  }
  auto client = service::Client::connect("127.0.0.1", daemon.port());
  if (!client) {
    std::fprintf(stderr, "latency: %s\n", client.error().message.c_str());
    return 1;
  }
  client->set_token(daemon.token());
  auto frame = io::load_cloud_frame(o.data_dir / "mosd/learn/learn13.pcd");
  if (!frame) {
    std::fprintf(stderr, "latency: %s\n", frame.error().message.c_str());
    return 1;
  }
  proto::Request ingest;
  *ingest.mutable_ingest_frame() = service::make_ingest_frame(*frame);
  auto ingested = client->call(ingest, 60);
  if (!ingested || !service::status_of(*ingested).ok()) {
    std::fprintf(stderr, "latency: ingest failed\n");
    return 1;
  }
  constexpr int kCalls = 3000;
  auto measure = [&](const proto::Request& request, std::vector<double>& us) {
    for (int i = 0; i < kCalls + 100; ++i) {
      const auto t0 = std::chrono::steady_clock::now();
      auto r = client->call(request, 10);
      const double t = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
      if (!r) return false;
      if (i >= 100) us.push_back(t);  // the first 100 warm up
    }
    return true;
  };
  proto::Request health, objects;
  health.mutable_health();
  objects.mutable_get_objects();
  std::vector<double> health_us, objects_us;
  if (!measure(health, health_us) || !measure(objects, objects_us)) {
    std::fprintf(stderr, "latency: a request failed\n");
    return 1;
  }
  auto reply = client->call(objects, 10);
  const int n_objects = reply ? reply->objects().objects_size() : -1;
  std::printf("\n== Request latency over loopback: one client, %d sequential calls each, scene of mOSD learn13 (%d objects)\n",
              kCalls, n_objects);
  std::printf("%-34s %10s %10s %10s %10s\n", "request", "p50 us", "p99 us", "max us", "p50 ratio");
  std::printf("%-34s %10.1f %10.1f %10.1f %10s\n", "Health (transport floor)", quantile(health_us, 0.5), quantile(health_us, 0.99),
              quantile(health_us, 1.0), "1.00");
  std::printf("%-34s %10.1f %10.1f %10.1f %9.2fx\n", "GetObjects", quantile(objects_us, 0.5), quantile(objects_us, 0.99),
              quantile(objects_us, 1.0), quantile(objects_us, 0.5) / quantile(health_us, 0.5));
  std::error_code ec;
  std::filesystem::remove_all(model_dir, ec);
  return 0;
}

}  // namespace scenewatch::bench

#else

namespace scenewatch::bench {
int run_latency(const Options&) {
  std::printf("\n== Request latency: built without the service module; skipped\n");
  return 0;
}
}  // namespace scenewatch::bench

#endif

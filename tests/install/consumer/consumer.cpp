// Uses the installed libraries: a WorkingMemory processes one synthetic frame whose answer is
// known exactly (a camera 1 m in front of a wall: one plane, z = 1 m, and the space before it
// free), and, given a port, the service's Client asks the installed daemon for its version.
//   consumer [PORT]     exit 0 when every check holds; each failure is printed
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/service/client.h"

namespace {

int failures = 0;

void check(bool ok, const std::string& what) {
  std::printf("%s %s\n", ok ? "ok  " : "FAIL", what.c_str());
  if (!ok) ++failures;
}

/// A 160x120 organized cloud of a flat wall at z = 1 m, seen by a camera at the origin.
scenewatch::Frame wall_frame() {
  constexpr int kWidth = 160, kHeight = 120;
  constexpr double kF = 200.0, kDepthM = 1.0;
  auto cloud = std::make_shared<scenewatch::Cloud>(kWidth, kHeight);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      scenewatch::PointT& p = cloud->at(u, v);
      p.x = static_cast<float>((u - kWidth / 2.0) / kF * kDepthM);
      p.y = static_cast<float>((v - kHeight / 2.0) / kF * kDepthM);
      p.z = static_cast<float>(kDepthM);
      p.r = 180;
      p.g = 170;
      p.b = 150;
    }
  }
  cloud->is_dense = true;
  scenewatch::Frame frame;
  frame.cloud = cloud;
  frame.intrinsics = scenewatch::Intrinsics{kF, kF, kWidth / 2.0, kHeight / 2.0, kWidth, kHeight};
  frame.source = "consumer wall";
  return frame;
}

}  // namespace

int main(int argc, char** argv) {
  scenewatch::pipeline::WorkingMemory memory{scenewatch::pipeline::Config{}};
  const scenewatch::Frame frame = wall_frame();
  auto result = memory.process(frame);
  if (!result) {
    std::printf("FAIL process: %s\n", result.error().message.c_str());
    return 1;
  }
  check(result->points == frame.cloud->size(), "all " + std::to_string(frame.cloud->size()) + " points valid (got " +
                                                   std::to_string(result->points) + ")");
  check(result->planes.size() == 1, "one plane (got " + std::to_string(result->planes.size()) + ")");
  if (!result->planes.empty()) {
    const scenewatch::Plane& plane = result->planes.front();
    const double distance_m = std::abs(plane.signed_distance(Eigen::Vector3d::Zero()));
    check(std::abs(std::abs(plane.normal.normalized().z()) - 1.0) < 1e-3, "its normal is the optical axis");
    check(std::abs(distance_m - 1.0) < 0.01, "it lies 1 m from the camera (got " + std::to_string(distance_m) + " m)");
  }
  check(memory.query(Eigen::Vector3d(0.0, 0.0, 0.5)) == scenewatch::background::Occupancy::kFree,
        "the space half-way to the wall is free");
  check(memory.query(Eigen::Vector3d(0.0, 0.0, 1.0)) == scenewatch::background::Occupancy::kOccupied,
        "the wall is occupied");

  if (argc > 1) {
    auto client = scenewatch::service::Client::connect("127.0.0.1", static_cast<std::uint16_t>(std::atoi(argv[1])));
    if (!client) {
      std::printf("FAIL connect: %s\n", client.error().message.c_str());
      return 1;
    }
    scenewatch::proto::Request request;
    request.mutable_health();
    auto reply = client->call(request, 10.0);
    check(reply && reply->has_health(), "Health answered" + (reply ? std::string() : ": " + reply.error().message));
    if (reply && reply->has_health()) {
      check(reply->health().version() == SCENEWATCH_PACKAGE_VERSION,
            "the daemon's version " + reply->health().version() + " is the package's " + SCENEWATCH_PACKAGE_VERSION);
    }
  }
  std::printf("%s\n", failures == 0 ? "consumer: all checks hold" : "consumer: checks failed");
  return failures == 0 ? 0 : 1;
}

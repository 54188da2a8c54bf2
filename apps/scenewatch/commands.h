#pragma once
// The commands of the scenewatch CLI. Each returns the process exit code.
#include <cstdint>
#include <string>
#include <vector>

#include "scenewatch/service/server_config.h"

namespace scenewatch::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitError = 1;
inline constexpr int kExitUsage = 2;

/// Prints "scenewatch: <message>" on stderr and returns kExitError.
int fail(const std::string& message);

/// Where the daemon is and how to print.
struct RemoteOptions {
  std::string host = "127.0.0.1";
  int port = service::kDefaultPort;
  bool json = false;
  double timeout_s = 30.0;  ///< per call; 0 = wait forever
};

int run_health(const RemoteOptions& options);
int run_stats(const RemoteOptions& options);
int run_ingest(const RemoteOptions& options, const std::vector<std::string>& paths, bool server_side);
int run_planes(const RemoteOptions& options);
int run_objects(const RemoteOptions& options);
/// `points`: x y z triples; `box`: empty or min x y z, max x y z.
int run_occupancy(const RemoteOptions& options, const std::vector<double>& points, const std::vector<double>& box);
int run_clear_box(const RemoteOptions& options, const std::vector<double>& box);
int run_reset(const RemoteOptions& options);
int run_save(const RemoteOptions& options);
int run_load(const RemoteOptions& options);
int run_events(const RemoteOptions& options, std::uint64_t since, std::uint32_t max_count);
int run_watch(const RemoteOptions& options);

struct SegmentOptions {
  std::string file;
  bool json = false;
  std::string out_dir;
  std::string config;
  bool plane_indices = false;
};
/// Offline: segments a cloud file and prints planes and objects (no daemon involved).
int run_segment(const SegmentOptions& options);

struct DiffOptions {
  std::string before, after;  ///< cloud files or sequence frames (DIR/frame-NNNNNN)
  bool json = false;
  std::string config;         ///< YAML config: its change and background sections are used
  bool force_map = false;     ///< compare through the map even for same-camera pairs
  double resolution_m = 0;    ///< map voxel edge for the map path (0 = config / default)
};
/// Offline: geometric change detection between two observations (no daemon involved).
int run_diff(const DiffOptions& options);

}  // namespace scenewatch::cli

#pragma once
// The commands of the scenewatch CLI. Each returns the process exit code.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "scenewatch.pb.h"
#include "scenewatch/core/frame.h"
#include "scenewatch/core/result.h"
#include "scenewatch/io/bag.h"
#include "scenewatch/service/access_token.h"
#include "scenewatch/service/client.h"
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
  /// The daemon's access token file (calls that change the model need the token).
  std::string token_file = service::default_token_path().string();
  /// ingest: the name of the camera the frames come from (empty: one name per run, from the first
  /// path's folder and this process's id; see camera_name()).
  std::string camera;
  /// ingest: how the daemon finds each frame's pose (unset: its localization.mode).
  std::optional<LocalizationMode> localization;
};

/// The camera name an ingest run gives its frames: `given`, else "<folder>#<pid>" from the first
/// path (a sequence folder's own name, a cloud file's folder), so that two runs are two cameras.
std::string camera_name(const std::string& given, const std::vector<std::string>& paths);

int run_health(const RemoteOptions& options);
int run_stats(const RemoteOptions& options);
/// GetLocalization: every camera, or options.camera alone.
int run_localization(const RemoteOptions& options);
/// `depth_scale_m`: metres per depth unit of sequence folders (unset: the folder's or layout's).
/// `bag`: how ROS bags among the paths are read.
int run_ingest(const RemoteOptions& options, const std::vector<std::string>& paths, bool server_side,
               const std::optional<double>& depth_scale_m, const std::string& trajectory_path = {},
               const io::BagOptions& bag = {});
/// Sequence folders streamed as a live sensor would: `fps` frames per second without waiting for
/// replies, each frame marked live (the daemon skips frames it cannot keep up with). With `preload`
/// every frame is decoded before the first is sent, so the send rate is not bounded by decoding.
int run_live_ingest(const RemoteOptions& options, const std::vector<std::string>& paths, double fps, bool preload,
                    const std::optional<double>& depth_scale_m, const io::BagOptions& bag = {});
int run_planes(const RemoteOptions& options);
/// `describe`: with each object's class, primitive and grasps (the ontology).
int run_objects(const RemoteOptions& options, bool describe);
int run_hands(const RemoteOptions& options);
/// `points`: x y z triples; `box`: empty or min x y z, max x y z.
int run_occupancy(const RemoteOptions& options, const std::vector<double>& points, const std::vector<double>& box);
int run_clear_box(const RemoteOptions& options, const std::vector<double>& box);
int run_reset(const RemoteOptions& options);
int run_save(const RemoteOptions& options);
int run_load(const RemoteOptions& options);
/// The daemon's object classes (ListClasses).
int run_classes(const RemoteOptions& options);
/// Sends a classes file (config/ontology.yaml's format) to the daemon (DefineClass).
int run_define_class(const RemoteOptions& options, const std::string& yaml_file);
int run_events(const RemoteOptions& options, std::uint64_t since, std::uint32_t max_count);
int run_watch(const RemoteOptions& options);
/// The changes seen but not yet confirmed (GetPendingChanges).
int run_pending(const RemoteOptions& options);

/// Where to look next (NextBestView): exactly one target of object, event, pending change, box or
/// workspace.
struct NextViewOptions {
  std::optional<std::uint64_t> object_id, event_id, pending_id;
  std::vector<double> box;  ///< MINX MINY MINZ MAXX MAXY MAXZ, or empty
  bool workspace = false;
  std::string measure;      ///< empty: the daemon's default for the target
  std::uint32_t n = 5;
  double radius_m = 0.0;    ///< 0: the daemon's default
};
int run_next_view(const RemoteOptions& options, const NextViewOptions& next);

struct SurpriseOptions {
  std::string observed;                 ///< frame spec (see frame_spec.h); empty: the daemon's last map
  std::vector<std::string> references;  ///< frame specs; empty: ask the daemon
  std::string out_png;                  ///< heatmap over the observed image
  std::string raw_tiff;                 ///< float32 surprise per pixel
  std::string expected_png;             ///< the expected (virtual) image
  std::string panel_png;                ///< observed | expected | heatmap side by side
  std::string mesh_ply;                 ///< the references' textured mesh
  std::string intrinsics;               ///< 3x3 K file for cloud files (else recovered)
  std::string config;                   ///< YAML: its appearance and surprise sections
  double saturation = 24.0;             ///< heatmap scale in nats
  bool json = false;
  std::optional<double> depth_scale_m;  ///< metres per depth unit of sequence folders (unset: theirs)
};
/// Image-based surprise of an observed frame against reference frames (offline), or against the
/// daemon's appearance memory when no reference is given.
int run_surprise(const SurpriseOptions& options, const RemoteOptions& remote);

/// The daemon's surprise map (GetSurpriseMap): of `observed` when set, else of its last frame.
struct RemoteSurprise {
  int width = 0, height = 0;
  std::vector<float> total;
  std::uint64_t known_pixels = 0;
  std::uint32_t reference_views = 0;
  std::vector<proto::Event> regions;
  double compute_ms = 0;
};
Result<RemoteSurprise> fetch_surprise(const RemoteOptions& options, const Frame* observed);

struct SegmentOptions {
  std::string file;
  bool json = false;
  std::string out_dir;
  std::string config;
  bool plane_indices = false;
};
/// Offline: segments a cloud file and prints planes and objects (no daemon involved).
int run_segment(const SegmentOptions& options);

struct FitOptions {
  std::string file;                     ///< a cloud file or one sequence frame (see frame_spec.h)
  bool json = false;
  std::string config;                   ///< YAML config: its segmentation section is used
  std::optional<double> depth_scale_m;  ///< metres per depth unit of sequence folders (unset: theirs)
  io::BagOptions bag;  ///< how ROS bags are read (topics, TF frames)
  std::string classes;                  ///< classes file (empty: the shipped config/ontology.yaml)
  std::string out_dir;                  ///< when set: each object's completed model as PCD and PLY
};
/// Offline: segments one frame, fits primitives (plane, cylinder, sphere, cone) to each object and
/// classifies it (class, score, grasp points, completed model).
int run_fit(const FitOptions& options);

struct DiffOptions {
  std::string before, after;  ///< cloud files or sequence frames (DIR/frame-NNNNNN)
  bool json = false;
  std::string config;         ///< YAML config: its change and background sections are used
  bool force_map = false;     ///< compare through the map even for same-camera pairs
  double resolution_m = 0;    ///< map voxel edge for the map path (0 = config / default)
  std::optional<double> depth_scale_m;  ///< metres per depth unit of sequence folders (unset: theirs)
};
/// Offline: geometric change detection between two observations (no daemon involved).
int run_diff(const DiffOptions& options);

struct ReplayOptions {
  std::vector<std::string> inputs;  ///< frame specs (see frame_spec.h), processed in order
  std::string config;               ///< YAML config, as the daemon's (the server section is not read)
  std::size_t stride = 1;           ///< process every N-th frame of each input
  bool json = false;                ///< one JSON line per event, then a summary line
  bool progress = true;             ///< a progress line on stderr every 25 frames
  std::string heatmap_dir;          ///< when set: surprise-NNNNNN.png per frame with a surprise map
  std::optional<double> depth_scale_m;  ///< metres per depth unit of sequence folders (unset: theirs)
  io::BagOptions bag;  ///< how ROS bags are read (topics, TF frames)
  std::string localization;         ///< overrides localization.mode: given, refine or track (empty: the config's)
  std::string trajectory;           ///< when set: the poses the memory used, as a TUM trajectory
  bool objects = false;             ///< after each frame, the object list a planner would get
  bool classes = false;             ///< with objects: each object's class and score (the ontology)
  std::string classes_file;         ///< the classes for `classes` (empty: the shipped ontology.yaml)
};
/// Offline: recordings through the working memory as the daemon would run them; prints the
/// event stream and a summary (events per 100 frames, time per frame and per stage).
int run_replay(const ReplayOptions& options);
/// A scenario script (SCRIPT.yaml) through a running daemon; `check`: exit 1 when an expectation fails.
int run_scenario(const RemoteOptions& remote, const std::string& script, bool check);
/// Connects to the daemon with the token of `options.token_file` (when it can be read).
Result<service::Client> connect_remote(const RemoteOptions& options);

}  // namespace scenewatch::cli

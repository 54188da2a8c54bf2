#pragma once
/// The DDS side of the bridge: one Cyclone DDS participant that is a ROS 2 peer (topics rt/<name>,
/// types <pkg>::msg::dds_::<Type>_, XCDR1 little-endian, QoS as ROS 2's profiles). It reads depth,
/// colour, CameraInfo, /tf and /tf_static into the FrameAssembler, and writes events, objects, the
/// map and the markers. With a cloud topic, it reads PointCloud2 frames instead of the images. Thread safe: the write functions may be called from any thread (dds_write is).
#include <dds/dds.h>

#include <atomic>
#include <string>
#include <vector>

#include "bridge_config.h"
#include "bridge_stats.h"
#include "frame_assembler.h"
#include "scene_markers.h"
#include "scenewatch.pb.h"

namespace scenewatch::ros {

class DdsNode {
 public:
  /// Creates the participant, the readers and the writers; the error names the topic or call.
  static Result<std::unique_ptr<DdsNode>> create(const BridgeConfig& config, BridgeStats& stats);
  ~DdsNode();
  DdsNode(const DdsNode&) = delete;
  DdsNode& operator=(const DdsNode&) = delete;

  /// Reads the incoming topics into `assembler` until `stop` is set (checked every 0.2 s).
  void run(FrameAssembler& assembler, const std::atomic<bool>& stop);

  void write_events(const std::vector<proto::Event>& events);
  void write_objects(const proto::ObjectsReply& objects, double stamp_s);
  void write_map(const proto::MapReply& map, double stamp_s);
  /// Only when config.markers (else there is no writer and nothing is written).
  void write_markers(const MarkerScene& scene, double stamp_s);
  /// Only when config.publish_odom_tf: world -> odom on /tf.
  void write_odom(const proto::Pose& T_world_odom, double stamp_s);
  /// Only when config.surprise: the heatmap as a 32FC1 sensor_msgs/Image in the camera's frame.
  void write_surprise(const proto::SurpriseMapReply& map, double stamp_s, const std::string& camera_frame);

 private:
  DdsNode(const BridgeConfig& config, BridgeStats& stats) : config_(config), stats_(stats) {}
  void written(dds_return_t rc, const char* what);

  const BridgeConfig& config_;
  BridgeStats& stats_;
  dds_entity_t participant_ = 0;
  dds_entity_t depth_reader_ = 0, color_reader_ = 0, cloud_reader_ = 0, info_reader_ = 0, tf_reader_ = 0, tf_static_reader_ = 0;
  dds_entity_t events_writer_ = 0, objects_writer_ = 0, map_writer_ = 0, markers_writer_ = 0, tf_writer_ = 0, surprise_writer_ = 0;
};

}  // namespace scenewatch::ros

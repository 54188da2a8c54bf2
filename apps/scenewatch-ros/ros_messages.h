#pragma once
/// The generated DDS types of the ROS 2 messages (idl/*.idl, C by idlc) and conversions between
/// them and ours: images, camera info and TF in; events, objects and the map out. Outgoing
/// messages are built on the stack, pointing into the reply they come from, and written at once.
#include <dds/dds.h>

#include <string>
#include <vector>

#include "builtin_interfaces.h"
#include "frame_assembler.h"
#include "octomap_msgs.h"
#include "scenewatch.pb.h"
#include "scenewatch/io/bag/messages.h"
#include "scenewatch_msgs.h"
#include "sensor_msgs.h"
#include "std_msgs.h"
#include "tf2_msgs.h"
#include "vision_msgs.h"

namespace scenewatch::ros {

/// builtin_interfaces/Time of seconds, and back.
builtin_interfaces_msg_dds__Time_ ros_time(double stamp_s);
double seconds(const builtin_interfaces_msg_dds__Time_& t);

/// A sensor_msgs/Image copied out of its sample.
RawImage to_raw_image(const sensor_msgs_msg_dds__Image_& m, Clock::time_point arrived);
/// A sensor_msgs/PointCloud2 copied out of its sample.
RawCloud to_raw_cloud(const sensor_msgs_msg_dds__PointCloud2_& m, Clock::time_point arrived);
io::bag::CameraInfoMessage to_camera_info(const sensor_msgs_msg_dds__CameraInfo_& m);
/// A TFMessage's transforms; a rotation that is not a unit quaternion (within 1e-3) is an error.
Result<std::vector<io::bag::StampedTransform>> to_transforms(const tf2_msgs_msg_dds__TFMessage_& m);

/// Writes the events as one scenewatch_msgs/EventArray, header frame `world_frame`.
dds_return_t write_events(dds_entity_t writer, const std::vector<proto::Event>& events, const std::string& world_frame);
/// Writes the tracked objects as one vision_msgs/Detection3DArray stamped `stamp_s`: per object
/// its box (centre, rotation, extents), id = the object's id, one hypothesis (its ontology class, or
/// "object" with score 1).
dds_return_t write_detections(dds_entity_t writer, const proto::ObjectsReply& objects, double stamp_s, const std::string& world_frame);
/// Writes `T_parent_child` (row-major 4x4, the daemon's Pose) as a one-transform TFMessage, as a
/// tf2_ros TransformBroadcaster does. An ill-formed pose (not 16 values) writes nothing.
dds_return_t write_transform(dds_entity_t writer, const proto::Pose& T_parent_child, double stamp_s, const std::string& parent,
                             const std::string& child);
/// Writes the map as octomap_server does: binary, id "OcTree", data = OcTree::writeBinaryData.
dds_return_t write_octomap(dds_entity_t writer, const proto::MapReply& map, double stamp_s, const std::string& world_frame);
/// Writes a surprise map as a sensor_msgs/Image, encoding 32FC1 (nats per pixel, NaN where the
/// memory predicts nothing), little-endian, in the camera's frame. A reply whose pixel bytes do not
/// match its size writes nothing (DDS_RETCODE_BAD_PARAMETER).
dds_return_t write_surprise_image(dds_entity_t writer, const proto::SurpriseMapReply& map, double stamp_s, const std::string& camera_frame);

}  // namespace scenewatch::ros

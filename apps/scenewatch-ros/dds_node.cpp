#include "dds_node.h"

#include <iostream>

#include "ros_messages.h"
#include "scenewatch/io/bag/image_conversion.h"
#include "visualization_msgs.h"

namespace scenewatch::ros {
namespace {

/// ROS 2's QoS profiles as DDS QoS.
enum class Profile {
  kSensorData,     ///< rmw_qos_profile_sensor_data: best effort, keep last 5, volatile
  kReliable,       ///< rmw_qos_profile_default: reliable, keep last 10, volatile
  kTf,             ///< tf2_ros listener: reliable, keep last 100, volatile
  kTransientLocal  ///< /tf_static and latched maps: reliable, keep last 1 (readers: 100), transient local
};

dds_qos_t* qos_of(Profile profile, bool reader) {
  dds_qos_t* q = dds_create_qos();
  switch (profile) {
    case Profile::kSensorData:
      dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
      dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 5);
      break;
    case Profile::kReliable:
      dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
      dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 10);
      break;
    case Profile::kTf:
      dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
      dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 100);
      break;
    case Profile::kTransientLocal:
      dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
      dds_qset_history(q, DDS_HISTORY_KEEP_LAST, reader ? 100 : 1);
      dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
      break;
  }
  return q;
}

Error dds_error(const std::string& what, dds_return_t rc) { return Error{ErrorCode::kIoError, what + ": " + dds_strretcode(rc)}; }

}  // namespace

Result<std::unique_ptr<DdsNode>> DdsNode::create(const BridgeConfig& config, BridgeStats& stats) {
  std::unique_ptr<DdsNode> node(new DdsNode(config, stats));
  node->participant_ = dds_create_participant(config.domain_id, nullptr, nullptr);
  if (node->participant_ < 0) {
    return dds_error("cannot create a DDS participant on domain " + std::to_string(config.domain_id) +
                         " (check CYCLONEDDS_URI and the network interface)",
                     node->participant_);
  }
  auto entity = [&](const std::string& ros_topic, const dds_topic_descriptor_t* type, Profile profile, bool reader,
                    dds_entity_t* out) -> Status {
    auto name = dds_topic_name(ros_topic);
    if (!name) return name.error();
    const dds_entity_t topic = dds_create_topic(node->participant_, type, name->c_str(), nullptr, nullptr);
    if (topic < 0) return dds_error("topic " + ros_topic + " (" + type->m_typename + ")", topic);
    dds_qos_t* q = qos_of(profile, reader);
    *out = reader ? dds_create_reader(node->participant_, topic, q, nullptr) : dds_create_writer(node->participant_, topic, q, nullptr);
    dds_delete_qos(q);
    if (*out < 0) return dds_error(std::string(reader ? "reader" : "writer") + " of " + ros_topic, *out);
    return {};
  };
  const std::string& ns = config.output_namespace;
  const bool images = config.cloud_topic.empty();
  for (auto st : {!images ? Status{} : entity(config.depth_topic, &sensor_msgs_msg_dds__Image__desc, Profile::kSensorData, true, &node->depth_reader_),
                  !images || config.color_topic.empty()
                      ? Status{}
                      : entity(config.color_topic, &sensor_msgs_msg_dds__Image__desc, Profile::kSensorData, true, &node->color_reader_),
                  images ? Status{}
                         : entity(config.cloud_topic, &sensor_msgs_msg_dds__PointCloud2__desc, Profile::kSensorData, true, &node->cloud_reader_),
                  entity(config.info_topic, &sensor_msgs_msg_dds__CameraInfo__desc, Profile::kSensorData, true, &node->info_reader_),
                  entity("/tf", &tf2_msgs_msg_dds__TFMessage__desc, Profile::kTf, true, &node->tf_reader_),
                  entity("/tf_static", &tf2_msgs_msg_dds__TFMessage__desc, Profile::kTransientLocal, true, &node->tf_static_reader_),
                  entity(ns + "/events", &scenewatch_msgs_msg_dds__EventArray__desc, Profile::kReliable, false, &node->events_writer_),
                  entity(ns + "/objects", &vision_msgs_msg_dds__Detection3DArray__desc, Profile::kReliable, false, &node->objects_writer_),
                  entity(ns + "/octomap_binary", &octomap_msgs_msg_dds__Octomap__desc, Profile::kTransientLocal, false,
                         &node->map_writer_),
                  // As the objects (RViz's Marker display reads reliable, volatile): every frame's array reaches it.
                  !config.markers ? Status{}
                                  : entity(ns + "/markers", &visualization_msgs_msg_dds__MarkerArray__desc, Profile::kReliable, false,
                                           &node->markers_writer_),
                  // An image like the camera's own: best effort, keep last 5 (rmw_qos_profile_sensor_data).
                  !config.surprise ? Status{}
                                   : entity(ns + "/surprise", &sensor_msgs_msg_dds__Image__desc, Profile::kSensorData, false,
                                            &node->surprise_writer_),
                  // As a tf2_ros TransformBroadcaster (reliable, keep last 100, volatile).
                  !config.publish_odom_tf ? Status{} : entity("/tf", &tf2_msgs_msg_dds__TFMessage__desc, Profile::kTf, false, &node->tf_writer_)}) {
    if (!st) return st.error();
  }
  return node;
}

DdsNode::~DdsNode() {
  if (participant_ > 0) dds_delete(participant_);
}

void DdsNode::run(FrameAssembler& assembler, const std::atomic<bool>& stop) {
  const dds_entity_t waitset = dds_create_waitset(participant_);
  for (dds_entity_t reader : {depth_reader_, color_reader_, cloud_reader_, info_reader_, tf_reader_, tf_static_reader_}) {
    if (reader <= 0) continue;
    dds_waitset_attach(waitset, dds_create_readcondition(reader, DDS_ANY_STATE), reader);
  }
  // Takes every waiting sample of a reader, one at a time, as loans.
  auto take_all = [&](dds_entity_t reader, auto&& handle) {
    for (;;) {
      void* samples[1] = {nullptr};
      dds_sample_info_t info;
      const dds_return_t n = dds_take(reader, samples, &info, 1, 1);
      if (n <= 0) return;
      if (info.valid_data) handle(samples[0]);
      dds_return_loan(reader, samples, n);
    }
  };
  auto log = [](const std::string& line) { std::cerr << "scenewatch-ros: " << line << std::endl; };
  while (!stop) {
    dds_attach_t triggered[8];
    const dds_return_t n = dds_waitset_wait(waitset, triggered, 8, DDS_MSECS(200));
    if (n <= 0) continue;
    take_all(info_reader_, [&](void* s) {
      assembler.set_intrinsics(io::bag::to_intrinsics(to_camera_info(*static_cast<sensor_msgs_msg_dds__CameraInfo_*>(s))));
    });
    for (auto [reader, is_static] : {std::pair{tf_static_reader_, true}, std::pair{tf_reader_, false}}) {
      take_all(reader, [&, is_static = is_static](void* s) {
        auto transforms = to_transforms(*static_cast<tf2_msgs_msg_dds__TFMessage_*>(s));
        if (!transforms) {
          const auto count = stats_.count("bad_tf");
          if (worth_logging(count)) log(std::string("ignored a TFMessage on ") + (is_static ? "/tf_static" : "/tf") + ": " + transforms.error().message);
          return;
        }
        for (const auto& t : *transforms) assembler.add_transform(t, is_static);
      });
    }
    if (color_reader_ > 0) {
      take_all(color_reader_, [&](void* s) {
        assembler.add_color(to_raw_image(*static_cast<sensor_msgs_msg_dds__Image_*>(s), Clock::now()));
      });
    }
    if (depth_reader_ > 0) {
      take_all(depth_reader_, [&](void* s) {
        assembler.add_depth(to_raw_image(*static_cast<sensor_msgs_msg_dds__Image_*>(s), Clock::now()));
      });
    }
    if (cloud_reader_ > 0) {
      take_all(cloud_reader_, [&](void* s) {
        assembler.add_cloud(to_raw_cloud(*static_cast<sensor_msgs_msg_dds__PointCloud2_*>(s), Clock::now()));
      });
    }
  }
  dds_delete(waitset);
}

void DdsNode::written(dds_return_t rc, const char* what) {
  if (rc >= 0) return;
  const auto n = stats_.count(std::string("write_failed.") + what);
  if (worth_logging(n)) std::cerr << "scenewatch-ros: writing " << what << " failed: " << dds_strretcode(rc) << std::endl;
}

void DdsNode::write_events(const std::vector<proto::Event>& events) {
  written(ros::write_events(events_writer_, events, config_.world_frame), "events");
}

void DdsNode::write_objects(const proto::ObjectsReply& objects, double stamp_s) {
  written(write_detections(objects_writer_, objects, stamp_s, config_.world_frame), "objects");
}

void DdsNode::write_map(const proto::MapReply& map, double stamp_s) {
  written(write_octomap(map_writer_, map, stamp_s, config_.world_frame), "octomap");
}

void DdsNode::write_markers(const MarkerScene& scene, double stamp_s) {
  if (markers_writer_ <= 0) return;
  written(ros::write_markers(markers_writer_, scene, stamp_s, config_.world_frame), "markers");
}

void DdsNode::write_surprise(const proto::SurpriseMapReply& map, double stamp_s, const std::string& camera_frame) {
  if (surprise_writer_ <= 0) return;
  written(write_surprise_image(surprise_writer_, map, stamp_s, camera_frame), "surprise");
}

void DdsNode::write_odom(const proto::Pose& T_world_odom, double stamp_s) {
  if (tf_writer_ <= 0) return;
  written(write_transform(tf_writer_, T_world_odom, stamp_s, config_.world_frame, config_.odom_frame), "tf");
}

}  // namespace scenewatch::ros

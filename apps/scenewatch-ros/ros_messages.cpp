#include "ros_messages.h"

#include <cmath>

namespace scenewatch::ros {
namespace {

char* c_str(const std::string& s) { return const_cast<char*>(s.c_str()); }

std_msgs_msg_dds__Header_ header(double stamp_s, const std::string& frame_id) {
  std_msgs_msg_dds__Header_ h{};
  h.stamp = ros_time(stamp_s);
  h.frame_id = c_str(frame_id);
  return h;
}

geometry_msgs_msg_dds__Point_ point(const proto::Vec3& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

builtin_interfaces_msg_dds__Time_ ros_time(double stamp_s) {
  builtin_interfaces_msg_dds__Time_ t{};
  double sec = std::floor(stamp_s);
  auto nanosec = static_cast<std::int64_t>(std::llround((stamp_s - sec) * 1e9));
  if (nanosec >= 1000000000) {
    sec += 1;
    nanosec -= 1000000000;
  }
  t.sec = static_cast<std::int32_t>(sec);
  t.nanosec = static_cast<std::uint32_t>(nanosec);
  return t;
}

double seconds(const builtin_interfaces_msg_dds__Time_& t) { return t.sec + t.nanosec * 1e-9; }

RawImage to_raw_image(const sensor_msgs_msg_dds__Image_& m, Clock::time_point arrived) {
  RawImage r;
  r.stamp_s = seconds(m.header.stamp);
  r.frame_id = m.header.frame_id ? m.header.frame_id : "";
  r.width = m.width;
  r.height = m.height;
  r.step = m.step;
  r.encoding = m.encoding ? m.encoding : "";
  r.big_endian = m.is_bigendian != 0;
  r.data.assign(m.data._buffer, m.data._buffer + m.data._length);
  r.arrived = arrived;
  return r;
}

RawCloud to_raw_cloud(const sensor_msgs_msg_dds__PointCloud2_& m, Clock::time_point arrived) {
  RawCloud r;
  r.stamp_s = seconds(m.header.stamp);
  r.frame_id = m.header.frame_id ? m.header.frame_id : "";
  r.width = m.width;
  r.height = m.height;
  r.point_step = m.point_step;
  r.row_step = m.row_step;
  r.big_endian = m.is_bigendian;
  for (std::uint32_t i = 0; i < m.fields._length; ++i) {
    const auto& f = m.fields._buffer[i];
    r.fields.push_back({f.name ? f.name : "", f.offset, f.datatype, f.count});
  }
  r.data.assign(m.data._buffer, m.data._buffer + m.data._length);
  r.arrived = arrived;
  return r;
}

io::bag::CameraInfoMessage to_camera_info(const sensor_msgs_msg_dds__CameraInfo_& m) {
  io::bag::CameraInfoMessage info;
  info.header.stamp_s = seconds(m.header.stamp);
  info.header.frame_id = m.header.frame_id ? m.header.frame_id : "";
  info.width = m.width;
  info.height = m.height;
  for (int i = 0; i < 9; ++i) info.K[i] = m.k[i];
  return info;
}

Result<std::vector<io::bag::StampedTransform>> to_transforms(const tf2_msgs_msg_dds__TFMessage_& m) {
  std::vector<io::bag::StampedTransform> out;
  for (std::uint32_t i = 0; i < m.transforms._length; ++i) {
    const auto& t = m.transforms._buffer[i];
    const auto& q = t.transform.rotation;
    const Eigen::Quaterniond rotation(q.w, q.x, q.y, q.z);
    const std::string child = t.child_frame_id ? t.child_frame_id : "";
    if (!(std::abs(rotation.norm() - 1.0) <= 1e-3)) {
      return invalid_argument("transform " + std::to_string(i) + " ('" + child + "'): rotation is no unit quaternion (norm " +
                              std::to_string(rotation.norm()) + ")");
    }
    io::bag::StampedTransform s;
    s.stamp_s = seconds(t.header.stamp);
    s.parent = t.header.frame_id ? t.header.frame_id : "";
    s.child = child;
    // tf2 takes frame names with or without a leading slash as the same frame.
    for (auto* name : {&s.parent, &s.child}) {
      if (!name->empty() && (*name)[0] == '/') name->erase(0, 1);
    }
    s.T_parent_child.linear() = rotation.normalized().toRotationMatrix();
    s.T_parent_child.translation() = Eigen::Vector3d(t.transform.translation.x, t.transform.translation.y, t.transform.translation.z);
    out.push_back(std::move(s));
  }
  return out;
}

dds_return_t write_events(dds_entity_t writer, const std::vector<proto::Event>& events, const std::string& world_frame) {
  std::vector<scenewatch_msgs_msg_dds__Event_> out(events.size());
  std::vector<std::string> kind_names(events.size());
  std::vector<std::vector<std::string>> keys(events.size());
  std::vector<std::vector<char*>> key_ptrs(events.size());
  std::vector<std::vector<double>> values(events.size());
  double last_stamp = 0;
  for (std::size_t i = 0; i < events.size(); ++i) {
    const proto::Event& e = events[i];
    auto& m = out[i];
    m = {};
    m.header = header(e.stamp_s(), world_frame);
    last_stamp = std::max(last_stamp, e.stamp_s());
    m.id = e.id();
    m.level = static_cast<std::uint8_t>(e.level());
    m.kind = static_cast<std::uint8_t>(e.kind());
    kind_names[i] = proto::Event::Kind_Name(e.kind());
    m.kind_name = c_str(kind_names[i]);
    m.score = e.score();
    m.box_min = point(e.box_world().min());
    m.box_max = point(e.box_world().max());
    m.centroid = point(e.centroid_world());
    m.has_object_id = e.has_object_id();
    m.object_id = e.object_id();
    m.detail = c_str(e.detail());
    for (const auto& [key, value] : e.evidence()) {
      keys[i].push_back(key);
      values[i].push_back(value);
    }
    for (const auto& k : keys[i]) key_ptrs[i].push_back(c_str(k));
    m.evidence_keys._length = m.evidence_keys._maximum = static_cast<std::uint32_t>(key_ptrs[i].size());
    m.evidence_keys._buffer = key_ptrs[i].data();
    m.evidence_values._length = m.evidence_values._maximum = static_cast<std::uint32_t>(values[i].size());
    m.evidence_values._buffer = values[i].data();
    m.has_displacement = e.has_displacement_world();
    m.displacement = {e.displacement_world().x(), e.displacement_world().y(), e.displacement_world().z()};
  }
  scenewatch_msgs_msg_dds__EventArray_ array{};
  array.header = header(last_stamp, world_frame);
  array.events._length = array.events._maximum = static_cast<std::uint32_t>(out.size());
  array.events._buffer = out.data();
  return dds_write(writer, &array);
}

dds_return_t write_detections(dds_entity_t writer, const proto::ObjectsReply& objects, double stamp_s, const std::string& world_frame) {
  const std::size_t n = static_cast<std::size_t>(objects.objects_size());
  std::vector<vision_msgs_msg_dds__Detection3D_> detections(n);
  std::vector<vision_msgs_msg_dds__ObjectHypothesisWithPose_> hypotheses(n);
  std::vector<std::string> ids(n), classes(n);
  for (std::size_t i = 0; i < n; ++i) {
    const proto::Object& o = objects.objects(static_cast<int>(i));
    const proto::OrientedBox& box = o.box();
    geometry_msgs_msg_dds__Pose_ center{};
    center.position = point(box.center());
    center.orientation = {box.rotation().x(), box.rotation().y(), box.rotation().z(), box.rotation().w()};
    if (!box.has_rotation()) center.orientation.w = 1.0;
    auto& h = hypotheses[i];
    h = {};
    const bool classified = o.has_ontology() && !o.ontology().class_name().empty();
    classes[i] = classified ? o.ontology().class_name() : "object";
    h.hypothesis.class_id = c_str(classes[i]);
    h.hypothesis.score = classified ? o.ontology().score() : 1.0;
    h.pose.pose = center;
    auto& d = detections[i];
    d = {};
    d.header = header(stamp_s, world_frame);
    d.results._length = d.results._maximum = 1;
    d.results._buffer = &h;
    d.bbox.center = center;
    d.bbox.size = {box.extents().x(), box.extents().y(), box.extents().z()};
    ids[i] = std::to_string(o.id());
    d.id = c_str(ids[i]);
  }
  vision_msgs_msg_dds__Detection3DArray_ array{};
  array.header = header(stamp_s, world_frame);
  array.detections._length = array.detections._maximum = static_cast<std::uint32_t>(n);
  array.detections._buffer = detections.data();
  return dds_write(writer, &array);
}

dds_return_t write_transform(dds_entity_t writer, const proto::Pose& T_parent_child, double stamp_s, const std::string& parent,
                             const std::string& child) {
  if (T_parent_child.matrix_size() != 16) return DDS_RETCODE_BAD_PARAMETER;
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = T_parent_child.matrix(4 * r + c);
  }
  const Eigen::Quaterniond q(m.topLeftCorner<3, 3>());
  geometry_msgs_msg_dds__TransformStamped_ t{};
  t.header = header(stamp_s, parent);
  t.child_frame_id = c_str(child);
  t.transform.translation = {m(0, 3), m(1, 3), m(2, 3)};
  t.transform.rotation = {q.x(), q.y(), q.z(), q.w()};
  tf2_msgs_msg_dds__TFMessage_ message{};
  message.transforms._length = message.transforms._maximum = 1;
  message.transforms._buffer = &t;
  return dds_write(writer, &message);
}

dds_return_t write_octomap(dds_entity_t writer, const proto::MapReply& map, double stamp_s, const std::string& world_frame) {
  static const std::string kId = "OcTree";
  octomap_msgs_msg_dds__Octomap_ m{};
  m.header = header(stamp_s, world_frame);
  m.binary = true;
  m.id = c_str(kId);
  m.resolution = map.resolution_m();
  m.data._length = m.data._maximum = static_cast<std::uint32_t>(map.binary_data().size());
  m.data._buffer = reinterpret_cast<int8_t*>(const_cast<char*>(map.binary_data().data()));
  return dds_write(writer, &m);
}

dds_return_t write_surprise_image(dds_entity_t writer, const proto::SurpriseMapReply& map, double stamp_s, const std::string& camera_frame) {
  static const std::string kEncoding = "32FC1";  // sensor_msgs/image_encodings.hpp TYPE_32FC1
  const std::uint64_t bytes = std::uint64_t{map.width()} * map.height() * sizeof(float);
  if (map.width() == 0 || map.height() == 0 || map.total().size() != bytes) return DDS_RETCODE_BAD_PARAMETER;
  sensor_msgs_msg_dds__Image_ m{};
  m.header = header(stamp_s, camera_frame);
  m.height = map.height();
  m.width = map.width();
  m.encoding = c_str(kEncoding);
  m.is_bigendian = 0;  // the reply's floats are little-endian, as this machine's
  m.step = map.width() * static_cast<std::uint32_t>(sizeof(float));
  m.data._length = m.data._maximum = static_cast<std::uint32_t>(bytes);
  m.data._buffer = reinterpret_cast<std::uint8_t*>(const_cast<char*>(map.total().data()));
  return dds_write(writer, &m);
}

}  // namespace scenewatch::ros

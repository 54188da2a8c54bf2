#include "scene_markers.h"

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <deque>

#include "ros_messages.h"
#include "visualization_msgs.h"

namespace scenewatch::ros {
namespace {

using Marker = visualization_msgs_msg_dds__Marker_;
using Point = geometry_msgs_msg_dds__Point_;
using Color = std_msgs_msg_dds__ColorRGBA_;

constexpr double kLineWidthM = 0.01;   ///< LINE_STRIP / LINE_LIST: scale.x is the line width
constexpr double kLabelHeightM = 0.04; ///< TEXT_VIEW_FACING: scale.z is the height of a capital
constexpr double kLabelGapM = 0.03;    ///< between a box's top and its label

constexpr Color kPlaneColor{0.1f, 0.9f, 0.2f, 1.0f};
constexpr Color kObjectColor{0.2f, 0.55f, 1.0f, 0.45f};
constexpr Color kLabelColor{1.0f, 1.0f, 1.0f, 1.0f};
constexpr Color kHandColor{1.0f, 0.55f, 0.1f, 0.5f};
constexpr Color kPersonColor{0.6f, 0.6f, 0.6f, 0.3f};
constexpr Color kEventColor{1.0f, 0.9f, 0.0f, 1.0f};

/// Marker.id is int32; the daemon's ids count up from 1, so the low 31 bits keep them apart for
/// two billion objects or events.
std::int32_t marker_id(std::uint64_t id) { return static_cast<std::int32_t>(id & 0x7fffffffu); }

Point point(const proto::Vec3& v) { return {v.x(), v.y(), v.z()}; }

/// Owns what the C messages point to (strings, point lists) until the array is written; deques
/// keep the addresses of what they hold when they grow.
class MarkerArrayBuilder {
 public:
  MarkerArrayBuilder(double stamp_s, const std::string& world_frame) : stamp_s_(stamp_s), frame_(world_frame) {}

  /// A marker with the header, `ns` and `id` set, the identity pose and ADD.
  Marker& add(const char* ns, std::int32_t id, std::int32_t type, const Color& color) {
    Marker& m = markers_.emplace_back();
    m = {};
    m.header.stamp = ros_time(stamp_s_);
    m.header.frame_id = const_cast<char*>(frame_.c_str());
    m.ns = const_cast<char*>(ns);
    m.id = id;
    m.type = type;
    m.action = visualization_msgs_msg_dds__Marker_Constants_ADD;
    m.pose.orientation.w = 1.0;
    m.color = color;
    // Empty strings, not null: a ROS 2 reader expects every string to be present.
    m.texture_resource = m.text = m.mesh_resource = m.texture.format = m.texture.header.frame_id = m.mesh_file.filename =
        const_cast<char*>("");
    return m;
  }

  void set_points(Marker& m, std::vector<Point> points) {
    auto& held = points_.emplace_back(std::move(points));
    m.points._length = m.points._maximum = static_cast<std::uint32_t>(held.size());
    m.points._buffer = held.data();
  }

  void set_text(Marker& m, std::string text) { m.text = const_cast<char*>(texts_.emplace_back(std::move(text)).c_str()); }

  dds_return_t write(dds_entity_t writer) {
    std::vector<Marker> flat(markers_.begin(), markers_.end());
    visualization_msgs_msg_dds__MarkerArray_ array{};
    array.markers._length = array.markers._maximum = static_cast<std::uint32_t>(flat.size());
    array.markers._buffer = flat.data();
    return dds_write(writer, &array);
  }

 private:
  double stamp_s_;
  const std::string& frame_;
  std::deque<Marker> markers_;
  std::deque<std::vector<Point>> points_;
  std::deque<std::string> texts_;
};

void add_planes(MarkerArrayBuilder& b, const google::protobuf::RepeatedPtrField<proto::Plane>& planes) {
  for (const proto::Plane& plane : planes) {
    if (plane.hull_size() < 3) continue;
    Marker& m = b.add("planes", plane.id(), visualization_msgs_msg_dds__Marker_Constants_LINE_STRIP, kPlaneColor);
    m.scale.x = kLineWidthM;
    std::vector<Point> hull;
    for (const auto& v : plane.hull()) hull.push_back(point(v));
    hull.push_back(hull.front());  // a strip draws no closing edge of its own
    b.set_points(m, std::move(hull));
  }
}

/// Half the world-z extent of an oriented box: how far its top lies above its centre.
double half_height_world(const Eigen::Quaterniond& rotation, const proto::Vec3& extents) {
  const Eigen::Matrix3d R = rotation.toRotationMatrix();
  return 0.5 * (std::abs(R(2, 0)) * extents.x() + std::abs(R(2, 1)) * extents.y() + std::abs(R(2, 2)) * extents.z());
}

void add_objects(MarkerArrayBuilder& b, const proto::ObjectsReply& objects) {
  for (const proto::Object& o : objects.objects()) {
    const proto::OrientedBox& box = o.box();
    Eigen::Quaterniond q = box.has_rotation() ? Eigen::Quaterniond(box.rotation().w(), box.rotation().x(), box.rotation().y(), box.rotation().z())
                                              : Eigen::Quaterniond::Identity();
    q.normalize();
    Marker& cube = b.add("objects", marker_id(o.id()), visualization_msgs_msg_dds__Marker_Constants_CUBE, kObjectColor);
    cube.pose.position = point(box.center());
    cube.pose.orientation = {q.x(), q.y(), q.z(), q.w()};
    cube.scale = {box.extents().x(), box.extents().y(), box.extents().z()};

    Marker& label = b.add("labels", marker_id(o.id()), visualization_msgs_msg_dds__Marker_Constants_TEXT_VIEW_FACING, kLabelColor);
    label.pose.position = point(box.center());
    label.pose.position.z += half_height_world(q, box.extents()) + kLabelGapM;
    label.scale.z = kLabelHeightM;
    std::string text = "#" + std::to_string(o.id());
    if (o.has_ontology() && !o.ontology().class_name().empty()) text += " " + o.ontology().class_name();
    b.set_text(label, std::move(text));
  }
}

/// An axis-aligned box as a CUBE marker's pose and scale.
void set_box(Marker& m, const proto::Box& box) {
  m.pose.position = {0.5 * (box.min().x() + box.max().x()), 0.5 * (box.min().y() + box.max().y()), 0.5 * (box.min().z() + box.max().z())};
  m.scale = {box.max().x() - box.min().x(), box.max().y() - box.min().y(), box.max().z() - box.min().z()};
}

/// Each hand (and forearm) as an orange box; the rest of the person, when seen, as a grey one.
void add_hands(MarkerArrayBuilder& b, const proto::HandsReply& hands) {
  for (int i = 0; i < hands.hands_size(); ++i) {
    set_box(b.add("hands", i, visualization_msgs_msg_dds__Marker_Constants_CUBE, kHandColor), hands.hands(i).box_world());
  }
  if (hands.has_person_box_world()) {
    set_box(b.add("person", 0, visualization_msgs_msg_dds__Marker_Constants_CUBE, kPersonColor), hands.person_box_world());
  }
}

/// The 12 edges of an axis-aligned box as 24 LINE_LIST points.
std::vector<Point> box_edges(const proto::Box& box) {
  const std::array<double, 2> xs{box.min().x(), box.max().x()}, ys{box.min().y(), box.max().y()}, zs{box.min().z(), box.max().z()};
  auto corner = [&](int i) { return Point{xs[i & 1], ys[(i >> 1) & 1], zs[(i >> 2) & 1]}; };
  std::vector<Point> points;
  // Corners are numbered by bits (x, y, z); an edge joins two corners that differ in one bit.
  for (int i = 0; i < 8; ++i) {
    for (int bit : {1, 2, 4}) {
      if ((i & bit) == 0) {
        points.push_back(corner(i));
        points.push_back(corner(i | bit));
      }
    }
  }
  return points;
}

void add_events(MarkerArrayBuilder& b, const std::vector<proto::Event>& events) {
  for (const proto::Event& e : events) {
    if (!e.has_box_world()) continue;
    Marker& m = b.add("events", marker_id(e.id()), visualization_msgs_msg_dds__Marker_Constants_LINE_LIST, kEventColor);
    m.scale.x = kLineWidthM;
    b.set_points(m, box_edges(e.box_world()));
  }
}

}  // namespace

dds_return_t write_markers(dds_entity_t writer, const MarkerScene& scene, double stamp_s, const std::string& world_frame) {
  MarkerArrayBuilder b(stamp_s, world_frame);
  // ns "" with DELETEALL clears every namespace: what the daemon no longer reports disappears.
  b.add("", 0, visualization_msgs_msg_dds__Marker_Constants_CUBE, Color{}).action = visualization_msgs_msg_dds__Marker_Constants_DELETEALL;
  if (scene.planes) add_planes(b, *scene.planes);
  if (scene.objects) add_objects(b, *scene.objects);
  if (scene.hands) add_hands(b, *scene.hands);
  add_events(b, scene.events);
  return b.write(writer);
}

}  // namespace scenewatch::ros

#include "ros_messages.h"

#include <cmath>

namespace scenewatch::io::bag {
namespace {

// Shorthand: evaluate a Result-returning read into `var`, returning its error.
#define SW_READ(lhs, expr)             \
  do {                                 \
    auto sw_r = (expr);                \
    if (!sw_r) return sw_r.error();    \
    lhs = std::move(*sw_r);            \
  } while (0)

Result<FieldReader> open(const std::vector<std::uint8_t>& bytes, WireFormat format) {
  return FieldReader::open(bytes.data(), bytes.size(), format);
}

}  // namespace

Result<ImageMessage> decode_image(const std::vector<std::uint8_t>& bytes, WireFormat format) {
  auto r = open(bytes, format);
  if (!r) return r.error();
  ImageMessage m;
  SW_READ(m.header, r->header());
  SW_READ(m.height, r->u32("height"));
  SW_READ(m.width, r->u32("width"));
  SW_READ(m.encoding, r->string("encoding"));
  std::uint8_t big = 0;
  SW_READ(big, r->u8("is_bigendian"));
  m.big_endian = big != 0;
  SW_READ(m.step, r->u32("step"));
  std::uint32_t n = 0;
  SW_READ(n, r->sequence_length("data", 1));
  SW_READ(m.data, r->bytes(n, "data"));
  m.size = n;
  return m;
}

Result<CameraInfoMessage> decode_camera_info(const std::vector<std::uint8_t>& bytes, WireFormat format) {
  auto r = open(bytes, format);
  if (!r) return r.error();
  CameraInfoMessage m;
  SW_READ(m.header, r->header());
  SW_READ(m.height, r->u32("height"));
  SW_READ(m.width, r->u32("width"));
  std::string model;
  SW_READ(model, r->string("distortion_model"));
  std::uint32_t nd = 0;
  SW_READ(nd, r->sequence_length("D", 8));
  for (std::uint32_t i = 0; i < nd; ++i) {
    double d = 0;
    SW_READ(d, r->f64("D"));
    (void)d;
  }
  if (auto st = r->f64_array(m.K, 9, "K"); !st) return st.error();
  return m;
}

Result<PointCloud2Message> decode_point_cloud2(const std::vector<std::uint8_t>& bytes, WireFormat format) {
  auto r = open(bytes, format);
  if (!r) return r.error();
  PointCloud2Message m;
  SW_READ(m.header, r->header());
  SW_READ(m.height, r->u32("height"));
  SW_READ(m.width, r->u32("width"));
  std::uint32_t nf = 0;
  SW_READ(nf, r->sequence_length("fields", 13));  // name length, offset, datatype, count
  m.fields.resize(nf);
  for (auto& f : m.fields) {
    SW_READ(f.name, r->string("fields.name"));
    SW_READ(f.offset, r->u32("fields.offset"));
    SW_READ(f.datatype, r->u8("fields.datatype"));
    SW_READ(f.count, r->u32("fields.count"));
  }
  std::uint8_t big = 0;
  SW_READ(big, r->u8("is_bigendian"));
  m.big_endian = big != 0;
  SW_READ(m.point_step, r->u32("point_step"));
  SW_READ(m.row_step, r->u32("row_step"));
  std::uint32_t n = 0;
  SW_READ(n, r->sequence_length("data", 1));
  SW_READ(m.data, r->bytes(n, "data"));
  m.size = n;
  return m;
}

Result<std::vector<StampedTransform>> decode_tf(const std::vector<std::uint8_t>& bytes, WireFormat format) {
  auto r = open(bytes, format);
  if (!r) return r.error();
  std::uint32_t n = 0;
  SW_READ(n, r->sequence_length("transforms", 68));  // header, child, 7 doubles: at least 68 bytes
  std::vector<StampedTransform> out(n);
  for (auto& t : out) {
    MessageHeader h;
    SW_READ(h, r->header());
    t.stamp_s = h.stamp_s;
    t.parent = std::move(h.frame_id);
    SW_READ(t.child, r->string("transforms.child_frame_id"));
    double v[7];
    if (auto st = r->f64_array(v, 7, "transforms.transform"); !st) return st.error();
    const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
    for (double x : v) {
      if (!std::isfinite(x)) return invalid_argument("transform '" + t.parent + "' -> '" + t.child + "': not a finite number");
    }
    if (std::abs(q.norm() - 1.0) > 1e-3) {
      return invalid_argument("transform '" + t.parent + "' -> '" + t.child + "': the rotation is not a unit quaternion (norm " +
                              std::to_string(q.norm()) + ")");
    }
    t.T_parent_child = Pose::Identity();
    t.T_parent_child.linear() = q.normalized().toRotationMatrix();
    t.T_parent_child.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  return out;
}

#undef SW_READ

}  // namespace scenewatch::io::bag

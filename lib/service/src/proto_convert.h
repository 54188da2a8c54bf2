#pragma once
// Conversions between core types and the wire protocol's messages. Private to the service module
// (the client header re-exports only what the CLI needs).
#include <optional>
#include <string>
#include <string_view>

#include "scenewatch.pb.h"
#include "scenewatch/change/pending_change.h"
#include "scenewatch/core/cloud.h"
#include "scenewatch/core/event.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/image.h"
#include "scenewatch/core/result.h"
#include "scenewatch/core/scene.h"
#include "scenewatch/localization/localizer.h"

namespace scenewatch::service::convert {

proto::Status::Code to_proto(ErrorCode code);
ErrorCode from_proto(proto::Status::Code code);

void to_proto(const Eigen::Vector3d& v, proto::Vec3* out);
Eigen::Vector3d from_proto(const proto::Vec3& v);
void to_proto(const Aabb& box, proto::Box* out);
void to_proto(const OrientedBox& box, proto::OrientedBox* out);
void to_proto(const Plane& plane, proto::Plane* out);
void to_proto(const ObjectCluster& cluster, proto::Cluster* out);
void to_proto(const TrackedObject& object, proto::Object* out);
void to_proto(const Event& event, proto::Event* out);
void to_proto(const Pose& pose, proto::Pose* out);
void to_proto(const localization::Localization& where, proto::LocalizationResult* out);
/// A frame's localization mode on the wire; unset is LOCALIZATION_CONFIGURED (the daemon's own).
proto::LocalizationMode to_proto(const std::optional<LocalizationMode>& mode);
/// The kind of a pending change as GetPendingChanges and the live view name it.
proto::PendingChange::Kind to_proto(change::PendingKind kind);
/// ... and back; an unknown number is an error naming it.
Result<std::optional<LocalizationMode>> decode_localization_mode(int value);
void to_proto(const Intrinsics& intrinsics, proto::Intrinsics* out);

/// Floats as little-endian float32 bytes, and back (error when the size is not a multiple of 4).
std::string encode_floats(const std::vector<float>& values);
Result<std::vector<float>> decode_floats(const std::string& bytes, const std::string& field);

/// Cloud -> xyz (little-endian float32) and, when has_color, rgb bytes.
void encode_cloud(const Cloud& cloud, bool has_color, proto::Cloud* out);

/// A decoded cloud; grey (128) when the message had no rgb.
struct DecodedCloud {
  CloudPtr cloud;
  bool has_color = false;
};
/// Checks sizes (xyz 12 bytes and rgb 3 bytes per point) and decodes. Errors name the field.
Result<DecodedCloud> decode_cloud(const proto::Cloud& msg);

/// A depth image and its colour image -> RgbdImages (depth_mm little-endian; rgb only with `color`).
void encode_rgbd(const DepthImage& depth, const ColorImage* color, proto::RgbdImages* out);
/// The images of an RgbdImages; grey (128) when it had no rgb.
struct DecodedRgbd {
  DepthImage depth;
  ColorImage color;
  bool has_color = false;
};
/// Checks sizes (depth_mm 2 bytes and rgb 0 or 3 bytes per pixel, at most 100000 on a side) and
/// decodes. Errors name the field.
Result<DecodedRgbd> decode_rgbd(const proto::RgbdImages& msg);

/// 16 finite values forming a rigid transform. `field` names the field in messages.
Result<Pose> decode_pose(const proto::Pose& msg, const std::string& field);
/// Finite, min <= max.
Result<Aabb> decode_box(const proto::Box& msg, const std::string& field);
/// Finite point.
Result<Eigen::Vector3d> decode_point(const proto::Vec3& msg, const std::string& field);
/// Positive focal lengths and image size.
Result<Intrinsics> decode_intrinsics(const proto::Intrinsics& msg, const std::string& field);

/// `text` with each byte that does not belong to a well-formed UTF-8 character replaced by '?'.
/// The protocol's string fields must be UTF-8: a status message quoting a damaged file's bytes (a
/// JSON parser's "last read: ...") made the whole Response one the client cannot parse.
std::string valid_utf8(std::string_view text);

/// The bytes of a source label kept (IngestFrame.source, which messages and the log quote).
inline constexpr std::size_t kMaxSourceLabelBytes = 256;
/// IngestFrame.source as the label of the frame: "api" when empty; control characters as '?';
/// longer than kMaxSourceLabelBytes, cut there (at a UTF-8 character's start) and marked
/// "... (cut from N bytes)".
std::string source_label(const std::string& sent);

}  // namespace scenewatch::service::convert

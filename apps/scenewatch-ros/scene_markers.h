#pragma once
/// The scene as RViz markers (visualization_msgs/MarkerArray, issue 32): what one frame left in
/// the daemon's memory, drawn in the world frame. The array starts with a DELETEALL, so a
/// subscriber shows this frame's scene and nothing older; then, by namespace:
///   planes  LINE_STRIP per supporting plane: its hull, closed, green, 1 cm wide; id = plane id
///   objects CUBE per tracked object: its oriented box, translucent blue; id = object id
///   labels  TEXT_VIEW_FACING per object above its box: "#<id>", then its class when known
///   hands   CUBE per hand (with forearm): its world box, translucent orange; id = index
///   person  CUBE of the rest of the person (body, head) when seen: its world box, translucent grey
///   events  LINE_LIST per recent event: the 12 edges of its world box, yellow; id = event id
/// Ids are the daemon's, truncated to int32 (Marker.id), so a marker keeps its id across frames.
#include <dds/dds.h>

#include <string>
#include <vector>

#include "scenewatch.pb.h"

namespace scenewatch::ros {

/// What the markers of one frame are made of (borrowed; nothing is copied).
struct MarkerScene {
  const google::protobuf::RepeatedPtrField<proto::Plane>* planes = nullptr;  ///< the frame's (IngestReply)
  const proto::ObjectsReply* objects = nullptr;
  const proto::HandsReply* hands = nullptr;     ///< null: the daemon gave none
  std::vector<proto::Event> events;             ///< the newest events
};

/// Writes `scene` as one visualization_msgs/MarkerArray stamped `stamp_s` in `world_frame`.
dds_return_t write_markers(dds_entity_t writer, const MarkerScene& scene, double stamp_s, const std::string& world_frame);

}  // namespace scenewatch::ros

#include "format.h"

#include <cstdio>
#include <sstream>

namespace scenewatch::cli {
namespace {

std::string fixed(double value, int decimals = 3) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

}  // namespace

nlohmann::json to_json(const proto::Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

nlohmann::json to_json(const proto::Pose& pose) { return std::vector<double>(pose.matrix().begin(), pose.matrix().end()); }

nlohmann::json to_json(const proto::Box& box) { return {{"min", to_json(box.min())}, {"max", to_json(box.max())}}; }

nlohmann::json to_json(const proto::OrientedBox& box) {
  const auto& q = box.rotation();
  return {{"center", to_json(box.center())},
          {"rotation", {{"w", q.w()}, {"x", q.x()}, {"y", q.y()}, {"z", q.z()}}},
          {"extents", to_json(box.extents())}};
}

nlohmann::json to_json(const proto::Plane& plane) {
  nlohmann::json hull = nlohmann::json::array();
  for (const auto& p : plane.hull()) hull.push_back(to_json(p));
  return {{"id", plane.id()},
          {"normal", to_json(plane.normal())},
          {"d", plane.d()},
          {"area_m2", plane.area_m2()},
          {"inlier_count", plane.inlier_count()},
          {"centroid", to_json(plane.centroid())},
          {"hull", std::move(hull)}};
}

nlohmann::json to_json(const proto::Cluster& cluster) {
  return {{"plane_id", cluster.plane_id()},
          {"centroid", to_json(cluster.centroid())},
          {"box", to_json(cluster.box())},
          {"point_count", cluster.point_count()},
          {"mean_rgb", to_json(cluster.mean_rgb())},
          {"supported_by", cluster.supported_by()}};
}

nlohmann::json to_json(const proto::Object& object) {
  nlohmann::json j = {{"id", object.id()},
          {"plane_id", object.plane_id()},
          {"centroid", to_json(object.centroid())},
          {"box", to_json(object.box())},
          {"point_count", object.point_count()},
          {"mean_rgb", to_json(object.mean_rgb())},
          {"first_seen_s", object.first_seen_s()},
          {"last_seen_s", object.last_seen_s()},
          {"observations", object.observations()},
          {"supported_by", object.supported_by()}};
  if (object.has_ontology()) {
    const auto& c = object.ontology();
    nlohmann::json grasps = nlohmann::json::array();
    for (const auto& g : c.grasps()) {
      grasps.push_back({{"name", g.name()}, {"kind", g.kind()}, {"position", to_json(g.position())},
                        {"approach", to_json(g.approach())}, {"closing", to_json(g.closing())}, {"width_m", g.width_m()}});
    }
    j["ontology"] = {{"class", c.class_name()}, {"score", c.score()}, {"grasps", grasps}};
    if (c.has_primitive()) {
      const auto& p = c.primitive();
      j["ontology"]["primitive"] = {{"shape", p.shape()}, {"center", to_json(p.center())}, {"axis", to_json(p.axis())},
                                    {"radius_m", p.radius_m()}, {"bottom_radius_m", p.bottom_radius_m()},
                                    {"top_radius_m", p.top_radius_m()}, {"height_m", p.height_m()},
                                    {"size_x_m", p.size_x_m()}, {"size_y_m", p.size_y_m()}, {"rms_m", p.rms_m()}};
    }
  }
  if (!object.foreground()) return j;
  nlohmann::json handlings = nlohmann::json::array();
  for (const auto& h : object.handlings()) {
    handlings.push_back({{"start_s", h.start_s()}, {"end_s", h.end_s()},
                         {"dof_range", std::vector<double>(h.dof_range().begin(), h.dof_range().end())},
                         {"moved_dofs", std::vector<std::string>(h.moved_dofs().begin(), h.moved_dofs().end())}});
  }
  j["foreground"] = {{"pose", to_json(object.pose())},
                     {"free_dofs", std::vector<std::string>(object.free_dofs().begin(), object.free_dofs().end())},
                     {"frozen_dofs", std::vector<std::string>(object.frozen_dofs().begin(), object.frozen_dofs().end())},
                     {"handlings", handlings}, {"in_hand", object.in_hand()}, {"visible", object.visible()},
                     {"promoted_s", object.promoted_s()}};
  return j;
}

nlohmann::json to_json(const proto::Event& event) {
  nlohmann::json j = {{"id", event.id()},
                      {"stamp_s", event.stamp_s()},
                      {"level", proto::Event::Level_Name(event.level())},
                      {"kind", proto::Event::Kind_Name(event.kind())},
                      {"score", event.score()},
                      {"box_world", to_json(event.box_world())},
                      {"centroid_world", to_json(event.centroid_world())},
                      {"detail", event.detail()}};
  j["object_id"] = event.has_object_id() ? nlohmann::json(event.object_id()) : nlohmann::json(nullptr);
  nlohmann::json evidence = nlohmann::json::object();
  for (const auto& [name, value] : event.evidence()) evidence[name] = value;
  j["evidence"] = evidence;
  if (event.has_region()) {
    const auto& r = event.region();
    j["region"] = {{"x", r.x()}, {"y", r.y()}, {"width", r.width()}, {"height", r.height()}, {"area", r.area()}};
  }
  if (event.has_displacement_world()) j["displacement_world"] = to_json(event.displacement_world());
  if (event.indices_before_size() > 0)
    j["indices_before"] = std::vector<int>(event.indices_before().begin(), event.indices_before().end());
  if (event.indices_after_size() > 0)
    j["indices_after"] = std::vector<int>(event.indices_after().begin(), event.indices_after().end());
  if (event.pending_ids_size() > 0)
    j["pending_ids"] = std::vector<std::uint64_t>(event.pending_ids().begin(), event.pending_ids().end());
  return j;
}

nlohmann::json to_json(const proto::PendingChange& change) {
  return {{"id", change.id()},
          {"kind", proto::PendingChange::Kind_Name(change.kind())},
          {"box_world", to_json(change.box_world())},
          {"centroid_world", to_json(change.centroid_world())},
          {"hits", change.hits()},
          {"hits_needed", change.hits_needed()},
          {"camera", change.camera()}};
}

nlohmann::json to_json(const proto::HealthReply& health) {
  return {{"status", "OK"},
          {"version", health.version()},
          {"uptime_s", health.uptime_s()},
          {"frames_processed", health.frames_processed()}};
}

nlohmann::json to_json(const proto::StatsReply& s) {
  return {{"frames_processed", s.frames_processed()},
          {"frames_skipped", s.frames_skipped()},
          {"points_processed", s.points_processed()},
          {"events_emitted", s.events_emitted()},
          {"map_leaf_nodes", s.map_leaf_nodes()},
          {"map_occupied_leaves", s.map_occupied_leaves()},
          {"map_memory_bytes", s.map_memory_bytes()},
          {"map_resolution_m", s.map_resolution_m()},
          {"last_frame_ms", s.last_frame_ms()},
          {"mean_frame_ms", s.mean_frame_ms()},
          {"tracked_objects", s.tracked_objects()},
          {"connections", s.connections()},
          {"uptime_s", s.uptime_s()},
          {"keyframes", s.keyframes()},
          {"mesh_triangles", s.mesh_triangles()},
          {"appearance_memory_bytes", s.appearance_memory_bytes()}};
}

nlohmann::json to_json(const proto::LocalizationResult& l) {
  return {{"mode", l.mode()},
          {"state", l.state()},
          {"pose", to_json(l.pose())},
          {"correction_m", l.correction_m()},
          {"correction_deg", l.correction_deg()},
          {"inlier_fraction", l.inlier_fraction()},
          {"residual_m", l.residual_m()},
          {"reference_keyframe", l.reference_keyframe()},
          {"reason", l.reason()},
          {"compute_ms", l.compute_ms()},
          {"T_world_odom", to_json(l.t_world_odom())},
          {"relocalized", l.relocalized()},
          {"homed", l.homed()},
          {"feature_matches", l.feature_matches()},
          {"feature_inliers", l.feature_inliers()},
          {"relocalization_ms", l.relocalization_ms()},
          {"odom_change_m", l.odom_change_m()},
          {"odom_change_deg", l.odom_change_deg()},
          {"camera", l.camera()}};
}

nlohmann::json to_json(const proto::LocalizationReply& reply) {
  nlohmann::json cameras = nlohmann::json::array();
  for (const auto& c : reply.cameras()) cameras.push_back(to_json(c));
  return {{"cameras", std::move(cameras)}};
}

nlohmann::json to_json(const proto::IngestReply& ingest) {
  nlohmann::json planes = nlohmann::json::array(), clusters = nlohmann::json::array(),
                 events = nlohmann::json::array();
  for (const auto& p : ingest.planes()) planes.push_back(to_json(p));
  for (const auto& c : ingest.clusters()) clusters.push_back(to_json(c));
  for (const auto& e : ingest.events()) events.push_back(to_json(e));
  return {{"frame_index", ingest.frame_index()},
          {"points", ingest.points()},
          {"planes", std::move(planes)},
          {"clusters", std::move(clusters)},
          {"events", std::move(events)},
          {"segment_ms", ingest.segment_ms()},
          {"insert_ms", ingest.insert_ms()},
          {"total_ms", ingest.total_ms()},
          {"skipped", ingest.skipped()},
          {"frames_skipped", ingest.frames_skipped()},
          {"localization", to_json(ingest.localization())}};
}

std::string occupancy_name(proto::OccupancyState state) {
  switch (state) {
    case proto::OCCUPANCY_FREE: return "free";
    case proto::OCCUPANCY_OCCUPIED: return "occupied";
    default: return "unknown";
  }
}

nlohmann::json to_json(const proto::BoxOccupancy& box) {
  return {{"state", occupancy_name(box.state())},
          {"occupied_voxels", box.occupied_voxels()},
          {"free_voxels", box.free_voxels()},
          {"unknown_voxels", box.unknown_voxels()}};
}

std::string text(const proto::Vec3& v) { return "(" + fixed(v.x()) + ", " + fixed(v.y()) + ", " + fixed(v.z()) + ")"; }

std::string text(const proto::Plane& plane) {
  std::ostringstream os;
  os << "  plane " << plane.id() << ": normal " << text(plane.normal()) << ", d " << fixed(plane.d()) << ", area "
     << fixed(plane.area_m2(), 2) << " m2, " << plane.inlier_count() << " inliers, centroid " << text(plane.centroid());
  return os.str();
}

std::string text(const proto::Object& object) {
  std::ostringstream os;
  const auto& e = object.box().extents();
  os << "  object " << object.id();
  if (object.supported_by() != 0) os << " on object " << object.supported_by();
  os << ": at " << text(object.centroid()) << ", size " << fixed(e.x()) << " x "
     << fixed(e.y()) << " x " << fixed(e.z()) << " m, " << object.point_count() << " points, rgb ("
     << fixed(object.mean_rgb().x(), 0) << ", " << fixed(object.mean_rgb().y(), 0) << ", "
     << fixed(object.mean_rgb().z(), 0) << "), seen " << object.observations() << "x (first "
     << fixed(object.first_seen_s(), 2) << " s, last " << fixed(object.last_seen_s(), 2) << " s)";
  if (object.has_ontology()) {
    const auto& c = object.ontology();
    os << "\n    class " << c.class_name();
    if (c.class_name() != "unknown") os << " (score " << fixed(c.score(), 2) << ")";
    if (c.has_primitive()) {
      const auto& p = c.primitive();
      if (p.shape() == "box") {
        os << ": box " << fixed(1000 * p.size_x_m(), 1) << " x " << fixed(1000 * p.size_y_m(), 1) << " x "
           << fixed(1000 * p.height_m(), 1) << " mm";
      } else {
        os << ": " << p.shape() << " r " << fixed(1000 * p.radius_m(), 1) << " mm, h " << fixed(1000 * p.height_m(), 1) << " mm";
      }
    }
    for (const auto& g : c.grasps()) os << "\n      grasp " << g.name() << " (" << g.kind() << ") at " << text(g.position());
  }
  if (object.foreground()) {
    auto names = [](const auto& list) {
      std::string s;
      for (const auto& n : list) s += (s.empty() ? "" : " ") + n;
      return s.empty() ? std::string("none") : s;
    };
    os << "\n    foreground since " << fixed(object.promoted_s(), 2) << " s" << (object.in_hand() ? ", in a hand" : "")
       << (object.visible() ? "" : ", not seen now") << "; free DoFs: " << names(object.free_dofs())
       << "; frozen: " << names(object.frozen_dofs()) << "; handled " << object.handlings_size() << "x";
  }
  return os.str();
}

std::string text(const proto::Cluster& cluster) {
  std::ostringstream os;
  const auto& e = cluster.box().extents();
  os << "  cluster on "
     << (cluster.supported_by() >= 0 ? "cluster " + std::to_string(cluster.supported_by()) : "plane " + std::to_string(cluster.plane_id()))
     << ": at " << text(cluster.centroid()) << ", size "
     << fixed(e.x()) << " x " << fixed(e.y()) << " x " << fixed(e.z()) << " m, " << cluster.point_count()
     << " points";
  return os.str();
}

std::string text(const proto::Event& event) {
  std::ostringstream os;
  os << "  event " << event.id() << " " << proto::Event::Kind_Name(event.kind()) << " ("
     << proto::Event::Level_Name(event.level()) << ", score " << fixed(event.score(), 2) << ")";
  if (event.has_object_id()) os << " object " << event.object_id();
  os << " at " << text(event.centroid_world()) << ", t " << fixed(event.stamp_s(), 2) << " s";
  if (!event.detail().empty()) os << ": " << event.detail();
  return os.str();
}

std::string text(const proto::PendingChange& change) {
  std::ostringstream os;
  os << "  pending " << change.id() << " " << proto::PendingChange::Kind_Name(change.kind()) << " at "
     << text(change.centroid_world()) << ", box " << text(change.box_world().min()) << " .. " << text(change.box_world().max())
     << ", seen in " << change.hits() << " of " << change.hits_needed() << " frames, camera "
     << (change.camera().empty() ? "(default)" : "'" + change.camera() + "'");
  return os.str();
}

std::string text(const proto::LocalizationResult& l) {
  std::ostringstream out;
  out << "camera " << (l.camera().empty() ? "(default)" : "'" + l.camera() + "'") << ": " << l.state() << " (mode " << l.mode()
      << (l.homed() ? ", homed" : ", not homed") << ")" << (l.reason().empty() ? "" : ": " + l.reason()) << "\n";
  const auto row = [&](const proto::Pose& p, int r) {
    std::string line;
    for (int c = 0; c < 4; ++c) line += (c ? " " : "") + fixed(p.matrix_size() == 16 ? p.matrix(4 * r + c) : (r == c ? 1.0 : 0.0), 4);
    return line;
  };
  for (int r = 0; r < 3; ++r) out << "  " << (r == 0 ? "T_world_odom  " : "              ") << row(l.t_world_odom(), r) << "\n";
  out << "  last correction " << fixed(1000 * l.odom_change_m(), 1) << " mm, " << fixed(l.odom_change_deg(), 2) << " deg of T_world_odom; "
      << fixed(1000 * l.correction_m(), 1) << " mm, " << fixed(l.correction_deg(), 2) << " deg from the given pose\n"
      << "  quality         " << fixed(100 * l.inlier_fraction(), 1) << " % depth inliers, residual " << fixed(1000 * l.residual_m(), 1)
      << " mm";
  // Aligned to a keyframe, or (track mode, reference 0 with a measured fit) to the camera's previous frame.
  if (l.reference_keyframe() != 0) {
    out << ", keyframe " << l.reference_keyframe();
  } else if (l.inlier_fraction() > 0) {
    out << ", the previous frame";
  }
  if (l.relocalized()) out << "; relocalized: " << l.feature_inliers() << " of " << l.feature_matches() << " feature matches, "
                           << fixed(l.relocalization_ms(), 1) << " ms";
  out << "\n";
  return out.str();
}

}  // namespace scenewatch::cli

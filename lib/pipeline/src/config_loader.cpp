#include "scenewatch/pipeline/config_loader.h"

#include <limits>
#include <system_error>

#include "scenewatch/core/yaml_value.h"

namespace scenewatch::pipeline {
namespace fs = std::filesystem;

YamlSection::YamlSection(const YAML::Node& node, std::string name) : node_(node), name_(std::move(name)) {}

Status YamlSection::check_is_map() const {
  if (!node_.IsDefined() || node_.IsNull() || node_.IsMap()) return {};
  return yaml::key_error(name_, "must be a mapping of keys to values");
}

Status YamlSection::finish() const {
  if (!node_.IsDefined() || node_.IsNull() || !node_.IsMap()) return {};
  for (const auto& kv : node_) {
    auto key = yaml::read_key(kv.first, name_);
    if (!key) return key.error();
    if (seen_.count(*key) == 0) return yaml::key_error(path(*key), "unknown key");
  }
  return {};
}

const std::vector<std::string>& pipeline_sections() {
  static const std::vector<std::string> kSections = {"sensor",     "background", "segmentation", "tracking", "change",
                                                     "appearance", "surprise",   "events",       "foreground", "workspace",
                                                     "localization"};
  return kSections;
}

namespace {
// Reads every key of a section in turn; stops at the first error.
template <typename... Reads>
Status read_all(Reads&&... reads) {
  Status st;
  ((st.ok() ? (st = reads(), 0) : 0), ...);
  return st;
}

// The `sensor:` section: a profile's defaults first, then any coefficient written beside it.
Status read_sensor(const YAML::Node& node, SensorModel& sensor) {
  YamlSection s(node, "sensor");
  if (auto st = s.check_is_map(); !st) return st;
  std::string profile = sensor.profile;
  if (auto st = s.read("profile", profile); !st) return st;
  if (profile != sensor.profile) {
    auto named = sensor_profile(profile);
    if (!named) return named.error();
    sensor = *named;
  }
  if (auto st = read_all([&] { return s.read("axial_base_m", sensor.axial_base_m); },
                         [&] { return s.read("axial_quad_per_m", sensor.axial_quad_per_m); },
                         [&] { return s.read("axial_offset_m", sensor.axial_offset_m); },
                         [&] { return s.read("lateral_px", sensor.lateral_px); },
                         [&] { return s.read("min_range_m", sensor.min_range_m); },
                         [&] { return s.read("max_range_m", sensor.max_range_m); },
                         [&] { return s.read("border_px", sensor.border_px); },
                         [&] { return s.read("registration_px", sensor.registration_px); },
                         [&] { return s.read("fit_colour_registration", sensor.fit_colour_registration); },
                         [&] { return s.read("pose_sigma_m", sensor.pose_sigma_m); },
                         [&] { return s.read("pose_sigma_deg", sensor.pose_sigma_deg); });
      !st)
    return st;
  return s.finish();
}

// The `localization:` section (issue 29).
Status read_localization(const YAML::Node& node, localization::Config& l) {
  YamlSection s(node, "localization");
  if (auto st = s.check_is_map(); !st) return st;
  std::string mode = localization::mode_name(l.mode);
  constexpr int kNotGiven = std::numeric_limits<int>::min();
  int finest_level_stride = kNotGiven;  // the key before `strides`: its last entry
  if (auto st = read_all([&] { return s.read("mode", mode); }, [&] { return s.read("levels", l.pyramid.levels); },
                         [&] { return s.read("finest_halvings", l.pyramid.finest_halvings); },
                         [&] { return s.read("iterations", l.alignment.iterations); },
                         [&] { return s.read("max_correspondence_m", l.alignment.max_correspondence_m); },
                         [&] { return s.read("photometric_weight", l.alignment.photometric_weight); },
                         [&] { return s.read("min_gradient", l.alignment.min_gradient); },
                         [&] { return s.read("photometric_on_finest_level", l.alignment.photometric_on_finest_level); },
                         [&] { return s.read("strides", l.alignment.strides); },
                         [&] { return s.read("finest_level_stride", finest_level_stride); },
                         [&] { return s.read("min_inlier_fraction", l.min_inlier_fraction); },
                         [&] { return s.read("min_conditioning", l.min_conditioning); },
                         [&] { return s.read("max_correction_m", l.max_correction_m); },
                         [&] { return s.read("max_correction_deg", l.max_correction_deg); },
                         [&] { return s.read("reference_keyframes", l.reference_keyframes); },
                         [&] { return s.read("drift_m_per_frame", l.drift_m_per_frame); },
                         [&] { return s.read("drift_deg_per_frame", l.drift_deg_per_frame); },
                         [&] { return s.read("noise_m", l.noise_m); },
                         [&] { return s.read("noise_deg", l.noise_deg); },
                         [&] { return s.read("rehome_after_lost_frames", l.rehome_after_lost_frames); },
                         [&] { return s.read("max_features", l.relocalization.features.max_features); },
                         [&] { return s.read("candidate_keyframes", l.relocalization.candidate_keyframes); },
                         [&] { return s.read("ransac_iterations", l.relocalization.ransac.iterations); },
                         [&] { return s.read("match_ratio", l.relocalization.match_ratio); },
                         [&] { return s.read("min_feature_inliers", l.relocalization.min_inliers); });
      !st)
    return st;
  auto parsed = localization::parse_mode(mode);
  if (!parsed) return yaml::key_error(s.path("mode"), parsed.error().message);
  l.mode = *parsed;
  if (finest_level_stride != kNotGiven) {
    if (finest_level_stride < 1 || finest_level_stride > 4)
      return yaml::key_error(s.path("finest_level_stride"),
                             "1 to 4 (every pixel to every fourth), got " + std::to_string(finest_level_stride));
    if (l.alignment.strides.empty()) l.alignment.strides.push_back(1);
    l.alignment.strides.back() = finest_level_stride;
  }
  return s.finish();
}

// The `background:` section.
Status read_background(const YAML::Node& node, Config& c) {
  YamlSection s(node, "background");
  auto& b = c.background;
  if (auto st = s.check_is_map(); !st) return st;
  if (auto st = read_all([&] { return s.read("resolution_m", b.resolution_m); }, [&] { return s.read("max_range_m", b.max_range_m); },
                         [&] { return s.read("prob_hit", b.prob_hit); }, [&] { return s.read("prob_miss", b.prob_miss); },
                         [&] { return s.read("clamp_min", b.clamp_min); }, [&] { return s.read("clamp_max", b.clamp_max); },
                         [&] { return s.read("fast_insertion", b.fast_insertion); },
                         [&] { return s.read("ray_stop_after", b.ray_stop_after); },
                         [&] { return s.read("insert_stride_px", b.insert_stride_px); });
      !st)
    return st;
  return s.finish();
}

// The `segmentation:` section.
Status read_segmentation(const YAML::Node& node, Config& c) {
  YamlSection s(node, "segmentation");
  auto& g = c.segmentation;
  if (auto st = s.check_is_map(); !st) return st;
  std::vector<double> up;
  if (auto st = read_all([&] { return s.read("voxel_size_m", g.voxel_size_m); }, [&] { return s.read("max_planes", g.max_planes); },
                         [&] { return s.read("plane_distance_m", g.plane_distance_m); },
                         [&] { return s.read("ransac_iterations", g.ransac_iterations); }, [&] { return s.read("seed", g.seed); },
                         [&] { return s.read("min_plane_area_m2", g.min_plane_area_m2); },
                         [&] { return s.read("plane_connectivity_m", g.plane_connectivity_m); },
                         [&] { return s.read("up_vector", up); },
                         [&] { return s.read("max_normal_angle_deg", g.max_normal_angle_deg); },
                         [&] { return s.read("min_object_height_m", g.min_object_height_m); },
                         [&] { return s.read("max_object_height_m", g.max_object_height_m); },
                         [&] { return s.read("height_noise_sigmas", g.height_noise_sigmas); },
                         [&] { return s.read("cluster_tolerance_m", g.cluster_tolerance_m); },
                         [&] { return s.read("min_cluster_points", g.min_cluster_points); },
                         [&] { return s.read("max_cluster_points", g.max_cluster_points); },
                         [&] { return s.read("split_concave", g.split_concave); },
                         [&] { return s.read("patch_size_m", g.patch_size_m); },
                         [&] { return s.read("concavity_tolerance_deg", g.concavity_tolerance_deg); },
                         [&] { return s.read("crease_angle_deg", g.crease_angle_deg); },
                         [&] { return s.read("join_occluded", g.join_occluded); },
                         [&] { return s.read("recover_image_grid", g.recover_image_grid); },
                         [&] { return s.read("bridge_hidden_support", g.bridge_hidden_support); },
                         [&] { return s.read("split_depth_steps", g.split_depth_steps); },
                         [&] { return s.read("split_stacked", g.split_stacked); },
                         [&] { return s.read("split_colour_edges", g.split_colour_edges); });
      !st)
    return st;
  if (!up.empty()) {
    if (up.size() != 3) return yaml::key_error(s.path("up_vector"), "must be [x, y, z] or null");
    g.up = Eigen::Vector3d(up[0], up[1], up[2]);
  }
  return s.finish();
}

// The `tracking:` section.
Status read_tracking(const YAML::Node& node, Config& c) {
  YamlSection s(node, "tracking");
  if (auto st = s.check_is_map(); !st) return st;
  if (auto st = read_all([&] { return s.read("match_distance_m", c.tracking.match_distance_m); },
                         [&] { return s.read("gone_free_fraction", c.tracking.gone_free_fraction); },
                         [&] { return s.read("confirm_frames", c.tracking.confirm_frames); },
                         [&] { return s.read("min_extent_cells", c.tracking.min_extent_cells); },
                         [&] { return s.read("gone_frames", c.tracking.gone_frames); },
                         [&] { return s.read("max_range_m", c.tracking.max_range_m); },
                         [&] { return s.read("segmentation_stride_px", c.tracking.segmentation_stride_px); });
      !st)
    return st;
  return s.finish();
}

// The `change:` section.
Status read_change(const YAML::Node& node, Config& c) {
  YamlSection s(node, "change");
  auto& g = c.change;
  if (auto st = s.check_is_map(); !st) return st;
  if (auto st = read_all([&] { return s.read("enabled", c.change_enabled); },
                         [&] { return s.read("persistence_frames", g.persistence_frames); },
                         [&] { return s.read("persistence_match_m", g.persistence_match_m); },
                         [&] { return s.read("sigma_factor", g.sigma_factor); },
                         [&] { return s.read("max_range_m", g.max_range_m); },
                         [&] { return s.read("min_surface_probability", g.min_surface_probability); },
                         [&] { return s.read("min_tolerance_m", g.min_tolerance_m); },
                         [&] { return s.read("cluster_voxel_m", g.cluster_voxel_m); },
                         [&] { return s.read("min_object_size_m", g.min_object_size_m); },
                         [&] { return s.read("min_object_area_m2", g.min_object_area_m2); },
                         [&] { return s.read("min_cluster_points", g.min_cluster_points); },
                         [&] { return s.read("move_max_size_ratio", g.move_max_size_ratio); },
                         [&] { return s.read("move_max_color_distance", g.move_max_color_distance); },
                         [&] { return s.read("move_min_distance_m", g.move_min_distance_m); },
                         [&] { return s.read("complete_objects", g.complete_objects); },
                         [&] { return s.read("completion_evidence_share", g.completion_evidence_share); },
                         [&] { return s.read("completion_object_share", g.completion_object_share); },
                         [&] { return s.read("completion_stride_px", g.completion_stride_px); },
                         [&] { return s.read("trusted_pixels_only", g.trusted_pixels_only); },
                         [&] { return s.read("measure_pose", g.measure_pose); },
                         [&] { return s.read("witness_per_camera", g.witness_per_camera); },
                         [&] { return s.read("incidence_aware", g.incidence_aware); },
                         [&] { return s.read("see_through_dark", g.see_through_dark); });
      !st)
    return st;
  return s.finish();
}

// The `appearance:` section.
Status read_appearance(const YAML::Node& node, Config& c) {
  YamlSection s(node, "appearance");
  if (auto st = s.check_is_map(); !st) return st;
  background::AppearanceConfig& a = c.appearance;
  if (auto st = read_all([&] { return s.read("enabled", a.enabled); },
                         [&] { return s.read("keyframe_min_translation_m", a.keyframe_min_translation_m); },
                         [&] { return s.read("keyframe_min_rotation_deg", a.keyframe_min_rotation_deg); },
                         [&] { return s.read("max_keyframes", a.max_keyframes); },
                         [&] { return s.read("memory_budget_mb", a.memory_budget_mb); },
                         [&] { return s.read("mesh_stride_px", a.mesh_stride_px); },
                         [&] { return s.read("mesh_max_depth_jump", a.mesh_max_depth_jump); },
                         [&] { return s.read("depth_views", a.depth_views); });
      !st)
    return st;
  return s.finish();
}

// The `surprise:` section.
Status read_surprise(const YAML::Node& node, Config& c) {
  YamlSection s(node, "surprise");
  if (auto st = s.check_is_map(); !st) return st;
  surprise::SurpriseConfig& u = c.surprise;
  if (auto st = read_all([&] { return s.read("enabled", u.enabled); }, [&] { return s.read("a0", u.prior.a0); },
                         [&] { return s.read("b0", u.prior.b0); }, [&] { return s.read("min_samples", u.min_samples); },
                         [&] { return s.read("max_samples", u.view.max_samples); },
                         [&] { return s.read("depth_tolerance_m", u.view.depth_tolerance_m); },
                         [&] { return s.read("depth_tolerance_rel", u.view.depth_tolerance_rel); },
                         [&] { return s.read("fill_holes_px", u.view.fill_holes_px); },
                         [&] { return s.read("sample_step_px", u.view.sample_step_px); },
                         [&] { return s.read("fill_holes_max_jump", u.view.fill_holes_max_jump); },
                         [&] { return s.read("threshold_high", u.regions.threshold_high); },
                         [&] { return s.read("threshold_low", u.regions.threshold_low); },
                         [&] { return s.read("open_radius_px", u.regions.open_radius_px); },
                         [&] { return s.read("min_area_px", u.regions.min_area_px); },
                         [&] { return s.read("min_extent_px", u.regions.min_extent_px); },
                         [&] { return s.read("adopt_after_frames", u.adopt_after_frames); },
                         [&] { return s.read("photometric", u.robust.photometric); },
                         [&] { return s.read("align_radius_px", u.robust.align_radius_px); },
                         [&] { return s.read("align_min_kl", u.robust.align_min_kl); },
                         [&] { return s.read("familiar_after_frames", u.familiar_after_frames); });
      !st)
    return st;
  return s.finish();
}

// The `foreground:` section.
Status read_foreground(const YAML::Node& node, Config& c) {
  YamlSection s(node, "foreground");
  if (auto st = s.check_is_map(); !st) return st;
  foreground::ForegroundConfig& f = c.foreground;
  if (auto st = read_all([&] { return s.read("enabled", f.enabled); },
                         [&] { return s.read("contact_m", f.contact_m); },
                         [&] { return s.read("promote_translation_m", f.promote_translation_m); },
                         [&] { return s.read("promote_rotation_deg", f.promote_rotation_deg); },
                         [&] { return s.read("vacated_fraction", f.vacated_fraction); },
                         [&] { return s.read("promote_lift_m", f.promote_lift_m); },
                         [&] { return s.read("touch_timeout_frames", f.touch_timeout_frames); },
                         [&] { return s.read("release_frames", f.release_frames); },
                         [&] { return s.read("dof_translation_m", f.dof.translation_m); },
                         [&] { return s.read("dof_rotation_deg", f.dof.rotation_deg); },
                         [&] { return s.read("search_radius_m", f.search_radius_m); },
                         [&] { return s.read("mask_m", f.mask_m); },
                         [&] { return s.read("max_model_points", f.max_model_points); },
                         [&] { return s.read("grow_model", f.grow_model); },
                         [&] { return s.read("grow_max_rmse_m", f.grow_max_rmse_m); },
                         [&] { return s.read("grow_min_inlier_fraction", f.grow_min_inlier_fraction); },
                         [&] { return s.read("reacquire_radius_m", f.reacquire_radius_m); },
                         [&] { return s.read("hands", f.hands.enabled); },
                         [&] { return s.read("hand_min_area_m2", f.hands.min_hand_area_m2); },
                         [&] { return s.read("hand_max_area_m2", f.hands.max_hand_area_m2); });
      !st)
    return st;
  return s.finish();
}

// The `events:` section.
Status read_events(const YAML::Node& node, Config& c) {
  YamlSection s(node, "events");
  if (auto st = s.check_is_map(); !st) return st;
  if (auto st = read_all([&] { return s.read("max_log", c.max_event_log); },
                         [&] { return s.read("appearance_persistence_frames", c.fusion.persistence_frames); },
                         [&] { return s.read("appearance_match_m", c.fusion.match_m); },
                         [&] { return s.read("merge_margin_m", c.fusion.margin_m); },
                         [&] { return s.read("silence_frames", c.fusion.zone_frames); });
      !st)
    return st;
  return s.finish();
}

// The `workspace:` section.
Status read_workspace(const YAML::Node& node, Config& c) {
  YamlSection s(node, "workspace");
  if (auto st = s.check_is_map(); !st) return st;
  if (auto st = s.read("radius_m", c.workspace_radius_m); !st) return st;
  return s.finish();
}

}  // namespace

Status read_pipeline_config(const YAML::Node& root, Config& c) {
  if (auto st = read_sensor(root["sensor"], c.sensor); !st) return st;
  c.change.sensor = c.sensor;  // what reads config.change alone (scenewatch diff) sees the same sensor
  c.segmentation.sensor = c.sensor;
  if (auto st = read_background(root["background"], c); !st) return st;
  if (auto st = read_segmentation(root["segmentation"], c); !st) return st;
  if (auto st = read_tracking(root["tracking"], c); !st) return st;
  if (auto st = read_change(root["change"], c); !st) return st;
  if (auto st = read_appearance(root["appearance"], c); !st) return st;
  if (auto st = read_surprise(root["surprise"], c); !st) return st;
  if (auto st = read_foreground(root["foreground"], c); !st) return st;
  if (auto st = read_events(root["events"], c); !st) return st;
  if (auto st = read_localization(root["localization"], c.localization); !st) return st;
  if (auto st = read_workspace(root["workspace"], c); !st) return st;
  return validate(c);
}

Result<YAML::Node> load_yaml_file(const fs::path& path, const std::vector<std::string>& known_sections) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return not_found("'" + path.string() + "': no such config file");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::ParserException& e) {
    return invalid_argument("'" + path.string() + "': YAML syntax error at line " + std::to_string(e.mark.line + 1) +
                            ", column " + std::to_string(e.mark.column + 1) + ": " + e.msg);
  } catch (const YAML::Exception& e) {
    return invalid_argument("'" + path.string() + "': " + e.what());
  }
  if (root.IsNull()) return root;  // an empty file means all defaults
  if (!root.IsMap()) return invalid_argument("'" + path.string() + "': the top level must be a mapping of sections");
  for (const auto& kv : root) {
    auto key = yaml::read_key(kv.first, "'" + path.string() + "'");
    if (!key) return key.error();
    if (std::find(known_sections.begin(), known_sections.end(), *key) == known_sections.end()) {
      return invalid_argument("'" + path.string() + "': unknown section '" + *key + "'");
    }
  }
  return root;
}

}  // namespace scenewatch::pipeline

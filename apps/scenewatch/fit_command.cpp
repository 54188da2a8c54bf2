// scenewatch fit: primitives fitted to each object of a scene (offline, no daemon): the
// segmentation module finds the objects, the ontology module fits and classifies them.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "config_file.h"
#include "frame_spec.h"
#include "install_layout.h"
#include "scenewatch/io/cloud_io.h"
#include "scenewatch/ontology/describe.h"
#include "scenewatch/segmentation/tabletop.h"
#include "subcommand.h"

namespace scenewatch::cli {
namespace {

using nlohmann::json;

json vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

std::string fixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

std::string direction(const Eigen::Vector3d& v) {
  return "(" + fixed(v.x(), 3) + ", " + fixed(v.y(), 3) + ", " + fixed(v.z(), 3) + ")";
}

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) * 180.0 / M_PI;
}

json to_json(const ontology::Primitive& p) {
  json j = {{"kind", ontology::to_string(p.kind)}, {"points", p.indices.size()}, {"rms_m", p.rms_m}};
  switch (p.kind) {
    case ontology::PrimitiveKind::kPlane: j["point"] = vec(p.point); j["normal"] = vec(p.direction); break;
    case ontology::PrimitiveKind::kCylinder: j["axis_point"] = vec(p.point); j["axis"] = vec(p.direction); j["radius_m"] = p.radius_m; break;
    case ontology::PrimitiveKind::kSphere: j["center"] = vec(p.point); j["radius_m"] = p.radius_m; break;
    case ontology::PrimitiveKind::kCone: j["apex"] = vec(p.point); j["axis"] = vec(p.direction); j["half_angle_deg"] = p.half_angle_deg; break;
  }
  return j;
}

std::string text(const ontology::Primitive& p) {
  std::string s = std::string(ontology::to_string(p.kind)) + " (" + std::to_string(p.indices.size()) + " points, rms " +
                  fixed(p.rms_m * 1000, 1) + " mm)";
  switch (p.kind) {
    case ontology::PrimitiveKind::kPlane: return s + ": normal " + direction(p.direction);
    case ontology::PrimitiveKind::kCylinder: return s + ": radius " + fixed(p.radius_m * 1000, 1) + " mm, axis " + direction(p.direction);
    case ontology::PrimitiveKind::kSphere: return s + ": radius " + fixed(p.radius_m * 1000, 1) + " mm";
    case ontology::PrimitiveKind::kCone: return s + ": half angle " + fixed(p.half_angle_deg, 1) + " deg, axis " + direction(p.direction);
  }
  return s;
}

json to_json(const ontology::CylinderFit& c, const Eigen::Vector3d& up) {
  return {{"center", vec(c.center)},         {"axis", vec(c.axis)},
          {"radius_m", c.radius_m},          {"height_m", c.height_m},
          {"rms_m", c.rms_m},                {"coverage_deg", c.coverage_deg},
          {"inliers", c.inliers},            {"axis_fixed_upright", c.axis_fixed},
          {"source", c.from_detection ? "detection" : "upright_circle_fit"},
          {"tilt_from_support_deg", angle_deg(c.axis, up)}};
}

json to_json(const ontology::ShapeFit& f) {
  json j = {{"shape", ontology::to_string(f.shape)}, {"center", vec(f.center)}, {"rms_m", f.rms_m}};
  switch (f.shape) {
    case ontology::ClassShape::kCylinder:
    case ontology::ClassShape::kFrustum:
      j["axis"] = vec(f.axis);
      j["radius_m"] = f.radius_m;
      j["height_m"] = f.height_m;
      j["coverage_deg"] = f.coverage_deg;
      j["axis_tilt_deg"] = f.axis_tilt_deg;
      j["inner_fraction"] = f.inner_fraction;
      if (f.shape == ontology::ClassShape::kFrustum) {
        j["bottom_radius_m"] = f.bottom_radius_m;
        j["top_radius_m"] = f.top_radius_m;
        j["taper_deg"] = f.taper_deg;
      }
      break;
    case ontology::ClassShape::kSphere: j["radius_m"] = f.radius_m; j["coverage_deg"] = f.coverage_deg; break;
    case ontology::ClassShape::kBox:
      j["axis"] = vec(f.axis);
      j["x_axis"] = vec(f.x_axis);
      j["size_m"] = json::array({f.size_m.x(), f.size_m.y(), f.height_m});
      break;
  }
  return j;
}

std::string text(const ontology::ShapeFit& f) {
  std::string s = ontology::to_string(f.shape);
  switch (f.shape) {
    case ontology::ClassShape::kCylinder:
      return s + " r " + fixed(f.radius_m * 1000, 1) + " mm, h " + fixed(f.height_m * 1000, 1) + " mm, tilt " +
             fixed(f.axis_tilt_deg, 1) + " deg, rms " + fixed(f.rms_m * 1000, 2) + " mm, coverage " + fixed(f.coverage_deg, 0) + " deg";
    case ontology::ClassShape::kFrustum:
      return s + " r " + fixed(f.bottom_radius_m * 1000, 1) + ".." + fixed(f.top_radius_m * 1000, 1) + " mm (taper " +
             fixed(f.taper_deg, 1) + " deg), h " + fixed(f.height_m * 1000, 1) + " mm, rms " + fixed(f.rms_m * 1000, 2) +
             " mm, inside wall " + fixed(f.inner_fraction, 2);
    case ontology::ClassShape::kSphere:
      return s + " r " + fixed(f.radius_m * 1000, 1) + " mm, rms " + fixed(f.rms_m * 1000, 2) + " mm";
    case ontology::ClassShape::kBox:
      return s + " " + fixed(f.size_m.x() * 1000, 0) + " x " + fixed(f.size_m.y() * 1000, 0) + " x " + fixed(f.height_m * 1000, 0) +
             " mm, rms " + fixed(f.rms_m * 1000, 2) + " mm";
  }
  return s;
}

json to_json(const ontology::GraspPose& g) {
  return {{"name", g.name},         {"kind", ontology::to_string(g.kind)}, {"position", vec(g.position)},
          {"approach", vec(g.approach)}, {"closing", vec(g.closing)},        {"width_m", g.width_m}};
}

/// The completed model of object `id` as DIR/object-ID-CLASS.pcd and .ply; the message on failure.
std::string write_completion(const std::string& dir, std::size_t id, const ontology::ObjectDescription& d) {
  Cloud cloud;
  for (const auto& p : d.completed_points) {
    PointT q;
    q.getVector3fMap() = p.cast<float>();
    q.r = 230;
    q.g = 160;
    q.b = 40;
    cloud.points.push_back(q);
  }
  cloud.width = static_cast<std::uint32_t>(cloud.points.size());
  cloud.height = 1;
  const std::string stem = dir + "/object-" + std::to_string(id) + "-" + d.class_name;
  if (Status s = io::write_pcd(stem + ".pcd", cloud); !s) return s.error().message;
  if (Status s = io::write_ply(stem + ".ply", cloud); !s) return s.error().message;
  return {};
}

}  // namespace

int run_fit(const FitOptions& options) {
  auto loaded = read_config_file(options.config);
  if (!loaded) return fail(loaded.error().message);
  const std::string classes_file = options.classes.empty() ? (apps::config_dir() / "ontology.yaml").string() : options.classes;
  auto library = ontology::load_classes_file(classes_file);
  if (!library) return fail(library.error().message);
  if (!options.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(options.out_dir, ec);
    if (ec) return fail(options.out_dir + ": cannot create the folder: " + ec.message());
  }
  InputOptions inputs(sequence_options(options.depth_scale_m));
  inputs.bag = options.bag;
  auto frame = load_one_frame(options.file, inputs);
  if (!frame) {
    const std::string& message = frame.error().message;
    return fail(message.find(options.file) != std::string::npos ? message : options.file + ": " + message);
  }
  const Cloud& cloud = *frame->cloud;
  if (count_valid(cloud) == 0) return fail(options.file + ": the cloud has no valid (finite) point");
  // In the camera frame, as `scenewatch segment`: the sensor at the origin.
  const auto t0 = std::chrono::steady_clock::now();
  const segmentation::Segmentation scene = segmentation::segment(cloud, loaded->segmentation);
  const double segment_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  json objects = json::array(), planes = json::array();
  std::string lines;
  for (const Plane& plane : scene.planes) {
    planes.push_back({{"id", plane.id}, {"normal", vec(plane.normal)}, {"d", plane.d}, {"area_m2", plane.area_m2},
                      {"centroid", vec(plane.centroid)}});
    lines += "  plane " + std::to_string(plane.id) + ": normal " + direction(plane.normal) + ", area " +
             fixed(plane.area_m2, 2) + " m2, centroid " + direction(plane.centroid) + "\n";
  }
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const ObjectCluster& object = scene.objects[i];
    Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
    for (const Plane& plane : scene.planes)
      if (plane.id == object.plane_id) up = plane.normal;
    const auto t1 = std::chrono::steady_clock::now();
    auto described = ontology::describe(cloud, object.indices, up, *library);
    const double fit_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();
    json j = {{"id", i}, {"plane_id", object.plane_id}, {"points", object.point_count}, {"centroid", vec(object.centroid)},
              {"fit_ms", fit_ms}};
    lines += "  object " + std::to_string(i) + " (" + std::to_string(object.point_count) + " points, at " +
             direction(object.centroid) + "):";
    if (!described) {
      j["error"] = described.error().message;
      lines += " no fit: " + described.error().message + "\n";
      objects.push_back(std::move(j));
      continue;
    }
    const ontology::ObjectDescription& d = *described;
    const ontology::ObjectFit* fit = &d.fit;
    json shapes = json::array();
    for (const auto& s : fit->shapes) shapes.push_back(to_json(s));
    j["shapes"] = std::move(shapes);
    j["best"] = fit->best >= 0 ? json(ontology::to_string(fit->shapes[static_cast<std::size_t>(fit->best)].kind)) : json(nullptr);
    j["cylinder"] = fit->cylinder ? to_json(*fit->cylinder, up) : json(nullptr);
    j["timing_ms"] = {{"normals", fit->normals_ms}, {"detection", fit->detection_ms}, {"refinement", fit->refinement_ms}};
    j["class"] = d.class_name;
    j["score"] = d.score;
    j["primitive"] = d.primitive ? to_json(*d.primitive) : json(nullptr);
    json grasps = json::array(), candidates = json::array();
    for (const auto& g : d.grasps) grasps.push_back(to_json(g));
    for (const auto& m : d.candidates) {
      candidates.push_back({{"class", m.class_name}, {"accepted", m.accepted}, {"score", m.score}, {"reason", m.reason}});
    }
    j["grasps"] = std::move(grasps);
    j["candidates"] = std::move(candidates);
    std::string written;
    if (!options.out_dir.empty() && !d.completed_points.empty()) {
      if (std::string error = write_completion(options.out_dir, i, d); !error.empty()) return fail(error);
      written = options.out_dir + "/object-" + std::to_string(i) + "-" + d.class_name + ".pcd";
      j["completed_file"] = written;
    }
    j["completed_points"] = d.completed_points.size();
    objects.push_back(std::move(j));

    lines += fit->best >= 0 ? " best " + text(fit->shapes[static_cast<std::size_t>(fit->best)]) : std::string(" no primitive found");
    lines += ", " + fixed(fit_ms, 1) + " ms\n";
    for (std::size_t s = 1; s < fit->shapes.size(); ++s) lines += "      also " + text(fit->shapes[s]) + "\n";
    if (const auto& c = fit->cylinder) {
      lines += std::string("      cylinder refined") + (c->from_detection ? "" : " (from an upright circle fit)") + ": radius " + fixed(c->radius_m * 1000, 1) + " mm, height " + fixed(c->height_m * 1000, 1) +
               " mm, axis " + direction(c->axis) + " (" + fixed(angle_deg(c->axis, up), 1) + " deg from the support's normal" +
               (c->axis_fixed ? ", held upright" : "") + "), rms " + fixed(c->rms_m * 1000, 2) + " mm, coverage " +
               fixed(c->coverage_deg, 0) + " deg, " + std::to_string(c->inliers) + " points\n";
    }
    if (d.class_name != ontology::kUnknownClass) {
      lines += "      class " + d.class_name + " (score " + fixed(d.score, 2) + "): " + text(*d.primitive) + "\n";
      for (const auto& g : d.grasps) {
        lines += "        grasp " + g.name + " (" + ontology::to_string(g.kind) + "): at " + direction(g.position) + ", approach " +
                 direction(g.approach) + ", width " + fixed(g.width_m * 1000, 0) + " mm\n";
      }
      if (!written.empty()) lines += "        completed model: " + written + " (" + std::to_string(d.completed_points.size()) + " points)\n";
    } else {
      lines += "      class unknown" + (d.best_primitive ? " (best primitive " + std::string(ontology::to_string(d.best_primitive->kind)) + ")" : std::string()) + "\n";
    }
    for (const auto& m : d.candidates) {
      if (!m.accepted) lines += "        not " + m.class_name + ": " + m.reason + "\n";
    }
  }

  if (options.json) {
    const json j = {{"file", options.file},           {"points", cloud.points.size()}, {"planes", std::move(planes)},
                    {"segment_ms", segment_ms},       {"objects", std::move(objects)}};
    std::cout << j.dump() << std::endl;
    return kExitOk;
  }
  std::cout << options.file << ": " << cloud.points.size() << " points, " << scene.planes.size()
            << (scene.planes.size() == 1 ? " plane, " : " planes, ") << scene.objects.size()
            << (scene.objects.size() == 1 ? " object" : " objects") << " (segmentation " << fixed(segment_ms, 0) << " ms)\n"
            << lines << std::flush;
  return kExitOk;
}

void add_fit_command(CLI::App& app, Action& action) {
  auto options = std::make_shared<FitOptions>();
  auto* fit = app.add_subcommand(
      "fit", "offline: segment one frame, fit primitives to each object and classify it (no daemon)");
  fit->footer(
      "FILE: a .pcd/.ply cloud, or one frame of an RGB-D sequence folder (DIR:N, DIR/frame-NNNNNN).\n"
      "Shapes by CGAL's Efficient RANSAC on the object's normals; the largest cylinder is refined by\n"
      "least squares, held upright along the support's normal when it stands within 25 degrees of it.\n"
      "Each class's primitive is then fitted and checked against the class's bounds: the object gets the\n"
      "best accepted class (score, grasp points, completed model) or 'unknown' with its best primitive.\n"
      "Example: scenewatch fit ../shared/data/ycb/frame-000003 --depth-scale 0.0001");
  fit->add_option("file", options->file, "cloud file, sequence frame or bag frame (BAG:N)")->required();
  fit->add_flag("--json", options->json, "print JSON (each object's shapes, refined cylinder, class, candidates, grasps and timings)");
  fit->add_option("--config", options->config, "YAML config (its segmentation section is used)");
  fit->add_option("--classes", options->classes, "object classes file (default: the shipped ontology.yaml, in /etc/scenewatch when installed)");
  fit->add_option("--out", options->out_dir,
                  "write each object's completed model (its class's primitive, whole surface) to DIR as object-N-CLASS.pcd and .ply");
  add_depth_scale_option(fit, options->depth_scale_m);
  add_bag_options(fit, options->bag);
  on_parsed(fit, action, [options] { return run_fit(*options); });
}

}  // namespace scenewatch::cli

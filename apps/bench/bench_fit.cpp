// Primitive fitting per object: scenewatch's fit_object (grid k-NN normals, CGAL Efficient RANSAC
// over four shapes, cylinder refinement), the same without cone detection (a candidate default: the
// classes never use a cone but as a nearly straight cylinder), the same with its former kd-tree normals (PCL's
// NormalEstimation), and PCL's cylinder RANSAC (SACSegmentationFromNormals, SACMODEL_CYLINDER, with
// kd-tree normals) on the same clusters, in the same run: the
// objects of the segmented YCB frames and of a simulated frame with a can and a cup. Also the time
// of the whole description (describe(): fit_object plus each shipped class's fit and checks) and
// the class it gives, the shares of fit_object's stages, and fit_object in CPU time beside its
// former configuration (6000 points, no depth-edge margin), which a loaded machine cannot blur.
#include <time.h>

#include <functional>

#include <pcl/ModelCoefficients.h>
#include <pcl/console/print.h>
#include <pcl/features/normal_3d.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/sac_segmentation.h>

#include "bench.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/ontology/describe.h"
#include "scenewatch/ontology/fit.h"
#include "scenewatch/segmentation/tabletop.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"

namespace scenewatch::bench {
namespace {

struct Scene {
  std::string name;
  CloudConstPtr cloud;
  segmentation::Config segmentation;
};

// Evenly spaced valid points, at most max_points, as fit_object takes them.
std::vector<int> subsample(const Cloud& cloud, const std::vector<int>& indices, int max_points) {
  std::vector<int> valid;
  for (const int i : indices)
    if (is_valid(cloud.points[static_cast<std::size_t>(i)])) valid.push_back(i);
  const std::size_t m = std::min(valid.size(), static_cast<std::size_t>(max_points));
  std::vector<int> out(m);
  for (std::size_t i = 0; i < m; ++i) out[i] = valid[i * valid.size() / m];
  return out;
}

// CPU time of this thread in ms: on a machine shared with other builds, wall time counts the
// waits for a core too.
double cpu_ms(const std::function<void()>& f) {
  const auto now = [] {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
  };
  const double t0 = now();
  f();
  return now() - t0;
}

// PCL's cylinder: normals (k = 24, as fit_object) and RANSAC with normals; 0 when none.
double pcl_cylinder_radius(const Cloud& cloud, const std::vector<int>& indices) {
  auto object = std::make_shared<Cloud>();
  for (const int i : indices) object->push_back(cloud.points[static_cast<std::size_t>(i)]);
  pcl::NormalEstimation<PointT, pcl::Normal> estimation;
  estimation.setInputCloud(object);
  estimation.setSearchMethod(std::make_shared<pcl::search::KdTree<PointT>>());
  estimation.setKSearch(24);
  auto normals = std::make_shared<pcl::PointCloud<pcl::Normal>>();
  estimation.compute(*normals);
  pcl::SACSegmentationFromNormals<PointT, pcl::Normal> sac;
  sac.setOptimizeCoefficients(true);
  sac.setModelType(pcl::SACMODEL_CYLINDER);
  sac.setMethodType(pcl::SAC_RANSAC);
  sac.setNormalDistanceWeight(0.1);
  sac.setMaxIterations(1000);
  sac.setDistanceThreshold(0.004);
  sac.setRadiusLimits(0.01, 0.2);
  sac.setInputCloud(object);
  sac.setInputNormals(normals);
  pcl::PointIndices inliers;
  pcl::ModelCoefficients coefficients;
  sac.segment(inliers, coefficients);
  return coefficients.values.size() == 7 && !inliers.indices.empty() ? coefficients.values[6] : 0.0;
}

std::vector<Scene> scenes(const Options& o) {
  std::vector<Scene> out;
  io::SequenceOptions ycb;
  ycb.depth_scale_m = 1e-4;
  if (auto seq = io::open_sequence(o.data_dir / "ycb", ycb)) {
    for (std::size_t i = 0; i < seq->frames.size(); ++i) {
      auto frame = io::load_sequence_frame(*seq, i);
      if (!frame) continue;
      segmentation::Config config;  // the writing tablet of frames 3 and 4 is a small support
      config.min_plane_area_m2 = 0.02;
      config.max_planes = 6;
      out.push_back({"ycb/" + seq->frames[i].name, frame->cloud, config});
    }
  }
  auto scenario = sim::load_scenario(std::filesystem::path(SCENEWATCH_SOURCE_DIR) / "sample_clouds/scenarios/cup_added.yaml");
  if (scenario) {
    if (auto simulator = sim::Simulator::create(*scenario)) {
      if (auto frame = sim::as_frame(simulator->render(1, 0), simulator->scenario().intrinsics, 0.0))
        out.push_back({"sim cup_added after:0", frame->cloud, segmentation::Config{}});
    }
  }
  return out;
}

}  // namespace

int run_fit(const Options& o) {
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);  // "RANSAC found no model" on every box
  std::printf("\n== Primitive fitting per object: scenewatch fit_object vs PCL SACMODEL_CYLINDER (medians of %d runs)\n",
              o.repetitions);
  std::printf("(ours: grid normals; kd: ours with the former kd-tree normals; nrm, det, ref: our normals', shape detection's\n"
              " and refinement's share; kd nrm: the kd-tree normals'; cpu: ours in this thread's CPU time; 6k cpu: the same\n"
              " with the former 6000-point subsample and no depth-edge margin, and its radius; no-cone cpu: ours without\n"
              " cone detection)\n");
  std::printf("%-24s %6s %7s %7s %7s %6s %6s %6s %6s %6s %6s %8s %6s %9s %9s %9s %9s %9s %11s %-8s\n", "scene/object", "points", "ours ms",
              "kd ms", "pcl ms", "nrm", "det", "ref", "kd nrm", "cpu", "6k cpu", "no-cone", "ratio", "best", "ours r mm", "6k r mm", "kd r mm",
              "pcl r mm", "describe ms", "class");
  std::vector<double> ratios, ours_all, kd_all, pcl_all, describe_all, normals_all, kd_normals_all, radius_diffs, cpu_all,
      former_cpu_all, no_cone_cpu_all, no_cone_radius_diffs;
  const ontology::FitConfig config;
  ontology::FitConfig kd_config;
  kd_config.normal_search = ontology::NormalSearch::kKdTree;
  ontology::FitConfig former;
  former.max_points = 6000;
  former.edge_margin_deg = 0;
  ontology::FitConfig no_cones;
  no_cones.detect_cone = false;
  auto classes = ontology::load_classes_file(std::filesystem::path(SCENEWATCH_SOURCE_DIR) / "config/ontology.yaml");
  if (!classes) {
    std::fprintf(stderr, "%s\n", classes.error().message.c_str());
    return 1;
  }
  for (const Scene& scene : scenes(o)) {
    const Cloud& cloud = *scene.cloud;
    const segmentation::Segmentation seg = segmentation::segment(cloud, scene.segmentation);
    for (std::size_t k = 0; k < seg.objects.size(); ++k) {
      const ObjectCluster& object = seg.objects[k];
      if (object.indices.size() < 500) continue;
      Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
      for (const auto& plane : seg.planes)
        if (plane.id == object.plane_id) up = plane.normal;
      const std::vector<int> same = subsample(cloud, object.indices, config.max_points);
      std::vector<double> ours, kd, theirs, described, normals, detection, refinement, kd_normals, cpu, former_cpu, no_cone_cpu;
      Result<ontology::ObjectFit> fit = invalid_argument("not run"), kd_fit = invalid_argument("not run");
      Result<ontology::ObjectFit> former_fit = invalid_argument("not run"), no_cone_fit = invalid_argument("not run");
      Result<ontology::ObjectDescription> description = invalid_argument("not run");
      double pcl_radius = 0;
      for (int r = 0; r < o.repetitions; ++r) {
        ours.push_back(time_ms([&] { fit = ontology::fit_object(cloud, object.indices, config, up); }));
        kd.push_back(time_ms([&] { kd_fit = ontology::fit_object(cloud, object.indices, kd_config, up); }));
        cpu.push_back(cpu_ms([&] { fit = ontology::fit_object(cloud, object.indices, config, up); }));
        former_cpu.push_back(cpu_ms([&] { former_fit = ontology::fit_object(cloud, object.indices, former, up); }));
        no_cone_cpu.push_back(cpu_ms([&] { no_cone_fit = ontology::fit_object(cloud, object.indices, no_cones, up); }));
        theirs.push_back(time_ms([&] { pcl_radius = pcl_cylinder_radius(cloud, same); }));
        described.push_back(time_ms([&] { description = ontology::describe(cloud, object.indices, up, *classes); }));
        if (fit) {
          normals.push_back(fit->normals_ms);
          detection.push_back(fit->detection_ms);
          refinement.push_back(fit->refinement_ms);
        }
        if (kd_fit) kd_normals.push_back(kd_fit->normals_ms);
      }
      if (!fit || !kd_fit || !former_fit || !no_cone_fit) continue;
      const double a = median(ours), akd = median(kd), b = median(theirs);
      ratios.push_back(a / b);
      ours_all.push_back(a);
      kd_all.push_back(akd);
      pcl_all.push_back(b);
      normals_all.push_back(median(normals));
      kd_normals_all.push_back(median(kd_normals));
      describe_all.push_back(median(described));
      const double r_ours = fit->cylinder ? fit->cylinder->radius_m * 1000 : 0.0;
      const double r_kd = kd_fit->cylinder ? kd_fit->cylinder->radius_m * 1000 : 0.0;
      const double r_former = former_fit->cylinder ? former_fit->cylinder->radius_m * 1000 : 0.0;
      cpu_all.push_back(median(cpu));
      former_cpu_all.push_back(median(former_cpu));
      no_cone_cpu_all.push_back(median(no_cone_cpu));
      if (fit->cylinder && no_cone_fit->cylinder) no_cone_radius_diffs.push_back(std::abs(r_ours - no_cone_fit->cylinder->radius_m * 1000));
      if (fit->cylinder && kd_fit->cylinder) radius_diffs.push_back(std::abs(r_ours - r_kd));
      const char* best = fit->best >= 0 ? ontology::to_string(fit->shapes[static_cast<std::size_t>(fit->best)].kind) : "-";
      const std::string name = scene.name + " #" + std::to_string(k);
      std::printf("%-24s %6zu %7.1f %7.1f %7.1f %6.1f %6.1f %6.1f %6.1f %6.1f %6.1f %8.1f %6.2f %9s %9.1f %9.1f %9.1f %9.1f %11.1f %-8s\n",
                  name.c_str(), same.size(), a, akd, b, median(normals), median(detection), median(refinement), median(kd_normals),
                  median(cpu), median(former_cpu), median(no_cone_cpu), a / b, best, r_ours, r_former, r_kd, pcl_radius * 1000, median(described),
                  description ? description->class_name.c_str() : "error");
    }
  }
  std::printf("objects %zu: median ours %.1f ms (normals %.1f), with kd-tree normals %.1f ms (normals %.1f), PCL cylinder %.1f ms, "
              "median ratio ours/PCL %.2f; median describe %.1f ms\n",
              ratios.size(), median(ours_all), median(normals_all), median(kd_all), median(kd_normals_all), median(pcl_all),
              median(ratios), median(describe_all));
  std::printf("CPU time: median ours %.1f ms, with the former 6000-point subsample and no edge margin %.1f ms, without cones %.1f ms\n",
              median(cpu_all), median(former_cpu_all), median(no_cone_cpu_all));
  std::sort(no_cone_radius_diffs.begin(), no_cone_radius_diffs.end());
  if (!no_cone_radius_diffs.empty())
    std::printf("refined cylinder radius, with vs without cones, |difference| over %zu objects: median %.2f mm, above 0.1 mm on %td "
                "(max %.2f mm)\n", no_cone_radius_diffs.size(), median(no_cone_radius_diffs),
                no_cone_radius_diffs.end() - std::upper_bound(no_cone_radius_diffs.begin(), no_cone_radius_diffs.end(), 0.1),
                no_cone_radius_diffs.back());
  std::sort(radius_diffs.begin(), radius_diffs.end());
  if (!radius_diffs.empty())
    std::printf("refined cylinder radius, grid vs kd-tree normals, |difference| over %zu objects: median %.2f mm, max %.2f mm\n",
                radius_diffs.size(), median(radius_diffs), radius_diffs.back());
  return 0;
}

}  // namespace scenewatch::bench

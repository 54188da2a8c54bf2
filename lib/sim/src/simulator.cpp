#include "scenewatch/sim/simulator.h"

#include <algorithm>

#include "random.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/sim/sequence_writer.h"

namespace scenewatch::sim {
namespace {

constexpr std::uint64_t kStreamCamera = 21;

/// The table as render items: a box top and four cylindrical legs, label 1.
std::vector<RenderItem> table_items(const TableSpec& t) {
  std::vector<RenderItem> items;
  if (!t.present) return items;
  const Pose T_ws = t.T_world_support();
  RenderItem top;
  top.shape.kind = ShapeKind::kBox;
  top.shape.size_m = Eigen::Vector3d(t.size_m.x(), t.size_m.y(), t.thickness_m);
  top.T_world_item = T_ws * Eigen::Translation3d(0, 0, -t.thickness_m);
  top.material = t.top;
  top.label = kLabelTable;
  items.push_back(top);
  for (int sx : {-1, 1}) {
    for (int sy : {-1, 1}) {
      RenderItem leg;
      leg.shape.kind = ShapeKind::kCylinder;
      leg.shape.radius_m = t.leg_radius_m;
      leg.shape.height_m = t.height_m - t.thickness_m;
      leg.T_world_item = T_ws * Eigen::Translation3d(sx * (0.5 * t.size_m.x() - t.leg_inset_m),
                                                     sy * (0.5 * t.size_m.y() - t.leg_inset_m), -t.height_m);
      leg.material = t.legs;
      leg.label = kLabelTable;
      items.push_back(leg);
    }
  }
  return items;
}

ObjectTruth object_truth(const SceneObject& o) { return {o.id, o.name, o.label(), o.shape, o.material.transparent}; }

}  // namespace

Simulator::Simulator(Scenario scenario, RaycasterConfig raycaster)
    : scenario_(std::move(scenario)), raycaster_(raycaster), sensor_(scenario_.sensor, scenario_.seed) {}

Result<Simulator> Simulator::create(Scenario scenario, RaycasterConfig raycaster) {
  if (auto st = validate(scenario); !st) return st.error();
  Simulator sim(std::move(scenario), raycaster);
  sim.static_items_ = table_items(sim.scenario_.table);
  std::vector<SceneObject> objects = sim.scenario_.objects;
  for (std::size_t p = 0; p < sim.scenario_.phases.size(); ++p) {
    const PhaseSpec& phase = sim.scenario_.phases[p];
    if (p > 0) {
      // The scene as the previous phase left it, then this phase's changes.
      const Animator& prev = sim.animators_.back();
      const WorldState end = prev.state_at(sim.scenario_.phases[p - 1].frames - 1);
      objects = prev.objects();
      for (std::size_t i = 0; i < objects.size(); ++i) objects[i].T_world_object = end.T_world_object[i];
      const SceneChanges& ch = phase.changes;
      objects.erase(std::remove_if(objects.begin(), objects.end(),
                                   [&](const SceneObject& o) {
                                     return std::find(ch.remove.begin(), ch.remove.end(), o.id) != ch.remove.end();
                                   }),
                    objects.end());
      for (const ObjectMove& m : ch.move) {
        for (SceneObject& o : objects) {
          if (o.id == m.id) o.T_world_object = m.T_world_object;
        }
      }
      for (const SceneObject& o : ch.add) objects.push_back(o);
    }
    auto animator = Animator::create(objects, phase.hand, sim.scenario_.touch_tolerance_m);
    if (!animator) {
      return invalid_argument("phases[" + std::to_string(p) + "]." + animator.error().message);
    }
    sim.animators_.push_back(std::move(*animator));
  }
  return sim;
}

std::uint64_t Simulator::frame_key(std::size_t phase, int frame) const {
  return (static_cast<std::uint64_t>(phase) << 32) | static_cast<std::uint32_t>(frame);
}

RenderScene Simulator::render_scene(std::size_t phase, int frame) const {
  const Animator& anim = animators_[phase];
  const WorldState state = anim.state_at(frame);
  RenderScene scene;
  scene.room = scenario_.room;
  scene.lighting = scenario_.lighting;
  scene.items = static_items_;
  for (std::size_t i = 0; i < anim.objects().size(); ++i) {
    const SceneObject& o = anim.objects()[i];
    scene.items.push_back({o.shape, state.T_world_object[i], o.material, o.label()});
  }
  if (state.T_world_hand) {
    for (const HandPart& part : anim.hand_parts()) {
      scene.items.push_back({part.shape, *state.T_world_hand * part.T_hand_part, anim.hand().skin, kLabelHand});
    }
  }
  return scene;
}

FrameTruth Simulator::frame_truth(std::size_t phase, int frame) const {
  const Animator& anim = animators_[phase];
  const WorldState state = anim.state_at(frame);
  FrameTruth t;
  t.name = frame_name(frame);
  t.stamp_s = frame / scenario_.frame_rate_hz;
  const std::uint64_t camera_seed = detail::hash(scenario_.seed, kStreamCamera, phase, 0);
  t.T_world_camera = camera_pose(scenario_.phases[phase].camera, frame, scenario_.phases[phase].frames, camera_seed);
  t.T_world_camera_reported = sensor_.reported_pose(t.T_world_camera, frame_key(phase, frame));
  t.T_world_hand = state.T_world_hand;
  for (std::size_t i = 0; i < anim.objects().size(); ++i) {
    t.objects.push_back({anim.objects()[i].id, state.T_world_object[i]});
  }
  t.held = state.held;
  t.touched = state.touched;
  return t;
}

SequenceTruth Simulator::sequence_truth(std::size_t phase) const {
  SequenceTruth t;
  t.scenario = scenario_.name;
  t.phase = scenario_.phases[phase].name;
  t.seed = scenario_.seed;
  t.intrinsics = scenario_.intrinsics;
  t.T_world_support = scenario_.table.present ? scenario_.table.T_world_support() : Pose::Identity();
  t.thresholds = scenario_.dof_thresholds;
  for (const SceneObject& o : animators_[phase].objects()) t.objects.push_back(object_truth(o));
  for (int f = 0; f < frame_count(phase); ++f) t.frames.push_back(frame_truth(phase, f));
  analyse_interactions(&t);
  return t;
}

std::vector<ChangeTruth> Simulator::changes() const {
  std::vector<ChangeTruth> out;
  for (std::size_t p = 1; p < phase_count(); ++p) {
    SequenceTruth before = sequence_truth(p - 1);
    SequenceTruth after = sequence_truth(p);
    out.push_back(compare_sequences(before, after));
  }
  return out;
}

void Simulator::render_ideal(std::size_t phase, int frame, IdealView* view) {
  const FrameTruth truth = frame_truth(phase, frame);
  raycaster_.render(render_scene(phase, frame), truth.T_world_camera, scenario_.intrinsics, view);
}

void Simulator::apply_sensor(std::size_t phase, int frame, const IdealView& view, ColorImage* color,
                             DepthImage* depth) const {
  sensor_.apply(view, scenario_.intrinsics.fx, frame_key(phase, frame), color, depth);
}

SimFrame Simulator::render(std::size_t phase, int frame) {
  SimFrame out;
  out.truth = frame_truth(phase, frame);
  raycaster_.render(render_scene(phase, frame), out.truth.T_world_camera, scenario_.intrinsics, &view_);
  apply_sensor(phase, frame, view_, &out.color, &out.depth);
  out.labels.width = view_.width;
  out.labels.height = view_.height;
  out.labels.labels = view_.labels;
  return out;
}

Result<RunSummary> Simulator::write(const std::filesystem::path& out_dir, const ProgressFn& progress) {
  RunSummary summary;
  std::size_t total = 0;
  for (std::size_t p = 0; p < phase_count(); ++p) total += static_cast<std::size_t>(frame_count(p));
  std::vector<SequenceTruth> truths;
  for (std::size_t p = 0; p < phase_count(); ++p) {
    const std::filesystem::path dir = phase_count() == 1 ? out_dir : out_dir / scenario_.phases[p].name;
    auto writer = SequenceWriter::create(dir);
    if (!writer) return writer.error();
    SequenceTruth truth = sequence_truth(p);
    for (int f = 0; f < frame_count(p); ++f) {
      const SimFrame frame = render(p, f);
      if (auto st = writer->write_frame(f, frame.truth.stamp_s, frame.color, frame.depth, frame.labels,
                                        frame.truth.T_world_camera_reported);
          !st) {
        return st.error();
      }
      ++summary.frames_written;
      if (progress) progress(scenario_.phases[p].name, summary.frames_written, total);
    }
    if (auto st = writer->finish(scenario_.intrinsics, truth); !st) return st.error();
    summary.sequence_dirs.push_back(dir);
    truths.push_back(std::move(truth));
  }
  if (phase_count() > 1) {
    std::vector<ChangeTruth> changes;
    for (std::size_t p = 1; p < truths.size(); ++p) changes.push_back(compare_sequences(truths[p - 1], truths[p]));
    summary.changes_json = out_dir / "changes.json";
    if (auto st = write_changes(summary.changes_json, scenario_.name, changes); !st) return st.error();
  }
  return summary;
}

Result<Frame> as_frame(const SimFrame& rendered, const Intrinsics& K, double stamp_s) {
  auto cloud = io::rgbd_to_cloud(rendered.color, rendered.depth, K);
  if (!cloud) return cloud.error();
  Frame frame;
  frame.cloud = *cloud;
  frame.T_world_camera = rendered.truth.T_world_camera_reported;
  frame.intrinsics = K;
  frame.has_color = true;
  frame.stamp_s = stamp_s;
  frame.source = "sim " + rendered.truth.name;
  return frame;
}

}  // namespace scenewatch::sim

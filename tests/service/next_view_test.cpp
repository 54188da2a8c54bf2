// NextBestView (issue 31) through the real scenewatchd on a loopback port, and `scenewatch
// next-view` against it: the simulator's cup_added seen by a hand-held camera from one side.
#include <gtest/gtest.h>

#include <cstdio>

#include <nlohmann/json.hpp>

#include "daemon_harness.h"
#include "scenewatch.pb.h"
#include "scenewatch/service/frame_parser.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"

namespace scenewatch::test {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;
using service::Client;

Eigen::Matrix4d matrix_of(const proto::Pose& pose) {
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = pose.matrix(i);
  return m;
}

void set_pose(const Pose& T, proto::Pose* out) {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out->add_matrix(T.matrix()(r, c));
}

class NextViewTest : public ::testing::Test {
 protected:
  void TearDown() override {
    if (HasFailure()) std::cerr << "---- scenewatchd log ----\n" << daemon_.log() << "-------------------------\n";
    daemon_ = Daemon();
    std::error_code ec;
    fs::remove_all(tmp_, ec);
  }
  fs::path tmp_ = make_temp_dir("next_view");
  Daemon daemon_;
};

TEST_F(NextViewTest, ObjectsAndEventsGetViewsOfWhatIsUnseen) {
  auto loaded = sim::load_scenario(source_dir() / "sample_clouds/scenarios/cup_added.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  const sim::Scenario scenario = sim::with_frames(sim::with_resolution(*loaded, 320, 240), 12);
  auto simulator = sim::Simulator::create(scenario);
  ASSERT_TRUE(simulator.ok()) << simulator.error().message;
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, "  model_dir: " + (tmp_ / "model").string() +
                                                  "\nsegmentation:\n  up_vector: [0, 0, 1]\n"));
  Client client = daemon_.connect();
  double stamp = 0;
  Pose last_camera = Pose::Identity();
  for (std::size_t phase = 0; phase < simulator->phase_count(); ++phase) {
    for (int f = 0; f < simulator->frame_count(phase); ++f) {
      const sim::SimFrame rendered = simulator->render(phase, f);
      last_camera = rendered.truth.T_world_camera_reported;
      auto frame = sim::as_frame(rendered, scenario.intrinsics, stamp += 1.0 / 30);
      ASSERT_TRUE(frame.ok());
      proto::Request r;
      *r.mutable_ingest_frame() = service::make_ingest_frame(*frame);
      ASSERT_EQ(call(client, r).status().code(), proto::Status::OK);
    }
  }

  // The blue box (id 1 of the scenario, at x 0.15 y 0.12): the tracked object nearest it.
  const auto objects = call(client, request([](proto::Request& r) { r.mutable_get_objects(); }));
  ASSERT_GT(objects.objects().objects_size(), 0);
  const Eigen::Vector3d box_truth = scenario.objects[0].T_world_object.translation();
  const proto::Object* box = nullptr;
  for (const auto& o : objects.objects().objects()) {
    const Eigen::Vector2d c(o.centroid().x(), o.centroid().y());
    if ((c - box_truth.head<2>()).norm() < 0.08) box = &o;
  }
  ASSERT_NE(box, nullptr);

  // Around the box on a cap: ranked, and the best one expects to see more of it than is known now.
  auto nbv = call(client, request([&](proto::Request& r) {
    r.mutable_next_best_view()->set_object_id(box->id());
    r.mutable_next_best_view()->set_n(4);
  }));
  ASSERT_EQ(nbv.status().code(), proto::Status::OK) << nbv.status().message();
  const auto& reply = nbv.next_best_view();
  EXPECT_EQ(reply.measure(), "rear_side_entropy");
  ASSERT_EQ(reply.views_size(), 4);
  EXPECT_EQ(reply.candidates(), 64u);
  for (int i = 0; i + 1 < reply.views_size(); ++i) EXPECT_GE(reply.views(i).score(), reply.views(i + 1).score());
  EXPECT_GT(reply.views(0).score(), 0.0);
  EXPECT_GT(reply.views(0).expected_coverage(), reply.coverage());
  EXPECT_TRUE(validate_rigid(matrix_of(reply.views(0).pose())));
  // The camera came from -x: the best view looks from the far side.
  const Eigen::Vector3d centre = 0.5 * (Eigen::Vector3d(reply.target().min().x(), reply.target().min().y(), reply.target().min().z()) +
                                        Eigen::Vector3d(reply.target().max().x(), reply.target().max().y(), reply.target().max().z()));
  const Eigen::Vector3d best = matrix_of(reply.views(0).pose()).block<3, 1>(0, 3);
  EXPECT_GT((best - centre).x(), 0.0) << reply.views(0).why();

  // The seed's planner: one view on the sphere around the box, on the side the camera did not see.
  auto seed = call(client, request([&](proto::Request& r) {
    r.mutable_next_best_view()->set_object_id(box->id());
    r.mutable_next_best_view()->set_measure("covariance");
    r.mutable_next_best_view()->set_n(4);
    r.mutable_next_best_view()->set_radius_m(0.6);
  }));
  ASSERT_EQ(seed.status().code(), proto::Status::OK) << seed.status().message();
  EXPECT_EQ(seed.next_best_view().measure(), "covariance");
  ASSERT_EQ(seed.next_best_view().views_size(), 1) << "one view whatever n";
  const auto& planned = seed.next_best_view().views(0);
  EXPECT_TRUE(validate_rigid(matrix_of(planned.pose())));
  const Eigen::Vector3d planned_at = matrix_of(planned.pose()).block<3, 1>(0, 3);
  EXPECT_NEAR((planned_at - centre).norm(), 0.6, 1e-6) << planned.why();
  EXPECT_GT((planned_at - centre).x(), 0.0) << "the camera came from -x: " << planned.why();  // measured +0.53
  EXPECT_NE(planned.why().find("3.23"), std::string::npos) << planned.why();
  EXPECT_NE(planned.why().find("observed by keyframes"), std::string::npos) << planned.why();
  std::printf("covariance: camera at (%.3f %.3f %.3f), %s\n", planned_at.x(), planned_at.y(), planned_at.z(), planned.why().c_str());
  auto seed_box = call(client, request([&](proto::Request& r) {
    *r.mutable_next_best_view()->mutable_box() = reply.target();
    r.mutable_next_best_view()->set_measure("covariance_322");
  }));
  EXPECT_EQ(seed_box.status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_NE(seed_box.status().message().find("covariance_322"), std::string::npos) << seed_box.status().message();
  EXPECT_NE(seed_box.status().message().find("object_id"), std::string::npos) << seed_box.status().message();

  // A list of two reachable poses: where the camera was, and its mirror image through the box.
  Pose mirrored = last_camera;
  mirrored.translation() = 2.0 * centre - last_camera.translation();
  mirrored.translation().z() = last_camera.translation().z();
  mirrored.linear() = (Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()) * last_camera.linear()).matrix();
  auto listed = call(client, request([&](proto::Request& r) {
    auto* q = r.mutable_next_best_view();
    q->set_object_id(box->id());
    q->set_constraint(proto::NextBestView::CONSTRAINT_LIST);
    set_pose(last_camera, q->add_poses());
    set_pose(mirrored, q->add_poses());
  }));
  ASSERT_EQ(listed.status().code(), proto::Status::OK) << listed.status().message();
  ASSERT_EQ(listed.next_best_view().views_size(), 2);
  EXPECT_LT((matrix_of(listed.next_best_view().views(0).pose()).block<3, 1>(0, 3) - mirrored.translation()).norm(), 1e-9);
  EXPECT_GT(listed.next_best_view().views(0).score(), listed.next_best_view().views(1).score());

  // The added cup's event: the views that see most of its box.
  const auto events = call(client, request([](proto::Request& r) { r.mutable_get_events(); }));
  ASSERT_EQ(events.events().events_size(), 1);
  auto confirm = call(client, request([&](proto::Request& r) {
    r.mutable_next_best_view()->set_event_id(events.events().events(0).id());
  }));
  ASSERT_EQ(confirm.status().code(), proto::Status::OK) << confirm.status().message();
  EXPECT_EQ(confirm.next_best_view().measure(), "visible");
  ASSERT_EQ(confirm.next_best_view().views_size(), 5);
  EXPECT_GT(confirm.next_best_view().views(0).score(), 0.0);
  const auto& event_box = events.events().events(0).box_world();
  EXPECT_LE(confirm.next_best_view().target().min().x(), event_box.min().x());
  EXPECT_GE(confirm.next_best_view().target().max().z(), event_box.max().z());

  // Bad requests get errors; the daemon goes on answering.
  auto unknown = call(client, request([](proto::Request& r) { r.mutable_next_best_view()->set_object_id(999999); }));
  EXPECT_EQ(unknown.status().code(), proto::Status::NOT_FOUND);
  auto no_target = call(client, request([](proto::Request& r) { r.mutable_next_best_view(); }));
  EXPECT_EQ(no_target.status().code(), proto::Status::INVALID_ARGUMENT);
  auto bad_measure = call(client, request([&](proto::Request& r) {
    r.mutable_next_best_view()->set_object_id(box->id());
    r.mutable_next_best_view()->set_measure("entropy");
  }));
  EXPECT_EQ(bad_measure.status().code(), proto::Status::INVALID_ARGUMENT);
  EXPECT_NE(bad_measure.status().message().find("measure"), std::string::npos);
  EXPECT_EQ(call(client, request([](proto::Request& r) { r.mutable_health(); })).status().code(), proto::Status::OK);

  // The CLI: --json gives views with 16-number poses.
  const auto& b = reply.target();
  auto cli = run_command({cli_binary().string(), "next-view", "--box", std::to_string(b.min().x()), std::to_string(b.min().y()),
                          std::to_string(b.min().z()), std::to_string(b.max().x()), std::to_string(b.max().y()),
                          std::to_string(b.max().z()), "-n", "2", "--json", "--port", std::to_string(daemon_.port())},
                         tmp_);
  ASSERT_EQ(cli.exit_code, 0) << cli.err;
  const json j = json::parse(cli.out);
  ASSERT_EQ(j.at("views").size(), 2u);
  EXPECT_EQ(j.at("views")[0].at("pose").size(), 16u);
  EXPECT_GT(j.at("views")[0].at("score").get<double>(), 0.0);
  EXPECT_TRUE(j.at("views")[0].contains("expected_coverage"));
  auto cli_seed = run_command({cli_binary().string(), "next-view", "--object", std::to_string(box->id()), "--measure", "covariance",
                               "--json", "--port", std::to_string(daemon_.port())},
                              tmp_);
  ASSERT_EQ(cli_seed.exit_code, 0) << cli_seed.err;
  const json js = json::parse(cli_seed.out);
  EXPECT_EQ(js.at("measure"), "covariance");
  ASSERT_EQ(js.at("views").size(), 1u);
  EXPECT_EQ(js.at("views")[0].at("pose").size(), 16u);
  auto usage = run_command({cli_binary().string(), "next-view", "--port", std::to_string(daemon_.port())}, tmp_);
  EXPECT_EQ(usage.exit_code, 2) << usage.err;
}

}  // namespace
}  // namespace scenewatch::test

// Ingestion: PCD/PLY in every encoding, PNG, RGB-D, intrinsics, poses, TUM, sequences; and every
// kind of bad file, each with a message that names the file and the problem.
#include <gtest/gtest.h>

#include <map>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <Eigen/Eigenvalues>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>

#include "scenewatch/io/cloud_io.h"
#include "scenewatch/io/image_io.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/io/sequence.h"
#include "test_data.h"

namespace scenewatch::io {
namespace {
namespace fs = std::filesystem;

class IoTest : public ::testing::Test {
 protected:
  fs::path write_text(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }
  test::TempDir dir_{"io"};
};

Cloud small_cloud() {
  Cloud c;
  for (int i = 0; i < 50; ++i) {
    PointT p;
    p.x = 0.01f * i;
    p.y = -0.02f * i;
    p.z = 1.0f + 0.001f * i;
    p.r = static_cast<std::uint8_t>(i);
    p.g = 200;
    p.b = static_cast<std::uint8_t>(255 - i);
    c.push_back(p);
  }
  return c;
}

void expect_error_mentions(const Error& e, const std::vector<std::string>& words) {
  for (const auto& w : words) EXPECT_NE(e.message.find(w), std::string::npos) << "'" << e.message << "' lacks '" << w << "'";
}

TEST_F(IoTest, PcdAllEncodingsRoundTrip) {
  const Cloud c = small_cloud();
  pcl::PCDWriter w;
  ASSERT_EQ(w.writeASCII((dir_ / "a.pcd").string(), c), 0);
  ASSERT_EQ(w.writeBinary((dir_ / "b.pcd").string(), c), 0);
  ASSERT_EQ(w.writeBinaryCompressed((dir_ / "c.pcd").string(), c), 0);
  for (const char* name : {"a.pcd", "b.pcd", "c.pcd"}) {
    auto r = read_cloud(dir_ / name);
    ASSERT_TRUE(r.ok()) << name << ": " << r.error().message;
    ASSERT_EQ(r->cloud->size(), c.size());
    EXPECT_TRUE(r->has_color);
    EXPECT_FALSE(r->organized);
    EXPECT_EQ(r->valid_points, c.size());
    for (std::size_t i = 0; i < c.size(); ++i) {
      EXPECT_NEAR(r->cloud->points[i].x, c[i].x, 1e-5);
      EXPECT_EQ(r->cloud->points[i].r, c[i].r);
      EXPECT_EQ(r->cloud->points[i].b, c[i].b);
    }
  }
}

TEST_F(IoTest, XyzOnlyPcdGetsGreyAndNoColourFlag) {
  pcl::PointCloud<pcl::PointXYZ> c;
  for (int i = 0; i < 10; ++i) c.push_back(pcl::PointXYZ(i, 0, 1));
  ASSERT_EQ(pcl::io::savePCDFileBinary((dir_ / "xyz.pcd").string(), c), 0);
  auto r = read_cloud(dir_ / "xyz.pcd");
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_FALSE(r->has_color);
  EXPECT_EQ(r->cloud->points[3].g, 128);
}

TEST_F(IoTest, PlyAsciiAndBinary) {
  const Cloud c = small_cloud();
  ASSERT_EQ(pcl::io::savePLYFileBinary((dir_ / "b.ply").string(), c), 0);
  ASSERT_EQ(pcl::io::savePLYFileASCII((dir_ / "a.ply").string(), c), 0);
  for (const char* name : {"a.ply", "b.ply"}) {
    auto r = read_cloud(dir_ / name);
    ASSERT_TRUE(r.ok()) << name << ": " << r.error().message;
    EXPECT_EQ(r->cloud->size(), c.size());
    EXPECT_TRUE(r->has_color);
    EXPECT_NEAR(r->cloud->points[49].z, c[49].z, 1e-5);
  }
  // A hand-written PLY with only x y z.
  auto p = write_text("hand.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                  "property float z\nend_header\n0 0 1\n1 0 1\n0 1 1\n");
  auto r = read_cloud(p);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r->cloud->size(), 3u);
  EXPECT_FALSE(r->has_color);
}

TEST_F(IoTest, RealMosdCloudWithLabelField) {
  SCENEWATCH_REQUIRE_DATA("mosd/learn/learn0.pcd");
  const auto path = test::data_dir() / "mosd/learn/learn0.pcd";
  auto r = read_cloud(path);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r->cloud->width, 640u);
  EXPECT_EQ(r->cloud->height, 480u);
  EXPECT_TRUE(r->organized);
  EXPECT_TRUE(r->has_color);
  EXPECT_GT(r->valid_points, 100000u);
  EXPECT_LT(r->valid_points, 640u * 480u) << "invalid Kinect pixels are NaN";
  auto labels = read_pcd_labels(path);
  ASSERT_TRUE(labels.ok()) << labels.error().message;
  ASSERT_EQ(labels->size(), 640u * 480u);
  EXPECT_GT(std::count(labels->begin(), labels->end(), 1u), 10000) << "label 1 is the table";
  // Organized Kinect geometry: x / z at pixel u matches fx = 525, cx = 319.5.
  const PointT& p = r->cloud->at(400, 300);
  ASSERT_TRUE(is_valid(p));
  EXPECT_NEAR(525.0 * p.x / p.z + 319.5, 400.0, 1.0);
}

TEST_F(IoTest, MissingFileIsNotFound) {
  auto r = read_cloud(dir_ / "nope.pcd");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kNotFound);
  expect_error_mentions(r.error(), {"nope.pcd", "no such file"});
}

TEST_F(IoTest, TruncatedBinaryPcd) {
  ASSERT_EQ(pcl::PCDWriter().writeBinary((dir_ / "t.pcd").string(), small_cloud()), 0);
  fs::resize_file(dir_ / "t.pcd", fs::file_size(dir_ / "t.pcd") - 100);
  auto r = read_cloud(dir_ / "t.pcd");
  ASSERT_FALSE(r.ok());
  expect_error_mentions(r.error(), {"t.pcd", "truncated"});
}

TEST_F(IoTest, TruncatedCompressedPcd) {
  SCENEWATCH_REQUIRE_DATA("mosd/learn/learn0.pcd");
  const auto src = test::data_dir() / "mosd/learn/learn0.pcd";
  fs::copy_file(src, dir_ / "cut.pcd");
  fs::resize_file(dir_ / "cut.pcd", fs::file_size(src) / 2);
  auto r = read_cloud(dir_ / "cut.pcd");
  ASSERT_FALSE(r.ok());
  expect_error_mentions(r.error(), {"cut.pcd", "truncated"});
}

TEST_F(IoTest, HeaderThatDisagreesWithData) {
  auto p = write_text("bad.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 5\nHEIGHT 1\n"
                                 "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 10\nDATA ascii\n0 0 1\n0 0 1\n");
  auto r = read_cloud(p);
  ASSERT_FALSE(r.ok());
  expect_error_mentions(r.error(), {"bad.pcd"});
  // An ascii body shorter than the header says.
  auto q = write_text("short.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 4\nHEIGHT 1\n"
                                   "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\nDATA ascii\n0 0 1\n0 0 1\n");
  auto s = read_cloud(q);
  ASSERT_FALSE(s.ok()) << "2 of 4 declared points must not pass";
  expect_error_mentions(s.error(), {"short.pcd"});
}

// Inputs the fuzzers found (fuzz/regressions/TARGET/): PCL's readers threw, asserted (abort) or
// read past their buffers on them, which aborted `scenewatch segment` and `diff` and made
// IngestFile answer INTERNAL; an infinite focal length was accepted. Each is now an error that
// names the file and the problem.
TEST_F(IoTest, FilesTheFuzzersFoundAreErrors) {
  const fs::path regressions = fs::path(SCENEWATCH_SOURCE_DIR) / "fuzz" / "regressions";
  const std::map<std::string, std::string> problem = {
      {"no_data_type.pcd", "DATA must name"},           // DATA without its type: std::out_of_range
      {"size_dot_binary.pcd", "line 10: DATA must name"},  // SIZE '.', DATA of two words: PCL read past its buffers
      {"vertex_list.ply", "'idx' is a list"},             // PCL asserted on a vertex list
      {"blue_only.ply", "red, green, blue"},              // PCL asserted on colour without red
      {"header_in_data.pcd", "begins like a header line"},  // PCL sized the cloud from data: 42 GB
  };
  int files = 0;
  for (const char* target : {"fuzz_pcd", "fuzz_ply"}) {
    for (const auto& entry : fs::directory_iterator(regressions / target)) {
      const fs::path& path = entry.path();
      const std::string name = path.filename().string();
      ASSERT_EQ(problem.count(name), 1u) << "say what " << name << " shows";
      ++files;
      auto cloud = read_cloud(path);
      ASSERT_FALSE(cloud.ok()) << name;
      expect_error_mentions(cloud.error(), {name, problem.at(name)});
      EXPECT_FALSE(load_cloud_frame(path).ok()) << name;
      if (path.extension() == ".pcd") {
        EXPECT_FALSE(read_pcd_labels(path).ok()) << name;
      } else {
        auto mesh = read_mesh_ply(path);
        ASSERT_FALSE(mesh.ok()) << name;
        expect_error_mentions(mesh.error(), {name});
      }
    }
  }
  EXPECT_EQ(files, static_cast<int>(problem.size()));
  // The strict header reading names each malformed line on its own.
  const std::string head = "VERSION 0.7\nFIELDS x y z\nSIZE 4 . 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\n";
  auto dot = read_cloud(write_text("size_dot.pcd", head + "DATA binary\n" + std::string(12, '\0')));
  ASSERT_FALSE(dot.ok());
  expect_error_mentions(dot.error(), {"size_dot.pcd", "field 'y' has SIZE '.'"});
  auto fields_after_data = read_cloud(write_text(
      "two_fields.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n"
                        "FIELDS a b c\n1 2 3\n"));
  ASSERT_FALSE(fields_after_data.ok()) << "a second FIELDS line is data, not header";
  // PCL reads on after DATA while lines begin with a keyword: data that does is refused before
  // PCL allocates WIDTH x HEIGHT points from it.
  auto huge = read_cloud(write_text(
      "width_in_data.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n"
                           "\n# comment\nWIDTH 4000000000\nHEIGHT 4000000000\n1 2 3\n"));
  ASSERT_FALSE(huge.ok());
  expect_error_mentions(huge.error(), {"width_in_data.pcd", "'WIDTH'"});
  auto k = read_intrinsics(regressions / "fuzz_poses" / "infinite_focal.txt");
  ASSERT_FALSE(k.ok());
  expect_error_mentions(k.error(), {"infinite_focal.txt", "5.85000000e502", "non-finite"});
  auto pose = read_pose_matrix(write_text("nan_pose.txt", "1 0 0 0\n0 1 0 0\n0 0 1 nan\n0 0 0 1\n"));
  ASSERT_FALSE(pose.ok());
  expect_error_mentions(pose.error(), {"nan_pose.txt", "'nan' is non-finite"});
}

TEST_F(IoTest, GarbageAndEmptyFiles) {
  auto g = write_text("garbage.pcd", std::string("\x89\x01\x02 this is not a point cloud \xff\xfe", 35));
  auto r = read_cloud(g);
  ASSERT_FALSE(r.ok());
  expect_error_mentions(r.error(), {"garbage.pcd"});
  auto e = write_text("empty.pcd", "");
  r = read_cloud(e);
  ASSERT_FALSE(r.ok());
  expect_error_mentions(r.error(), {"empty.pcd", "empty"});
  auto ply = write_text("bad.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n");
  r = read_cloud(ply);
  ASSERT_FALSE(r.ok());
  expect_error_mentions(r.error(), {"bad.ply"});
  // Counts a file cannot hold are refused before anything is allocated from them (PCL's reader
  // ended in std::bad_alloc on these).
  const std::string props = "property float x\nproperty float y\nproperty float z\nend_header\n";
  for (const char* count : {"-5", "1000000000000", "99999999999999999999", "3x"}) {
    auto huge = write_text("count.ply", std::string("ply\nformat binary_little_endian 1.0\nelement vertex ") + count + "\n" + props +
                                            std::string(36, '\0'));
    r = read_cloud(huge);
    ASSERT_FALSE(r.ok()) << count;
    expect_error_mentions(r.error(), {"count.ply", "vertex"});
  }
  auto binary_short = write_text("short.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 100\n" + props +
                                                  std::string(36, '\0'));
  r = read_cloud(binary_short);
  ASSERT_FALSE(r.ok());
  expect_error_mentions(r.error(), {"short.ply", "more data than the file holds"});
  r = read_cloud(write_text("cloud.xyz", "1 2 3\n"));
  ASSERT_FALSE(r.ok());
  expect_error_mentions(r.error(), {"cloud.xyz", "extension"});
}

TEST_F(IoTest, AllNanAndInfinite) {
  Cloud c = small_cloud();
  for (auto& p : c.points) p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
  c.is_dense = false;
  ASSERT_EQ(pcl::PCDWriter().writeBinary((dir_ / "nan.pcd").string(), c), 0);
  auto r = read_cloud(dir_ / "nan.pcd");
  ASSERT_FALSE(r.ok());
  expect_error_mentions(r.error(), {"nan.pcd", "no valid points"});

  Cloud inf = small_cloud();
  inf.points[0].x = std::numeric_limits<float>::infinity();
  inf.points[1].z = -std::numeric_limits<float>::infinity();
  ASSERT_EQ(pcl::PCDWriter().writeBinary((dir_ / "inf.pcd").string(), inf), 0);
  auto s = read_cloud(dir_ / "inf.pcd");
  ASSERT_TRUE(s.ok()) << s.error().message;
  EXPECT_EQ(s->valid_points, inf.size() - 2);
  EXPECT_TRUE(std::isnan(s->cloud->points[0].y)) << "non-finite points become NaN throughout";
}

TEST_F(IoTest, WritePcdRoundTripAndRefusesEmpty) {
  ASSERT_TRUE(write_pcd(dir_ / "sub/out.pcd", small_cloud()).ok());
  auto r = read_cloud(dir_ / "sub/out.pcd");
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->cloud->size(), 50u);
  EXPECT_FALSE(write_pcd(dir_ / "e.pcd", Cloud()).ok());
}

TEST_F(IoTest, PngRoundTripAndDepthMustBe16Bit) {
  ColorImage c{4, 3, {}};
  for (int i = 0; i < 36; ++i) c.rgb.push_back(static_cast<std::uint8_t>(7 * i));
  ASSERT_TRUE(write_color_png(dir_ / "c.png", c).ok());
  auto rc = read_color_png(dir_ / "c.png");
  ASSERT_TRUE(rc.ok()) << rc.error().message;
  EXPECT_EQ(rc->rgb, c.rgb);
  DepthImage d{4, 3, {0, 1, 500, 1000, 2000, 65535, 3, 4, 5, 6, 7, 8}};
  ASSERT_TRUE(write_depth_png(dir_ / "d.png", d).ok());
  auto rd = read_depth_png(dir_ / "d.png");
  ASSERT_TRUE(rd.ok());
  EXPECT_EQ(rd->depth_mm, d.depth_mm);
  // The colour image as depth: 3 channels, 8 bit.
  auto wrong = read_depth_png(dir_ / "c.png");
  ASSERT_FALSE(wrong.ok());
  expect_error_mentions(wrong.error(), {"c.png", "one channel"});
  EXPECT_FALSE(write_depth_png(dir_ / "x.png", DepthImage{4, 3, {1, 2}}).ok()) << "buffer smaller than 4x3";
  auto bad = read_color_png(write_text("bad.png", "\x89PNG\r\n\x1a\n truncated"));
  ASSERT_FALSE(bad.ok());
  expect_error_mentions(bad.error(), {"bad.png", "decode"});
}

TEST_F(IoTest, RgbdBackProjection) {
  ColorImage c{4, 2, std::vector<std::uint8_t>(24, 100)};
  DepthImage d{4, 2, {0, 1000, 2000, 65535, 1500, 1500, 1500, 1500}};
  Intrinsics K{100, 100, 1.5, 0.5, 4, 2};
  auto cloud = rgbd_to_cloud(c, d, K);
  ASSERT_TRUE(cloud.ok()) << cloud.error().message;
  EXPECT_EQ((*cloud)->width, 4u);
  EXPECT_EQ((*cloud)->height, 2u);
  EXPECT_FALSE(is_valid((*cloud)->at(0, 0))) << "0 is no depth";
  EXPECT_FALSE(is_valid((*cloud)->at(3, 0))) << "65535 is no depth (7-Scenes)";
  const PointT& p = (*cloud)->at(2, 0);  // u = 2, v = 0, z = 2 m
  EXPECT_NEAR(p.z, 2.0, 1e-6);
  EXPECT_NEAR(p.x, (2 - 1.5) * 2.0 / 100, 1e-6);
  EXPECT_NEAR(p.y, (0 - 0.5) * 2.0 / 100, 1e-6);

  ColorImage small{2, 2, std::vector<std::uint8_t>(12, 0)};
  auto mismatch = rgbd_to_cloud(small, d, K);
  ASSERT_FALSE(mismatch.ok());
  expect_error_mentions(mismatch.error(), {"2x2", "4x2", "differ"});
  DepthImage zeros{4, 2, std::vector<std::uint16_t>(8, 0)};
  EXPECT_FALSE(rgbd_to_cloud(c, zeros, K).ok());
  Intrinsics other{100, 100, 1.5, 0.5, 640, 480};
  EXPECT_FALSE(rgbd_to_cloud(c, d, other).ok());
}

TEST_F(IoTest, IntrinsicsPosesAndTum) {
  SCENEWATCH_REQUIRE_DATA("redkitchen/camera-intrinsics.txt");
  auto K = read_intrinsics(test::data_dir() / "redkitchen/camera-intrinsics.txt");
  ASSERT_TRUE(K.ok()) << K.error().message;
  EXPECT_DOUBLE_EQ(K->fx, 585);
  EXPECT_DOUBLE_EQ(K->cy, 240);
  auto T = read_pose_matrix(test::data_dir() / "redkitchen/frame-000150.pose.txt");
  ASSERT_TRUE(T.ok()) << T.error().message;
  EXPECT_NEAR(T->translation().x(), -0.91287065, 1e-6);

  auto skew = read_pose_matrix(write_text("skew.txt", "1 0.5 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"));
  ASSERT_FALSE(skew.ok());
  expect_error_mentions(skew.error(), {"skew.txt", "rigid"});
  auto nan = read_pose_matrix(write_text("nan.txt", "1 0 0 nan\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"));
  ASSERT_FALSE(nan.ok());
  expect_error_mentions(nan.error(), {"nan.txt", "non-finite"});
  auto mirror = read_pose_matrix(write_text("mirror.txt", "-1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"));
  ASSERT_FALSE(mirror.ok());
  expect_error_mentions(mirror.error(), {"reflection"});
  EXPECT_FALSE(read_intrinsics(write_text("k.txt", "1 2 3\n")).ok());

  std::vector<StampedPose> poses(3);
  for (int i = 0; i < 3; ++i) {
    poses[i].stamp_s = 0.5 * i;
    poses[i].T_world_camera = Eigen::Translation3d(i, 2, 3) * Eigen::AngleAxisd(0.3 * i, Eigen::Vector3d::UnitZ());
  }
  ASSERT_TRUE(write_tum(dir_ / "traj.txt", poses).ok());
  auto back = read_tum(dir_ / "traj.txt");
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR((*back)[i].stamp_s, poses[i].stamp_s, 1e-6);
    EXPECT_TRUE((*back)[i].T_world_camera.isApprox(poses[i].T_world_camera, 1e-9));
  }
  auto bad = read_tum(write_text("bad_traj.txt", "# header\n0 0 0 0 0 0 0 1\n1 0 0 0 0 0\n"));
  ASSERT_FALSE(bad.ok());
  expect_error_mentions(bad.error(), {"bad_traj.txt", "line 3"});
  auto notunit = read_tum(write_text("q.txt", "0 0 0 0 0 0 0 2\n"));
  ASSERT_FALSE(notunit.ok());
  expect_error_mentions(notunit.error(), {"unit"});
}

TEST_F(IoTest, RedkitchenSequence) {
  SCENEWATCH_REQUIRE_DATA("redkitchen/frame-000150.color.png");
  const auto dir = test::data_dir() / "redkitchen";
  EXPECT_TRUE(is_sequence_dir(dir));
  auto seq = open_sequence(dir);
  ASSERT_TRUE(seq.ok()) << seq.error().message;
  EXPECT_EQ(seq->frames.size(), 50u);
  EXPECT_EQ(seq->frames.front().name, "frame-000150");
  EXPECT_EQ(seq->intrinsics.width, 640) << "image size from the first frame's PNG header";
  EXPECT_EQ(seq->intrinsics.height, 480);
  ASSERT_TRUE(seq->frames.front().T_world_camera.has_value());
  auto frame = load_sequence_frame(*seq, 0);
  ASSERT_TRUE(frame.ok()) << frame.error().message;
  EXPECT_EQ(frame->cloud->width, 640u);
  EXPECT_EQ(frame->cloud->height, 480u);
  EXPECT_GT(count_valid(*frame->cloud), 100000u);
  ASSERT_TRUE(frame->intrinsics.has_value());
  EXPECT_EQ(frame->intrinsics->width, 640);
  EXPECT_FALSE(load_sequence_frame(*seq, 50).ok());
}

TEST_F(IoTest, JpegColourSequence) {
  SCENEWATCH_REQUIRE_DATA("hrt1/pick_toy_1/frame-000000.color.jpg");
  const auto dir = test::data_dir() / "hrt1/pick_toy_1";
  EXPECT_TRUE(is_sequence_dir(dir)) << "frame-NNNNNN.color.jpg makes a sequence folder";
  auto seq = open_sequence(dir);
  ASSERT_TRUE(seq.ok()) << seq.error().message;
  EXPECT_EQ(seq->frames.size(), 40u);
  EXPECT_EQ(seq->frames.front().color.filename(), "frame-000000.color.jpg");
  auto frame = load_sequence_frame(*seq, 0);
  ASSERT_TRUE(frame.ok()) << frame.error().message;
  EXPECT_TRUE(frame->has_color);
  EXPECT_EQ(frame->cloud->width, 640u);
  // The white table fills the lower middle of the view: its colour is decoded, not left black.
  const auto& p = frame->cloud->at(320, 400);
  EXPECT_GT(int(p.r) + p.g + p.b, 300);
}

TEST_F(IoTest, SequenceWithTwoColourImagesForOneFrameIsRefused) {
  ColorImage c{4, 2, std::vector<std::uint8_t>(24, 90)};
  DepthImage d{4, 2, std::vector<std::uint16_t>(8, 1200)};
  ASSERT_TRUE(write_color_png(dir_ / "frame-000000.color.png", c).ok());
  ASSERT_TRUE(write_depth_png(dir_ / "frame-000000.depth.png", d).ok());
  fs::copy_file(dir_ / "frame-000000.color.png", dir_ / "frame-000000.color.jpg");
  ASSERT_TRUE(write_intrinsics(dir_ / "camera-intrinsics.txt", Intrinsics{100, 100, 2, 1, 4, 2}).ok());
  auto seq = open_sequence(dir_);
  ASSERT_FALSE(seq.ok());
  expect_error_mentions(seq.error(), {"frame-000000", "two colour images"});
}

TEST_F(IoTest, TumSequenceAndItsErrors) {
  ColorImage c{4, 2, std::vector<std::uint8_t>(24, 90)};
  DepthImage d{4, 2, std::vector<std::uint16_t>(8, 1200)};
  for (int i = 0; i < 2; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "frame-%06d", i);
    ASSERT_TRUE(write_color_png(dir_ / (std::string(name) + ".color.png"), c).ok());
    ASSERT_TRUE(write_depth_png(dir_ / (std::string(name) + ".depth.png"), d).ok());
  }
  auto missing_k = open_sequence(dir_);
  ASSERT_FALSE(missing_k.ok());
  expect_error_mentions(missing_k.error(), {"camera-intrinsics.txt"});
  ASSERT_TRUE(write_intrinsics(dir_ / "camera-intrinsics.txt", Intrinsics{100, 100, 2, 1, 0, 0}).ok());
  std::vector<StampedPose> poses(3);
  ASSERT_TRUE(write_tum(dir_ / "trajectory.txt", poses).ok());
  auto wrong_count = open_sequence(dir_);
  ASSERT_FALSE(wrong_count.ok());
  expect_error_mentions(wrong_count.error(), {"3 poses for 2 frames"});
  poses.resize(2);
  poses[1].stamp_s = 0.25;
  poses[1].T_world_camera.translation() = Eigen::Vector3d(0, 0, 1);
  ASSERT_TRUE(write_tum(dir_ / "trajectory.txt", poses).ok());
  auto seq = open_sequence(dir_);
  ASSERT_TRUE(seq.ok()) << seq.error().message;
  EXPECT_DOUBLE_EQ(seq->frames[1].stamp_s, 0.25);
  auto f = load_sequence_frame(*seq, 1);
  ASSERT_TRUE(f.ok()) << f.error().message;
  EXPECT_NEAR(f->T_world_camera->translation().z(), 1.0, 1e-9);

  fs::remove(dir_ / "frame-000001.depth.png");
  auto no_depth = open_sequence(dir_);
  ASSERT_FALSE(no_depth.ok());
  expect_error_mentions(no_depth.error(), {"frame-000001.depth.png"});
  EXPECT_FALSE(open_sequence(dir_ / "absent").ok());
}

// A TUM RGB-D benchmark folder as published: rgb/ and depth/ PNGs listed in rgb.txt and
// depth.txt, poses in groundtruth.txt at a higher rate, no camera-intrinsics.txt.
class TumLayoutTest : public IoTest {
 protected:
  void SetUp() override {
    fs::create_directories(dir_ / "rgb");
    fs::create_directories(dir_ / "depth");
    const ColorImage c{4, 2, std::vector<std::uint8_t>(24, 90)};
    const DepthImage d{4, 2, std::vector<std::uint16_t>(8, 5000)};  // 1 m in units of 1/5000 m
    std::vector<StampedFile> rgb, depth;
    // Colour at 30 Hz; depth near the first three only (10.100 and 10.133 have none within 0.02 s).
    for (double t : {10.0, 10.033, 10.066, 10.1, 10.133}) rgb.push_back({t, name("rgb", t), 0});
    for (double t : {10.004, 10.037, 10.07, 10.16}) depth.push_back({t, name("depth", t), 0});
    for (const auto& f : rgb) ASSERT_TRUE(write_color_png(dir_ / f.file, c).ok());
    for (const auto& f : depth) ASSERT_TRUE(write_depth_png(dir_ / f.file, d).ok());
    ASSERT_TRUE(write_tum_list(dir_ / "rgb.txt", rgb).ok());
    ASSERT_TRUE(write_tum_list(dir_ / "depth.txt", depth).ok());
    // Ground truth at 100 Hz up to 10.045 s: the depth at 10.070 has no pose within 0.02 s.
    std::vector<StampedPose> poses;
    for (int i = 0; i <= 5; ++i) {
      StampedPose p;
      p.stamp_s = 9.995 + 0.01 * i;
      p.T_world_camera = Eigen::Translation3d(0.1 * i, 0, 0) * Eigen::AngleAxisd(0.05 * i, Eigen::Vector3d::UnitY());
      poses.push_back(p);
    }
    ASSERT_TRUE(write_tum(dir_ / "groundtruth.txt", poses).ok());
  }
  static fs::path name(const std::string& folder, double t) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.6f.png", t);
    return fs::path(folder) / buffer;
  }
};

TEST_F(TumLayoutTest, AssociatesColourDepthAndPoseByTime) {
  EXPECT_TRUE(is_sequence_dir(dir_.path()));
  auto seq = open_sequence(dir_);
  ASSERT_TRUE(seq.ok()) << seq.error().message;
  EXPECT_EQ(seq->layout, SequenceLayout::kTum);
  ASSERT_EQ(seq->frames.size(), 2u);
  EXPECT_EQ(seq->skipped_without_depth, 2u);
  EXPECT_EQ(seq->skipped_without_pose, 1u);
  EXPECT_EQ(skipped_summary(*seq),
            "2 colour images without a depth image within 0.02 s skipped; "
            "1 colour image without a ground-truth pose within 0.02 s skipped");
  EXPECT_EQ(seq->frames[0].name, "10.000000");
  EXPECT_EQ(seq->frames[1].color.filename(), "10.033000.png");
  EXPECT_EQ(seq->frames[1].depth.filename(), "10.037000.png");
  EXPECT_DOUBLE_EQ(seq->frames[1].stamp_s, 10.037) << "the depth image's time";
  // Nearest ground truth: 10.005 for the depth at 10.004, 10.035 for 10.037.
  ASSERT_TRUE(seq->frames[1].T_world_camera.has_value());
  EXPECT_NEAR(seq->frames[0].T_world_camera->translation().x(), 0.1, 1e-9);
  EXPECT_NEAR(seq->frames[1].T_world_camera->translation().x(), 0.4, 1e-9);
  // TUM's default intrinsics, the image size from the files, depth in 1/5000 m.
  EXPECT_EQ(seq->intrinsics.fx, 525.0);
  EXPECT_EQ(seq->intrinsics.cy, 239.5);
  EXPECT_EQ(seq->intrinsics.width, 4);
  EXPECT_DOUBLE_EQ(seq->depth_scale_m, 1.0 / 5000);
  auto frame = load_sequence_frame(*seq, 1);
  ASSERT_TRUE(frame.ok()) << frame.error().message;
  EXPECT_FLOAT_EQ(frame->cloud->at(1, 1).z, 1.0f);
  EXPECT_EQ(frame->cloud->at(1, 1).r, 90);

  // A looser tolerance takes the frame at 10.100 (depth 10.070 is taken; 10.133 pairs with 10.160).
  SequenceOptions loose;
  loose.max_time_difference_s = 0.05;
  auto more = open_sequence(dir_, loose);
  ASSERT_TRUE(more.ok()) << more.error().message;
  EXPECT_EQ(more->frames.size() + more->skipped_without_depth + more->skipped_without_pose, 5u);
  EXPECT_EQ(more->skipped_without_depth, 1u) << "10.066 and 10.100 both want 10.070; the nearer wins";
}

TEST_F(TumLayoutTest, IntrinsicsAndDepthScaleFilesAndOptions) {
  ASSERT_TRUE(write_intrinsics(dir_ / "camera-intrinsics.txt", Intrinsics{517.3, 516.5, 318.6, 255.3, 0, 0}).ok());
  write_text("depth-scale.txt", "# metres per unit\n0.0001\n");
  auto seq = open_sequence(dir_);
  ASSERT_TRUE(seq.ok()) << seq.error().message;
  EXPECT_EQ(seq->intrinsics.fx, 517.3);
  EXPECT_DOUBLE_EQ(seq->depth_scale_m, 1e-4);
  auto frame = load_sequence_frame(*seq, 0);
  ASSERT_TRUE(frame.ok()) << frame.error().message;
  EXPECT_FLOAT_EQ(frame->cloud->at(0, 0).z, 0.5f) << "5000 units of 0.1 mm";
  SequenceOptions options;
  options.depth_scale_m = 0.001;  // the command line's --depth-scale wins over the file
  auto mm = open_sequence(dir_, options);
  ASSERT_TRUE(mm.ok()) << mm.error().message;
  auto frame_mm = load_sequence_frame(*mm, 0);
  ASSERT_TRUE(frame_mm.ok()) << frame_mm.error().message;
  EXPECT_FLOAT_EQ(frame_mm->cloud->at(0, 0).z, 5.0f);

  options.depth_scale_m = -1;
  auto negative = open_sequence(dir_, options);
  ASSERT_FALSE(negative.ok());
  expect_error_mentions(negative.error(), {"--depth-scale", "(0, 1]", "-1"});
  write_text("depth-scale.txt", "0\n");
  auto zero = open_sequence(dir_);
  ASSERT_FALSE(zero.ok());
  expect_error_mentions(zero.error(), {"depth-scale.txt", "(0, 1]"});
  write_text("depth-scale.txt", "\n1e-4 mm\n");
  auto word = open_sequence(dir_);
  ASSERT_FALSE(word.ok());
  expect_error_mentions(word.error(), {"depth-scale.txt", "line 2", "'mm'"});
  write_text("depth-scale.txt", "0.001 0.001\n");
  auto two = open_sequence(dir_);
  ASSERT_FALSE(two.ok());
  expect_error_mentions(two.error(), {"depth-scale.txt", "one number", "found 2"});
}

TEST_F(TumLayoutTest, MalformedListsNameTheFileAndLine) {
  write_text("rgb.txt", "# colour images\n10.0 rgb/10.000000.png\n10.o33 rgb/10.033000.png\n");
  auto bad_stamp = open_sequence(dir_);
  ASSERT_FALSE(bad_stamp.ok());
  expect_error_mentions(bad_stamp.error(), {"rgb.txt", "line 3", "'10.o33'", "not a number"});

  write_text("rgb.txt", "10.0 rgb/10.000000.png\n10.033\n");
  auto no_file = open_sequence(dir_);
  ASSERT_FALSE(no_file.ok());
  expect_error_mentions(no_file.error(), {"rgb.txt", "line 2", "no file name"});

  write_text("rgb.txt", "10.0 rgb/10.000000.png\n");
  write_text("depth.txt", "10.004 depth/10.004000.png\n10.037 depth/gone.png\n");
  auto missing = open_sequence(dir_);
  ASSERT_FALSE(missing.ok());
  expect_error_mentions(missing.error(), {"depth.txt", "line 2", "depth/gone.png", "does not exist"});

  fs::remove(dir_ / "depth.txt");
  EXPECT_TRUE(is_sequence_dir(dir_.path())) << "rgb.txt marks the layout; what is missing is then named";
  auto no_list = open_sequence(dir_);
  ASSERT_FALSE(no_list.ok());
  expect_error_mentions(no_list.error(), {"depth.txt", "missing"});

  write_text("depth.txt", "10.004 depth/10.004000.png\n");
  write_text("groundtruth.txt", "# timestamp tx ty tz qx qy qz qw\n10.0 0 0 0 0 0 0 1\n10.01 0 0 0 0 0 1\n");
  auto bad_pose = open_sequence(dir_);
  ASSERT_FALSE(bad_pose.ok());
  expect_error_mentions(bad_pose.error(), {"groundtruth.txt", "line 3"});

  write_text("groundtruth.txt", "20.0 0 0 0 0 0 0 1\n");
  auto no_pose = open_sequence(dir_);
  ASSERT_FALSE(no_pose.ok());
  expect_error_mentions(no_pose.error(), {"no frame has colour, depth and pose", "without a ground-truth pose"});
}

TEST_F(IoTest, DepthScaleFileBesideTheFramesLayout) {
  ColorImage c{4, 2, std::vector<std::uint8_t>(24, 90)};
  DepthImage d{4, 2, std::vector<std::uint16_t>(8, 12000)};
  ASSERT_TRUE(write_color_png(dir_ / "frame-000000.color.png", c).ok());
  ASSERT_TRUE(write_depth_png(dir_ / "frame-000000.depth.png", d).ok());
  ASSERT_TRUE(write_intrinsics(dir_ / "camera-intrinsics.txt", Intrinsics{100, 100, 2, 1, 0, 0}).ok());
  auto mm = open_sequence(dir_);
  ASSERT_TRUE(mm.ok()) << mm.error().message;
  EXPECT_DOUBLE_EQ(mm->depth_scale_m, 0.001) << "millimetres unless told otherwise";
  write_text("depth-scale.txt", "0.0001\n");
  auto seq = open_sequence(dir_);
  ASSERT_TRUE(seq.ok()) << seq.error().message;
  auto frame = load_sequence_frame(*seq, 0);
  ASSERT_TRUE(frame.ok()) << frame.error().message;
  EXPECT_FLOAT_EQ(frame->cloud->at(2, 1).z, 1.2f);
}

// The tomato soup can of YCB-Video frame 3 (depth in units of 0.1 mm) measured on the loaded
// cloud: its side wall, between 2 and 8 cm above the writing tablet it stands on, projected on
// the tablet's plane, fits a circle of the can's diameter (65.8 mm by its model).
double soup_can_diameter_m(const Cloud& cloud) {
  // The tablet: pixels below the can (rows 458-477, columns 110-329), plane by PCA.
  std::vector<Eigen::Vector3d> tablet;
  for (int v = 458; v < 478; v += 2)
    for (int u = 110; u < 330; u += 3)
      if (is_valid(cloud.at(u, v))) tablet.push_back(cloud.at(u, v).getVector3fMap().cast<double>());
  if (tablet.size() < 100) return -1;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : tablet) centroid += p;
  centroid /= static_cast<double>(tablet.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : tablet) cov += (p - centroid) * (p - centroid).transpose();
  Eigen::Vector3d up = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
  if (up.dot(-centroid) < 0) up = -up;  // towards the camera's side: the can stands there
  const Eigen::Vector3d e1 = (Eigen::Vector3d::UnitX() - up.x() * up).normalized(), e2 = up.cross(e1);
  // The can's front at pixel (228, 390); its wall points within 6 cm of it across the tablet.
  if (!is_valid(cloud.at(228, 390))) return -1;
  const Eigen::Vector3d seed = cloud.at(228, 390).getVector3fMap().cast<double>();
  const Eigen::Vector2d seed_2d(seed.dot(e1), seed.dot(e2));
  // Kasa circle fit: x^2 + y^2 = 2 a x + 2 b y + c, least squares.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  std::size_t n = 0;
  for (int v = 300; v < 450; ++v) {
    for (int u = 150; u < 310; ++u) {
      if (!is_valid(cloud.at(u, v))) continue;
      const Eigen::Vector3d p = cloud.at(u, v).getVector3fMap().cast<double>();
      const double height = (p - centroid).dot(up);
      const Eigen::Vector2d q(p.dot(e1), p.dot(e2));
      if (height < 0.02 || height > 0.08 || (q - seed_2d).norm() > 0.06) continue;
      const Eigen::Vector3d row(2 * q.x(), 2 * q.y(), 1);
      A += row * row.transpose();
      b += row * q.squaredNorm();
      ++n;
    }
  }
  if (n < 1000) return -1;
  const Eigen::Vector3d abc = A.ldlt().solve(b);
  return 2 * std::sqrt(abc.z() + abc.x() * abc.x() + abc.y() * abc.y());
}

TEST_F(IoTest, YcbFramesLoadAtTheirMetricScale) {
  SCENEWATCH_REQUIRE_DATA("ycb/frame-000003.depth.png");
  const fs::path ycb = test::data_dir() / "ycb";
  // As recorded, with the unit on the command line (--depth-scale 0.0001) ...
  SequenceOptions options;
  options.depth_scale_m = 1e-4;
  auto seq = open_sequence(ycb, options);
  ASSERT_TRUE(seq.ok()) << seq.error().message;
  ASSERT_EQ(seq->frames.size(), 3u);
  ASSERT_EQ(seq->frames[1].name, "frame-000003");
  auto frame = load_sequence_frame(*seq, 1);
  ASSERT_TRUE(frame.ok()) << frame.error().message;
  const double diameter = soup_can_diameter_m(*frame->cloud);
  std::cout << "tomato soup can, YCB frame 3: " << diameter * 1000 << " mm across (model: 65.8 mm)\n";
  EXPECT_NEAR(diameter, 0.0658, 0.003);
  EXPECT_NEAR(frame->cloud->at(228, 390).z, 0.74, 0.01) << "the can stands 74 cm from the camera";

  // ... and with a depth-scale.txt beside camera-intrinsics.txt (a copy of the folder's files).
  for (const char* f : {"camera-intrinsics.txt", "frame-000003.color.png", "frame-000003.depth.png"})
    fs::create_symlink(ycb / f, dir_ / f);
  write_text("depth-scale.txt", "0.0001\n");
  auto with_file = open_sequence(dir_);
  ASSERT_TRUE(with_file.ok()) << with_file.error().message;
  auto same = load_sequence_frame(*with_file, 0);
  ASSERT_TRUE(same.ok()) << same.error().message;
  EXPECT_EQ(same->cloud->at(228, 390).z, frame->cloud->at(228, 390).z);

  // Read as millimetres the can would stand 7.4 m away.
  auto as_mm = load_sequence_frame(*open_sequence(ycb), 1);
  ASSERT_TRUE(as_mm.ok()) << as_mm.error().message;
  EXPECT_NEAR(as_mm->cloud->at(228, 390).z, 7.4, 0.1);
}

TEST_F(IoTest, CloudFrameUsesThePcdViewpoint) {
  Cloud c = small_cloud();
  c.sensor_origin_ = Eigen::Vector4f(1, 2, 3, 0);
  ASSERT_EQ(pcl::PCDWriter().writeBinary((dir_ / "vp.pcd").string(), c), 0);
  auto f = load_cloud_frame(dir_ / "vp.pcd");
  ASSERT_TRUE(f.ok()) << f.error().message;
  ASSERT_TRUE(f->T_world_camera.has_value());
  // World points (the file's) are recovered by the pose.
  const Eigen::Vector3d w = *f->T_world_camera * f->cloud->points[5].getVector3fMap().cast<double>();
  EXPECT_NEAR(w.x(), c[5].x, 1e-5);
  EXPECT_NEAR(w.z(), c[5].z, 1e-5);
  ASSERT_TRUE(write_pcd(dir_ / "plain.pcd", small_cloud()).ok());
  auto g = load_cloud_frame(dir_ / "plain.pcd");
  ASSERT_TRUE(g.ok());
  EXPECT_FALSE(g->T_world_camera.has_value());
}

}  // namespace
}  // namespace scenewatch::io

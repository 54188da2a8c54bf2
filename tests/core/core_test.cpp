#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/event.h"
#include "scenewatch/core/files.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/result.h"
#include "test_data.h"

namespace scenewatch {
namespace {

TEST(Geometry, ValidateRigid) {
  EXPECT_TRUE(validate_rigid(Eigen::Matrix4d::Identity()).ok());
  Eigen::Matrix4d rot = Eigen::Matrix4d::Identity();
  rot.topLeftCorner<3, 3>() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  rot.topRightCorner<3, 1>() = Eigen::Vector3d(1, -2, 3);
  EXPECT_TRUE(validate_rigid(rot).ok());

  Eigen::Matrix4d scaled = rot;
  scaled.topLeftCorner<3, 3>() *= 1.1;
  auto st = validate_rigid(scaled);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("not rigid"), std::string::npos);

  Eigen::Matrix4d mirror = Eigen::Matrix4d::Identity();
  mirror(0, 0) = -1;
  EXPECT_NE(validate_rigid(mirror).error().message.find("reflection"), std::string::npos);

  Eigen::Matrix4d nan = Eigen::Matrix4d::Identity();
  nan(1, 3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(validate_rigid(nan).error().message.find("non-finite"), std::string::npos);

  Eigen::Matrix4d row = Eigen::Matrix4d::Identity();
  row(3, 0) = 0.5;
  EXPECT_NE(validate_rigid(row).error().message.find("last row"), std::string::npos);
}

TEST(Geometry, PoseFromMatrixReorthonormalises) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  m(0, 1) += 1e-5;  // tiny drift, as in files written with few digits
  const Pose p = pose_from_matrix(m);
  EXPECT_NEAR((p.linear().transpose() * p.linear() - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
}

TEST(Geometry, OrientedBoxAabb) {
  OrientedBox b;
  b.center = Eigen::Vector3d(1, 2, 3);
  b.extents = Eigen::Vector3d(2, 1, 1);
  b.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  const Aabb a = b.aabb();
  EXPECT_NEAR(a.min.x(), 0.5, 1e-12);
  EXPECT_NEAR(a.max.y(), 3.0, 1e-12);
  EXPECT_TRUE(a.valid());
  EXPECT_FALSE((Aabb{{1, 0, 0}, {0, 1, 1}}).valid());
}

TEST(Cloud, CountValid) {
  Cloud c(3, 1);
  c.points[0].x = c.points[0].y = c.points[0].z = 1;
  c.points[1].x = std::numeric_limits<float>::infinity();
  c.points[2].z = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(count_valid(c), 1u);
}

TEST(Result, ValueAndError) {
  Result<int> ok = 3;
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(*ok, 3);
  Result<int> bad = invalid_argument("x");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, ErrorCode::kInvalidArgument);
  EXPECT_STREQ(to_string(ErrorCode::kNotFound), "not_found");
  EXPECT_STREQ(to_string(EventKind::kObjectGone), "OBJECT_GONE");
  EXPECT_STREQ(to_string(EventLevel::kImplausibility), "IMPLAUSIBILITY");
}

// Every writer of the project goes through write_atomically: a failed write leaves the old file
// as it was and no temporary file behind; a good one replaces it whole.
TEST(Files, WriteAtomicallyReplacesWholeOrNotAtAll) {
  const test::TempDir dir("atomic");
  const std::filesystem::path path = dir / "sub" / "a.txt";
  auto write_text = [](const std::string& text) {
    return [text](const std::filesystem::path& tmp) -> Status {
      std::ofstream(tmp) << text;
      return {};
    };
  };
  auto read_text = [](const std::filesystem::path& p) {
    std::ifstream in(p);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  ASSERT_TRUE(write_atomically(path, write_text("first")).ok()) << "the folder is created";
  EXPECT_EQ(read_text(path), "first");
  const Status failed = write_atomically(path, [](const std::filesystem::path& tmp) -> Status {
    std::ofstream(tmp) << "half of";
    return io_error("disk full");
  });
  ASSERT_FALSE(failed.ok());
  EXPECT_EQ(failed.error().message, "disk full");
  EXPECT_EQ(read_text(path), "first") << "the old file stays";
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".tmp")) << "no temporary file is left";
  ASSERT_TRUE(write_atomically(path, write_text("second"), ".tmp.txt").ok());
  EXPECT_EQ(read_text(path), "second");
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".tmp.txt"));
}

}  // namespace
}  // namespace scenewatch

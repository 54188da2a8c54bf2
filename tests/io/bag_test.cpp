// ROS bags as frame sources (scenewatch/io/bag.h), against bags written at test time from a
// stretch of ../shared/data/redkitchen_long by tests/io/make_bag.py: ROS 1 bags by Debian's
// python3-rosbag (uncompressed, lz4, bz2; depth 16UC1 and 32FC1), rosbag2 SQLite bags by the
// script itself (CDR serialized by hand: ours, not an independent tool's). The oracle is the same
// frames read from the folder. Then hostile bags: truncated at many offsets, bytes flipped at
// random, lying lengths; each gives an error or frames, never a crash.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <random>

#include "bag/field_reader.h"
#include "bag/ros_messages.h"
#include "scenewatch/io/bag.h"
#include "scenewatch/io/sequence.h"
#include "test_data.h"

namespace scenewatch::io {
namespace {
namespace fs = std::filesystem;

constexpr int kFrames = 4;

fs::path folder() { return test::data_dir() / "redkitchen_long"; }

// Writes a bag with tests/io/make_bag.py; fails the test with the script's command when it cannot.
fs::path make_bag(const fs::path& dir, const std::string& name, const std::string& args, int count = kFrames) {
  const fs::path out = dir / name;
  const std::string command = "/usr/bin/python3 " + (test::source_dir() / "tests/io/make_bag.py").string() + " " +
                              folder().string() + " " + out.string() + " --count " + std::to_string(count) + " " + args +
                              " > " + (dir / (name + ".log")).string() + " 2>&1";
  if (std::system(command.c_str()) != 0) {
    std::ifstream log(dir / (name + ".log"));
    std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
    ADD_FAILURE() << "could not write the test bag (scripts/install-deps installs python3-rosbag and the message "
                     "packages): " << command << "\n" << text;
  }
  return out;
}

std::vector<char> read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void write_file(const fs::path& p, const std::vector<char>& bytes, std::size_t n) {
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(n));
}

// Opens and loads every frame; returns the first error's message, or "" when all went well.
std::string read_all(const fs::path& path) {
  auto rec = open_bag(path);
  if (!rec) return rec.error().message;
  for (std::size_t i = 0; i < rec->frames.size(); ++i) {
    auto f = load_bag_frame(*rec, i);
    if (!f) return f.error().message;
  }
  return "";
}

class BagTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!fs::exists(folder())) return;
    dir_ = new test::TempDir("bags");
    const fs::path& d = dir_->path();
    bags_ = {
        make_bag(d, "plain.bag", "--format ros1 --oracle " + (d / "oracle").string()),
        make_bag(d, "lz4.bag", "--format ros1 --compression lz4"),
        make_bag(d, "bz2_32f.bag", "--format ros1 --compression bz2 --depth-encoding 32FC1"),
        make_bag(d, "rosbag2", "--format rosbag2"),
        make_bag(d, "rosbag2_32f", "--format rosbag2 --depth-encoding 32FC1"),
        make_bag(d, "plain.mcap", "--format mcap"),
        make_bag(d, "lz4.mcap", "--format mcap --compression lz4"),
        make_bag(d, "zstd_32f.mcap", "--format mcap --compression zstd --depth-encoding 32FC1"),
    };
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override { SCENEWATCH_REQUIRE_DATA("redkitchen_long"); }

  static test::TempDir* dir_;
  static std::vector<fs::path> bags_;
};
test::TempDir* BagTest::dir_ = nullptr;
std::vector<fs::path> BagTest::bags_;

TEST_F(BagTest, EveryFormatGivesTheFolderFramesExactly) {
  // The folder's frames with the poses made exactly rigid, as TF carries them (make_bag.py --oracle).
  auto seq = open_sequence(dir_->path() / "oracle");
  ASSERT_TRUE(seq) << seq.error().message;
  for (const auto& path : bags_) {
    SCOPED_TRACE(path.filename().string());
    ASSERT_TRUE(is_bag(path));
    auto rec = open_bag(path);
    ASSERT_TRUE(rec) << rec.error().message;
    EXPECT_EQ(rec->depth_topic, "/camera/depth/image_raw");
    EXPECT_EQ(rec->color_topic, "/camera/color/image_raw");
    EXPECT_EQ(rec->info_topic, "/camera/depth/camera_info");
    EXPECT_EQ(rec->world_frame, "world");
    EXPECT_EQ(rec->camera_frame, "camera_depth_optical_frame");
    ASSERT_EQ(rec->frames.size(), static_cast<std::size_t>(kFrames));
    EXPECT_EQ(skipped_summary(*rec), "");
    for (int i = 0; i < kFrames; ++i) {
      auto from_bag = load_bag_frame(*rec, static_cast<std::size_t>(i));
      ASSERT_TRUE(from_bag) << from_bag.error().message;
      auto from_folder = load_sequence_frame(*seq, static_cast<std::size_t>(i));
      ASSERT_TRUE(from_folder) << from_folder.error().message;
      // The pose went through a quaternion and a chain of two transforms: equal to rounding.
      ASSERT_TRUE(from_bag->T_world_camera.has_value());
      EXPECT_TRUE(from_bag->T_world_camera->isApprox(*from_folder->T_world_camera, 1e-9))
          << from_bag->T_world_camera->matrix() << "\nvs\n" << from_folder->T_world_camera->matrix();
      ASSERT_TRUE(from_bag->intrinsics);
      EXPECT_DOUBLE_EQ(from_bag->intrinsics->fx, from_folder->intrinsics->fx);
      EXPECT_DOUBLE_EQ(from_bag->intrinsics->cy, from_folder->intrinsics->cy);
      const Cloud& a = *from_bag->cloud;
      const Cloud& b = *from_folder->cloud;
      ASSERT_EQ(a.width, b.width);
      ASSERT_EQ(a.height, b.height);
      std::size_t differing = 0;
      for (std::size_t k = 0; k < a.size(); ++k) {
        const bool va = is_valid(a[k]), vb = is_valid(b[k]);
        if (va != vb || (va && (a[k].x != b[k].x || a[k].y != b[k].y || a[k].z != b[k].z || a[k].rgba != b[k].rgba))) ++differing;
      }
      EXPECT_EQ(differing, 0u) << "frame " << i;
    }
  }
}

TEST_F(BagTest, TopicsAndFramesByFlagsAndClearErrors) {
  const fs::path& bag = bags_[0];
  BagOptions o;
  o.depth_topic = "/camera/depth/nothing";
  auto r = open_bag(bag, o);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("--depth-topic /camera/depth/nothing: no such topic"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("/camera/color/image_raw"), std::string::npos) << r.error().message;  // the candidates

  o = {};
  o.depth_topic = "/camera/depth/camera_info";
  r = open_bag(bag, o);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("type is sensor_msgs/CameraInfo, not sensor_msgs/Image"), std::string::npos) << r.error().message;

  o = {};
  o.depth_topic = "/camera/color/image_raw";  // a colour topic named as depth: its encoding is refused when read
  o.color_topic = "/camera/color/image_raw";
  o.camera_frame = "camera_depth_optical_frame";  // the colour images' own frame is not on TF
  auto colour_as_depth = open_bag(bag, o);
  ASSERT_TRUE(colour_as_depth) << colour_as_depth.error().message;
  auto f = load_bag_frame(*colour_as_depth, 0);
  ASSERT_FALSE(f);
  EXPECT_NE(f.error().message.find("topic /camera/color/image_raw"), std::string::npos) << f.error().message;
  EXPECT_NE(f.error().message.find("unknown image encoding 'bgr8'"), std::string::npos) << f.error().message;

  o = {};
  o.world_frame = "map";
  r = open_bag(bag, o);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("missing TF"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("'map'"), std::string::npos) << r.error().message;

  o = {};
  o.camera_frame = "camera_color_optical_frame";
  r = open_bag(bag, o);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("'camera_color_optical_frame'"), std::string::npos) << r.error().message;

  // The camera link instead of the optical frame: a pose of another frame, from the same TF.
  o = {};
  o.camera_frame = "camera_link";
  r = open_bag(bag, o);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->camera_frame, "camera_link");
}

TEST_F(BagTest, TruncatedBagsGiveAnErrorThatNamesTheByte) {
  for (const fs::path& bag : {bags_[0], bags_[1]}) {
    SCOPED_TRACE(bag.filename().string());
    const auto bytes = read_file(bag);
    ASSERT_GT(bytes.size(), 1000u);
    const fs::path cut = dir_->path() / "cut.bag";
    std::vector<std::size_t> offsets;
    for (std::size_t n = 0; n < 64; ++n) offsets.push_back(n);
    for (std::size_t k = 1; k < 150; ++k) offsets.push_back(bytes.size() * k / 150);
    std::size_t errors = 0;
    for (std::size_t n : offsets) {
      write_file(cut, bytes, n);
      const std::string message = read_all(cut);
      if (message.empty()) continue;  // a cut in the index section after the last chunk leaves a readable bag
      ++errors;
      EXPECT_NE(message.find("byte"), std::string::npos) << "cut at " << n << ": " << message;
    }
    EXPECT_GT(errors, offsets.size() * 9 / 10);
  }
  // A cut inside the first chunk says so.
  const auto bytes = read_file(bags_[0]);
  write_file(dir_->path() / "cut.bag", bytes, 10000);
  const std::string message = read_all(dir_->path() / "cut.bag");
  EXPECT_NE(message.find("truncated"), std::string::npos) << message;
}

TEST_F(BagTest, FlippedBytesNeverCrash) {
  std::mt19937 rng(32);
  const fs::path small_dir = dir_->path() / "small";
  fs::create_directories(small_dir);
  const std::vector<fs::path> small = {make_bag(small_dir, "plain.bag", "--format ros1", 2),
                                       make_bag(small_dir, "lz4.bag", "--format ros1 --compression lz4", 2),
                                       make_bag(small_dir, "bz2.bag", "--format ros1 --compression bz2", 2),
                                       make_bag(small_dir, "r2", "--format rosbag2", 2),
                                       make_bag(small_dir, "zstd.mcap", "--format mcap --compression zstd", 2)};
  for (const fs::path& bag : small) {
    SCOPED_TRACE(bag.filename().string());
    const fs::path file = fs::is_directory(bag) ? bag / "r2_0.db3" : bag;
    const auto original = read_file(file);
    const fs::path target = fs::is_directory(bag) ? bag / "r2_0.db3" : small_dir / ("flipped" + bag.extension().string());
    std::size_t errors = 0;
    for (int round = 0; round < 120; ++round) {
      auto bytes = original;
      const int flips = 1 + static_cast<int>(rng() % 8);
      for (int k = 0; k < flips; ++k) {
        // Half the flips in the first 16 KB (headers, connections, the first message headers), half anywhere.
        const std::size_t span = (rng() % 2) ? std::min<std::size_t>(bytes.size(), 16384) : bytes.size();
        bytes[rng() % span] ^= static_cast<char>(1u << (rng() % 8));
      }
      write_file(target, bytes, bytes.size());
      errors += read_all(fs::is_directory(bag) ? bag : target).empty() ? 0 : 1;
    }
    write_file(target, original, original.size());
    EXPECT_GT(errors, 0u);  // some flips must hit a length, a CRC of a compressed stream or a field
  }
}

TEST_F(BagTest, McapChunksWithALyingCrcAreRefused) {
  const fs::path bag = make_bag(dir_->path(), "lying.mcap", "--format mcap --compression lz4 --lie-crc", 2);
  auto r = open_bag(bag);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("the chunk at byte"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("lying CRC"), std::string::npos) << r.error().message;
  // And truncated MCAP files name the byte.
  const auto bytes = read_file(bags_[6]);
  for (std::size_t k = 1; k < 40; ++k) {
    const std::size_t n = bytes.size() * k / 40;
    write_file(dir_->path() / "cut.mcap", bytes, n);
    const std::string message = read_all(dir_->path() / "cut.mcap");
    ASSERT_FALSE(message.empty()) << "cut at " << n;
    EXPECT_NE(message.find("byte"), std::string::npos) << "cut at " << n << ": " << message;
  }
}

TEST(BagWireFormat, CdrAndRos1DecodersCheckEveryLength) {
  using bag::WireFormat;
  // CDR big-endian encapsulation: refused by name.
  std::vector<std::uint8_t> be = {0x00, 0x00, 0x00, 0x00, 1, 2, 3, 4};
  auto r = bag::decode_tf(be, WireFormat::kCdr);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("CDR big-endian"), std::string::npos) << r.error().message;
  // A TFMessage that claims a million transforms in 8 bytes: refused before allocating.
  std::vector<std::uint8_t> many = {0x00, 0x01, 0x00, 0x00, 0x40, 0x42, 0x0f, 0x00};
  r = bag::decode_tf(many, WireFormat::kCdr);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("1000000 elements"), std::string::npos) << r.error().message;
  // A CDR string whose length misses its NUL.
  std::vector<std::uint8_t> image = {0x00, 0x01, 0x00, 0x00, 1, 0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 'a', 'b'};
  auto i = bag::decode_image(image, WireFormat::kCdr);
  ASSERT_FALSE(i);
  EXPECT_NE(i.error().message.find("header.frame_id"), std::string::npos) << i.error().message;
  // ROS 1: an image cut inside its data.
  std::vector<std::uint8_t> ros1 = {0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 0, 0, 0, 0,  // seq, stamp, frame_id ""
                                    1, 0, 0, 0, 1, 0, 0, 0,                          // height, width
                                    5, 0, 0, 0, 'm', 'o', 'n', 'o', '8', 0,          // encoding, is_bigendian
                                    1, 0, 0, 0, 9, 0, 0, 0, 7};                      // step, 9 bytes of data at byte 42: 1 there
  i = bag::decode_image(ros1, WireFormat::kRos1);
  ASSERT_FALSE(i);
  EXPECT_NE(i.error().message.find("field 'data'"), std::string::npos) << i.error().message;
  EXPECT_NE(i.error().message.find("byte 42"), std::string::npos) << i.error().message;
}

}  // namespace
}  // namespace scenewatch::io

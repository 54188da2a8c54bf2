#pragma once
// What the three bag formats have in common once opened: topics with their message types and wire
// format, and an index of messages in recording order that can be read one at a time.
// Implementations: ros1_bag.cpp, rosbag2_sqlite.cpp, mcap_file.cpp. NOT thread safe (reading may
// cache a decompressed chunk).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "field_reader.h"
#include "scenewatch/core/result.h"

namespace scenewatch::io::bag {

/// A topic as the container declares it.
struct Topic {
  std::string name;  ///< "/camera/color/image_raw"
  std::string type;  ///< normalised to ROS 1 spelling: "sensor_msgs/Image" (ROS 2's "/msg/" dropped)
  WireFormat format = WireFormat::kRos1;
};

/// Where one message is; `where` is opaque to all but its container.
struct MessageRef {
  std::uint32_t topic = 0;  ///< index into Container::topics()
  std::int64_t log_time_ns = 0;
  std::uint64_t where[3] = {0, 0, 0};
};

class Container {
 public:
  virtual ~Container() = default;
  virtual const std::vector<Topic>& topics() const = 0;
  /// Every message, in the order recorded.
  virtual const std::vector<MessageRef>& messages() const = 0;
  /// The serialized message. Errors name the byte offset in the file (or the database row).
  virtual Result<std::vector<std::uint8_t>> read(const MessageRef& message) = 0;
  /// Where a message is, for error messages ("chunk at byte 4117, offset 96").
  virtual std::string locate(const MessageRef& message) const = 0;
};

/// "sensor_msgs/msg/Image" -> "sensor_msgs/Image".
std::string normalise_type(const std::string& type);

/// Opens a ROS 1 bag (format 2.0; chunks uncompressed, bz2 or lz4).
Result<std::unique_ptr<Container>> open_ros1_bag(const std::string& path);
/// Opens rosbag2 SQLite files (one or several .db3 of one bag, in order).
Result<std::unique_ptr<Container>> open_rosbag2_sqlite(const std::vector<std::string>& db3_files);
/// Opens an MCAP file (chunks uncompressed, lz4 or zstd; each chunk's CRC checked when given).
Result<std::unique_ptr<Container>> open_mcap(const std::string& path);

}  // namespace scenewatch::io::bag

#include "topic_choice.h"

#include "ros_messages.h"
#include "scenewatch/io/bag/image_conversion.h"

namespace scenewatch::io::bag {
namespace {

constexpr const char* kImage = "sensor_msgs/Image";
constexpr const char* kInfo = "sensor_msgs/CameraInfo";
constexpr const char* kCloud = "sensor_msgs/PointCloud2";
constexpr const char* kTf = "tf2_msgs/TFMessage";

std::string listing(const Container& bag, const std::vector<int>& topics, const std::vector<std::string>& notes = {}) {
  std::string out;
  for (std::size_t i = 0; i < topics.size(); ++i) {
    out += (i ? ", " : "") + bag.topics()[static_cast<std::size_t>(topics[i])].name;
    if (i < notes.size() && !notes[i].empty()) out += " (" + notes[i] + ")";
  }
  return out.empty() ? "none" : out;
}

std::string parent_of(const std::string& topic) {
  const auto slash = topic.rfind('/');
  return slash == std::string::npos ? "" : topic.substr(0, slash);
}

// The topic the user named, checked to exist with the type wanted.
Result<int> named(const Container& bag, const std::string& name, const char* type, const char* flag) {
  std::vector<int> of_type;
  for (std::size_t i = 0; i < bag.topics().size(); ++i) {
    const Topic& t = bag.topics()[i];
    if (t.type == type) of_type.push_back(static_cast<int>(i));
    if (t.name == name) {
      if (t.type != type) return invalid_argument(std::string(flag) + " " + name + ": the topic's type is " + t.type + ", not " + type);
      return static_cast<int>(i);
    }
  }
  return not_found(std::string(flag) + " " + name + ": no such topic; the " + type + " topics are: " + listing(bag, of_type));
}

}  // namespace

Result<TopicChoice> choose_topics(Container& bag, const BagOptions& options) {
  TopicChoice c;
  std::vector<int> colors, depths, infos, clouds, other_images;
  std::vector<std::string> depth_notes, other_notes;
  for (std::size_t i = 0; i < bag.topics().size(); ++i) {
    const Topic& t = bag.topics()[i];
    const int index = static_cast<int>(i);
    if (t.type == kInfo) infos.push_back(index);
    if (t.type == kCloud) clouds.push_back(index);
    if (t.type == kTf) c.tf.push_back(index);
    if (t.type != kImage) continue;
    // The first message's encoding says what the topic is.
    for (const MessageRef& m : bag.messages()) {
      if (m.topic != i) continue;
      auto bytes = bag.read(m);
      if (!bytes) return Error{bytes.error().code, "topic " + t.name + ", first message (" + bag.locate(m) + "): " + bytes.error().message};
      auto image = decode_image(*bytes, t.format);
      if (!image) return Error{image.error().code, "topic " + t.name + ", first message (" + bag.locate(m) + "): " + image.error().message};
      if (is_color_encoding(image->encoding)) colors.push_back(index);
      else if (is_depth_encoding(image->encoding)) depths.push_back(index), depth_notes.push_back(image->encoding);
      else other_images.push_back(index), other_notes.push_back(image->encoding);
      break;
    }
  }
  auto pick = [&](const std::string& flag_value, const char* type, const char* flag, const std::vector<int>& candidates,
                  const char* what, const std::vector<std::string>& notes, int& out) -> Status {
    if (!flag_value.empty()) {
      auto n = named(bag, flag_value, type, flag);
      if (!n) return n.error();
      out = *n;
      return {};
    }
    if (candidates.size() == 1) out = candidates[0];
    if (candidates.size() > 1) {
      return invalid_argument(std::string("several ") + what + " topics: " + listing(bag, candidates, notes) + "; choose one with " + flag);
    }
    return {};
  };
  if (auto st = pick(options.depth_topic, kImage, "--depth-topic", depths, "depth image", depth_notes, c.depth); !st) return st.error();
  if (c.depth < 0) {
    if (auto st = pick(options.cloud_topic, kCloud, "--cloud-topic", clouds, "sensor_msgs/PointCloud2", {}, c.cloud); !st) return st.error();
    if (c.cloud < 0) {
      std::string also = other_images.empty() ? "" : "; image topics of other encodings: " + listing(bag, other_images, other_notes);
      return not_found("no depth image topic (sensor_msgs/Image 16UC1, mono16 or 32FC1) and no sensor_msgs/PointCloud2 topic" + also);
    }
  }
  if (auto st = pick(options.color_topic, kImage, "--color-topic", colors, "colour image", {}, c.color); !st) return st.error();
  // Camera info: the one beside the depth topic when there are several.
  if (options.info_topic.empty() && infos.size() > 1 && c.depth >= 0) {
    const std::string beside = parent_of(bag.topics()[static_cast<std::size_t>(c.depth)].name);
    std::vector<int> near;
    for (int i : infos) {
      if (parent_of(bag.topics()[static_cast<std::size_t>(i)].name) == beside) near.push_back(i);
    }
    if (near.size() == 1) {
      c.info = near[0];
      return c;
    }
  }
  if (auto st = pick(options.info_topic, kInfo, "--info-topic", infos, "sensor_msgs/CameraInfo", {}, c.info); !st) return st.error();
  return c;
}

}  // namespace scenewatch::io::bag

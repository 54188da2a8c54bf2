#include "bridge_config.h"

namespace scenewatch::ros {

Result<std::string> dds_topic_name(const std::string& ros_topic) {
  if (ros_topic.size() < 2 || ros_topic[0] != '/' || ros_topic.back() == '/') {
    return invalid_argument("topic '" + ros_topic + "': give an absolute ROS topic name such as /camera/depth/image_raw");
  }
  return "rt" + ros_topic;
}

}  // namespace scenewatch::ros

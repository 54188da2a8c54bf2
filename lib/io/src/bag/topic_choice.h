#pragma once
// Which topics of a bag make the frames: the ones the user named (checked against the bag's types),
// else the only candidate of each kind. Image topics are told apart by the encoding of their first
// message. An ambiguous or missing choice is an error that lists the candidates and the flag.
#include <string>
#include <vector>

#include "container.h"
#include "scenewatch/io/bag.h"

namespace scenewatch::io::bag {

struct TopicChoice {
  int color = -1, depth = -1, info = -1, cloud = -1;  ///< topic indices; -1: none
  std::vector<int> tf;                                ///< every tf2_msgs/TFMessage topic
};

Result<TopicChoice> choose_topics(Container& bag, const BagOptions& options);

}  // namespace scenewatch::io::bag

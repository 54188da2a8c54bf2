// stalled_subscriber: a ROS 2 subscriber that never reads, in a process of its own, for the bridge's
// test of slow subscribers. Its readers on the bridge's reliable topics (events, objects, the map,
// the markers) keep every sample (KEEP_ALL) within resource limits of a few samples, so once those
// are full it acknowledges nothing more: the writer must either wait for it or go on. (Inside the
// test's own process such a reader stalled Cyclone's delivery to every reader of that process,
// the test's included, so it has to live apart.)
//
// Usage: stalled_subscriber DOMAIN MAX_SAMPLES. Prints "matched" once every reader has matched
// the bridge's writer, then "rejected N" whenever the samples its readers refused grow, until
// killed. CYCLONEDDS_URI comes from the environment.
#include <dds/dds.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "octomap_msgs.h"
#include "scenewatch_msgs.h"
#include "vision_msgs.h"
#include "visualization_msgs.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: stalled_subscriber DOMAIN MAX_SAMPLES\n");
    return 2;
  }
  const auto domain = static_cast<dds_domainid_t>(std::strtoul(argv[1], nullptr, 10));
  const int max_samples = std::atoi(argv[2]);
  const dds_entity_t participant = dds_create_participant(domain, nullptr, nullptr);
  if (participant < 0) {
    std::fprintf(stderr, "participant: %s\n", dds_strretcode(participant));
    return 1;
  }
  struct Topic {
    const char* name;
    const dds_topic_descriptor_t* type;
    bool transient_local;
  };
  const Topic topics[] = {{"rt/scenewatch/events", &scenewatch_msgs_msg_dds__EventArray__desc, false},
                          {"rt/scenewatch/objects", &vision_msgs_msg_dds__Detection3DArray__desc, false},
                          {"rt/scenewatch/octomap_binary", &octomap_msgs_msg_dds__Octomap__desc, true},
                          {"rt/scenewatch/markers", &visualization_msgs_msg_dds__MarkerArray__desc, false}};
  std::vector<dds_entity_t> readers;
  for (const Topic& t : topics) {
    const dds_entity_t topic = dds_create_topic(participant, t.type, t.name, nullptr, nullptr);
    dds_qos_t* q = dds_create_qos();
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
    dds_qset_resource_limits(q, max_samples, DDS_LENGTH_UNLIMITED, max_samples);
    if (t.transient_local) dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
    const dds_entity_t reader = topic < 0 ? topic : dds_create_reader(participant, topic, q, nullptr);
    dds_delete_qos(q);
    if (reader < 0) {
      std::fprintf(stderr, "%s: %s\n", t.name, dds_strretcode(reader));
      return 1;
    }
    readers.push_back(reader);
  }
  for (;;) {
    bool all = true;
    for (dds_entity_t r : readers) {
      dds_subscription_matched_status_t s{};
      dds_get_subscription_matched_status(r, &s);
      all = all && s.current_count > 0;
    }
    if (all) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::printf("matched\n");
  std::fflush(stdout);
  // Never reads. Says how many samples its full readers refused, whenever that grows: the proof
  // that they were full and the writer was left unacknowledged.
  std::uint64_t said = 0;
  for (;;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    std::uint64_t rejected = 0;
    for (dds_entity_t r : readers) {
      dds_sample_rejected_status_t s{};
      dds_get_sample_rejected_status(r, &s);
      rejected += s.total_count;
    }
    if (rejected > said) {
      said = rejected;
      std::printf("rejected %llu\n", static_cast<unsigned long long>(said));
      std::fflush(stdout);
    }
  }
}

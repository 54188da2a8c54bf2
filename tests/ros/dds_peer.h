#pragma once
// The test's own DDS participant, a ROS 2 peer as a camera driver, robot_state_publisher and a
// subscriber in RViz would be: it publishes images, CameraInfo and TF with the ROS 2 names and the
// same idlc-generated types as the bridge, and takes what the bridge publishes. Cyclone is set up
// for unicast on loopback (CYCLONEDDS_URI, inherited by the bridge) on a domain of its own.
#include <dds/dds.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <functional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "octomap_msgs.h"
#include "ros_messages.h"
#include "scenewatch_msgs.h"
#include "sensor_msgs.h"
#include "tf2_msgs.h"
#include "vision_msgs.h"
#include "visualization_msgs.h"

namespace scenewatch::test {

/// Cyclone on loopback only, unicast discovery; returns the random domain id chosen (and sets
/// CYCLONEDDS_URI and ROS_DOMAIN_ID for this process and the children it starts).
inline std::uint32_t configure_loopback_dds() {
  ::setenv("CYCLONEDDS_URI",
           "<CycloneDDS><Domain><General><Interfaces><NetworkInterface name=\"lo\"/></Interfaces>"
           "<AllowMulticast>false</AllowMulticast></General><Discovery><Peers><Peer address=\"127.0.0.1\"/></Peers>"
           "<ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>50</MaxAutoParticipantIndex></Discovery>"
           "<Internal><SocketReceiveBufferSize min=\"default\" max=\"8MB\"/></Internal>"
           "</Domain></CycloneDDS>",
           1);
  std::mt19937 random(static_cast<unsigned>(::getpid()) ^ static_cast<unsigned>(std::chrono::steady_clock::now().time_since_epoch().count()));
  const std::uint32_t domain = 1 + random() % 200;
  ::setenv("ROS_DOMAIN_ID", std::to_string(domain).c_str(), 1);
  return domain;
}

class DdsPeer {
 public:
  explicit DdsPeer(std::uint32_t domain) {
    participant_ = dds_create_participant(domain, nullptr, nullptr);
    EXPECT_GT(participant_, 0) << dds_strretcode(participant_);
  }
  ~DdsPeer() {
    if (participant_ > 0) dds_delete(participant_);
  }
  DdsPeer(const DdsPeer&) = delete;
  DdsPeer& operator=(const DdsPeer&) = delete;

  /// A writer or reader on rt<topic>; QoS: reliable (else best effort), keep last `depth`,
  /// transient local when asked.
  dds_entity_t entity(const std::string& topic, const dds_topic_descriptor_t* type, bool reader, bool reliable, int depth,
                      bool transient_local = false) {
    const dds_entity_t t = dds_create_topic(participant_, type, ("rt" + topic).c_str(), nullptr, nullptr);
    EXPECT_GT(t, 0) << topic << ": " << dds_strretcode(t);
    dds_qos_t* q = dds_create_qos();
    dds_qset_reliability(q, reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT, DDS_SECS(1));
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
    if (transient_local) dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
    const dds_entity_t e = reader ? dds_create_reader(participant_, t, q, nullptr) : dds_create_writer(participant_, t, q, nullptr);
    dds_delete_qos(q);
    EXPECT_GT(e, 0) << topic << ": " << dds_strretcode(e);
    return e;
  }

  /// A reader on `topic` (the DDS name, "rt/...") with the QoS given.
  dds_entity_t reader_with(const std::string& topic, const dds_topic_descriptor_t* type, const dds_qos_t* qos) {
    const dds_entity_t t = dds_create_topic(participant_, type, topic.c_str(), nullptr, nullptr);
    EXPECT_GT(t, 0) << topic << ": " << dds_strretcode(t);
    const dds_entity_t r = dds_create_reader(participant_, t, qos, nullptr);
    EXPECT_GT(r, 0) << topic << ": " << dds_strretcode(r);
    return r;
  }

  /// Waits until every writer and reader has matched a remote peer.
  static bool wait_matched(const std::vector<dds_entity_t>& writers, const std::vector<dds_entity_t>& readers, double timeout_s) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < until) {
      bool all = true;
      for (auto w : writers) {
        dds_publication_matched_status_t s{};
        dds_get_publication_matched_status(w, &s);
        all = all && s.current_count > 0;
      }
      for (auto r : readers) {
        dds_subscription_matched_status_t s{};
        dds_get_subscription_matched_status(r, &s);
        all = all && s.current_count > 0;
      }
      if (all) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }

  /// Takes every waiting sample of `reader` and hands each to `handle` (as its C type).
  template <typename T>
  static void take(dds_entity_t reader, const std::function<void(const T&)>& handle) {
    for (;;) {
      void* samples[1] = {nullptr};
      dds_sample_info_t info;
      const dds_return_t n = dds_take(reader, samples, &info, 1, 1);
      if (n <= 0) return;
      if (info.valid_data) handle(*static_cast<const T*>(samples[0]));
      dds_return_loan(reader, samples, n);
    }
  }

 private:
  dds_entity_t participant_ = 0;
};

}  // namespace scenewatch::test

// cyclone_cdr: serializes ROS 2 messages with Eclipse Cyclone DDS's own CDR serializer, for the
// rosbag2 and MCAP test bags of tests/io/make_bag.py (--cdr-tool). The bytes a bag holds for a
// message are what a ROS 2 recorder on rmw_cyclonedds_cpp stores: the serialized sample as it
// travels, 4-byte encapsulation header first. Here each sample is written by a DDS writer and taken
// back, serialized, by a reader of the same participant (dds_takecdr): nothing of scenewatch's own
// touches the bytes.
//
// Protocol, one message at a time on standard input; the answer on standard output is a 4-byte
// little-endian length and that many bytes:
//   image SEC NSEC FRAME HEIGHT WIDTH ENCODING STEP NBYTES\n  then NBYTES raw bytes
//   info SEC NSEC FRAME HEIGHT WIDTH MODEL ND D... K(9) R(9) P(12)\n
//   tf N\n  then N lines: SEC NSEC PARENT CHILD TX TY TZ QX QY QZ QW
#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "sensor_msgs.h"
#include "tf2_msgs.h"

namespace {

[[noreturn]] void fail(const std::string& what) { throw std::runtime_error(what); }

/// One topic with a writer and a reader on it: write a sample, take its serialized form.
class Loopback {
 public:
  Loopback(dds_entity_t participant, const dds_topic_descriptor_t* type, const char* name) {
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(10));
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
    const dds_entity_t topic = dds_create_topic(participant, type, name, qos, nullptr);
    writer_ = dds_create_writer(participant, topic, qos, nullptr);
    reader_ = dds_create_reader(participant, topic, qos, nullptr);
    dds_delete_qos(qos);
    if (topic < 0 || writer_ < 0 || reader_ < 0) fail(std::string("cannot create the DDS entities of ") + name);
    waitset_ = dds_create_waitset(participant);
    dds_waitset_attach(waitset_, dds_create_readcondition(reader_, DDS_ANY_STATE), 0);
  }

  std::vector<unsigned char> serialize(const void* sample) {
    if (dds_write(writer_, sample) < 0) fail("dds_write failed");
    for (int attempt = 0; attempt < 100; ++attempt) {
      ddsi_serdata* serdata = nullptr;
      dds_sample_info_t info;
      if (dds_takecdr(reader_, &serdata, 1, &info, DDS_ANY_STATE) == 1) {
        std::vector<unsigned char> bytes(ddsi_serdata_size(serdata));
        ddsi_serdata_to_ser(serdata, 0, bytes.size(), bytes.data());
        ddsi_serdata_unref(serdata);
        return bytes;
      }
      dds_waitset_wait(waitset_, nullptr, 0, DDS_MSECS(100));
    }
    fail("the sample written never reached the reader");
  }

 private:
  dds_entity_t writer_ = 0, reader_ = 0, waitset_ = 0;
};

void stamp(std::istream& in, std_msgs_msg_dds__Header_& header, std::string& frame) {
  in >> header.stamp.sec >> header.stamp.nanosec >> frame;
  header.frame_id = frame.data();
}

std::vector<unsigned char> image(std::istream& line, Loopback& out) {
  sensor_msgs_msg_dds__Image_ msg{};
  std::string frame, encoding;
  std::size_t nbytes = 0;
  stamp(line, msg.header, frame);
  line >> msg.height >> msg.width >> encoding >> msg.step >> nbytes;
  if (!line) fail("malformed image line");
  std::vector<unsigned char> data(nbytes);
  if (!std::cin.read(reinterpret_cast<char*>(data.data()), static_cast<std::streamsize>(nbytes))) fail("image data cut short");
  msg.encoding = encoding.data();
  msg.data._buffer = data.data();
  msg.data._length = msg.data._maximum = static_cast<uint32_t>(nbytes);
  return out.serialize(&msg);
}

std::vector<unsigned char> info(std::istream& line, Loopback& out) {
  sensor_msgs_msg_dds__CameraInfo_ msg{};
  std::string frame, model;
  std::size_t nd = 0;
  stamp(line, msg.header, frame);
  line >> msg.height >> msg.width >> model >> nd;
  std::vector<double> d(nd);
  for (double& v : d) line >> v;
  for (double& v : msg.k) line >> v;
  for (double& v : msg.r) line >> v;
  for (double& v : msg.p) line >> v;
  if (!line) fail("malformed info line");
  msg.distortion_model = model.data();
  msg.d._buffer = d.data();
  msg.d._length = msg.d._maximum = static_cast<uint32_t>(nd);
  return out.serialize(&msg);
}

std::vector<unsigned char> tf(std::istream& line, Loopback& out) {
  std::size_t n = 0;
  line >> n;
  if (!line) fail("malformed tf line");
  std::vector<geometry_msgs_msg_dds__TransformStamped_> transforms(n);
  std::vector<std::string> parents(n), children(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::string text;
    std::getline(std::cin, text);
    std::istringstream in(text);
    auto& t = transforms[i];
    stamp(in, t.header, parents[i]);
    in >> children[i] >> t.transform.translation.x >> t.transform.translation.y >> t.transform.translation.z >>
        t.transform.rotation.x >> t.transform.rotation.y >> t.transform.rotation.z >> t.transform.rotation.w;
    if (!in) fail("malformed transform line: " + text);
    t.header.frame_id = parents[i].data();
    t.child_frame_id = children[i].data();
  }
  tf2_msgs_msg_dds__TFMessage_ msg{};
  msg.transforms._buffer = transforms.data();
  msg.transforms._length = msg.transforms._maximum = static_cast<uint32_t>(n);
  return out.serialize(&msg);
}

}  // namespace

int main() {
  try {
    // Local delivery only: loopback, no multicast, a domain of its own.
    const char* config =
        "<CycloneDDS><Domain><General><Interfaces><NetworkInterface name=\"lo\"/></Interfaces>"
        "<AllowMulticast>false</AllowMulticast></General></Domain></CycloneDDS>";
    const dds_entity_t domain = dds_create_domain(230, config);
    const dds_entity_t participant = dds_create_participant(230, nullptr, nullptr);
    if (domain < 0 || participant < 0) fail("cannot create a DDS participant");
    Loopback images(participant, &sensor_msgs_msg_dds__Image__desc, "rt/image");
    Loopback infos(participant, &sensor_msgs_msg_dds__CameraInfo__desc, "rt/camera_info");
    Loopback tfs(participant, &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf");
    std::string text;
    while (std::getline(std::cin, text)) {
      std::istringstream line(text);
      std::string kind;
      line >> kind;
      std::vector<unsigned char> bytes;
      if (kind == "image") bytes = image(line, images);
      else if (kind == "info") bytes = info(line, infos);
      else if (kind == "tf") bytes = tf(line, tfs);
      else fail("unknown message kind '" + kind + "'");
      const uint32_t size = static_cast<uint32_t>(bytes.size());
      const unsigned char length[4] = {static_cast<unsigned char>(size), static_cast<unsigned char>(size >> 8),
                                       static_cast<unsigned char>(size >> 16), static_cast<unsigned char>(size >> 24)};
      std::cout.write(reinterpret_cast<const char*>(length), 4);
      std::cout.write(reinterpret_cast<const char*>(bytes.data()), size);
      std::cout.flush();
    }
    dds_delete(domain);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "cyclone_cdr: " << e.what() << "\n";
    return 1;
  }
}

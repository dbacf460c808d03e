// The wire format of exports and imports is std_msgs/msg/Float64MultiArray as ROS 2 puts it on
// DDS: checked here byte for byte against the message's published layout (XCDR1, little endian;
// MultiArrayLayout's dim sequence and data_offset, then sequence<double>), without ROS installed.

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>

#include <unistd.h>

#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "float64_multi_array.h"

namespace chimera {
namespace {

using Msg = std_msgs_msg_dds__Float64MultiArray_;
using Dim = std_msgs_msg_dds__MultiArrayDimension_;

TEST(WireFormat, TypeNameIsRos2s) {
  EXPECT_STREQ(std_msgs_msg_dds__Float64MultiArray__desc.m_typename, "std_msgs::msg::dds_::Float64MultiArray_");
}

TEST(WireFormat, Float64MultiArrayBytesAreRos2s) {
  const dds_entity_t participant = dds_create_participant(DDS_DOMAIN_DEFAULT, nullptr, nullptr);
  ASSERT_GT(participant, 0);
  dds_qos_t* qos = dds_create_qos();
  const std::string partition = "chimera_wire_format_" + std::to_string(getpid());
  dds_qset_partition1(qos, partition.c_str());
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  const dds_entity_t topic =
      dds_create_topic(participant, &std_msgs_msg_dds__Float64MultiArray__desc, "rt/x", nullptr, nullptr);
  const dds_entity_t writer = dds_create_writer(participant, topic, qos, nullptr);
  const dds_entity_t reader = dds_create_reader(participant, topic, qos, nullptr);
  dds_delete_qos(qos);
  ASSERT_GT(writer, 0);
  ASSERT_GT(reader, 0);

  char label[] = "x";
  Dim dim{label, 2, 2};
  double data[] = {1.5, -2.0};
  Msg msg{};
  msg.layout.dim._length = msg.layout.dim._maximum = 1;
  msg.layout.dim._buffer = &dim;
  msg.layout.data_offset = 0;
  msg.data._length = msg.data._maximum = 2;
  msg.data._buffer = data;
  ASSERT_EQ(dds_write(writer, &msg), DDS_RETCODE_OK);

  // Writer and reader of one participant: the sample is there once write returns (local delivery).
  ddsi_serdata* sample = nullptr;
  dds_sample_info_t info;
  ASSERT_EQ(dds_takecdr(reader, &sample, 1, &info, DDS_ANY_STATE), 1);
  std::vector<std::uint8_t> bytes(ddsi_serdata_size(sample));
  ddsi_serdata_to_ser(sample, 0, bytes.size(), bytes.data());
  ddsi_serdata_unref(sample);
  dds_delete(participant);

  const std::vector<std::uint8_t> expected = {
      0x00, 0x01, 0x00, 0x00,                          // encapsulation: CDR, little endian
      0x01, 0x00, 0x00, 0x00,                          // layout.dim: 1 element
      0x02, 0x00, 0x00, 0x00, 'x',  0x00,              // dim[0].label: length 2 with its NUL
      0x00, 0x00,                                      // padding to 4
      0x02, 0x00, 0x00, 0x00,                          // dim[0].size
      0x02, 0x00, 0x00, 0x00,                          // dim[0].stride
      0x00, 0x00, 0x00, 0x00,                          // layout.data_offset
      0x02, 0x00, 0x00, 0x00,                          // data: 2 elements
      0x00, 0x00, 0x00, 0x00,                          // padding to 8 (offset 28 -> 32 after the header)
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF8, 0x3F,  // 1.5
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xC0,  // -2.0
  };
  EXPECT_EQ(bytes, expected);
}

}  // namespace
}  // namespace chimera

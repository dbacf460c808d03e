#pragma once
// The writer's stamp on each sample: who wrote it, its sequence number and the writer's time. It
// travels as the label of a second, size-1 dimension of the Float64MultiArray's layout, so the
// message stays a standard one: a ROS 2 reader sees an N x 1 array of the same N values, and
// `ros2 topic echo` shows the stamp as text. Private to src/dds.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace chimera::dds_detail {

struct SampleStamp {
  std::string writer;          // the exporting subsystem's name
  std::uint64_t sequence = 0;  // 1 for the first sample of a variable, then one more each
  std::int64_t time_ns = 0;    // the writer's CLOCK_REALTIME when it published: not our clock
};

/// "chimera:from=vision;seq=12;t=1700000000000000000". Not real-time safe.
std::string stamp_label(const SampleStamp& stamp);
/// The stamp of a label made by stamp_label(); nullopt for anything else (a ROS 2 node's
/// sample carries none). Not real-time safe.
std::optional<SampleStamp> parse_stamp_label(std::string_view label);

/// What an exporting writer says of itself in its USER_DATA QoS, which every reader learns at
/// discovery, before any sample: its subsystem and the variable's element count.
struct WriterShape {
  std::string writer;
  std::uint32_t count = 0;
};

/// "chimera:from=vision;type=f64;count=6". Not real-time safe.
std::string shape_userdata(const WriterShape& shape);
/// The shape of user data made by shape_userdata(); nullopt for anything else (a ROS 2 node's
/// writer has none). Not real-time safe.
std::optional<WriterShape> parse_shape_userdata(std::string_view data);

}  // namespace chimera::dds_detail

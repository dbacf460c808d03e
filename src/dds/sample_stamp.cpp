#include "sample_stamp.hpp"

#include <charconv>

#include <fmt/format.h>

namespace chimera::dds_detail {
namespace {

constexpr std::string_view kPrefix = "chimera:from=";

template <class Int>
bool parse_int(std::string_view text, Int& out) {
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc() && end == text.data() + text.size();
}

}  // namespace

std::string stamp_label(const SampleStamp& stamp) {
  return fmt::format("{}{};seq={};t={}", kPrefix, stamp.writer, stamp.sequence, stamp.time_ns);
}

std::optional<SampleStamp> parse_stamp_label(std::string_view label) {
  if (!label.starts_with(kPrefix)) return std::nullopt;
  label.remove_prefix(kPrefix.size());
  const auto seq = label.find(";seq=");
  const auto time = label.find(";t=");
  if (seq == std::string_view::npos || time == std::string_view::npos || time < seq) return std::nullopt;
  SampleStamp stamp;
  stamp.writer = std::string(label.substr(0, seq));
  const auto seq_text = label.substr(seq + 5, time - seq - 5);
  if (!parse_int(seq_text, stamp.sequence) || !parse_int(label.substr(time + 3), stamp.time_ns)) return std::nullopt;
  return stamp;
}

std::string shape_userdata(const WriterShape& shape) {
  return fmt::format("{}{};type=f64;count={}", kPrefix, shape.writer, shape.count);
}

std::optional<WriterShape> parse_shape_userdata(std::string_view data) {
  constexpr std::string_view kCount = ";type=f64;count=";
  if (!data.starts_with(kPrefix)) return std::nullopt;
  data.remove_prefix(kPrefix.size());
  const auto count = data.rfind(kCount);
  if (count == std::string_view::npos) return std::nullopt;
  WriterShape shape;
  shape.writer = std::string(data.substr(0, count));
  if (!parse_int(data.substr(count + kCount.size()), shape.count)) return std::nullopt;
  return shape;
}

}  // namespace chimera::dds_detail

#include "dds_bridge.hpp"

#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

namespace chimera::cli {

DdsBridge::DdsBridge(const SubsystemSpec& spec, Subsystem& subsystem, std::string table_name)
    : spec_(spec), subsystem_(subsystem), table_name_(std::move(table_name)) {}

Result<std::unique_ptr<DdsBridge>> DdsBridge::start(const SubsystemSpec& spec, Subsystem& subsystem,
                                                    std::string table_name) {
  std::unique_ptr<DdsBridge> bridge(new DdsBridge(spec, subsystem, std::move(table_name)));
  for (const auto& x : spec.exports)
    if (auto watched = subsystem.watch_writes(x.variable, bridge->exports_written_); !watched)
      spdlog::warn("dds: export {}: {}; it is polled", x.variable, watched.error().message);
  if (auto attached = bridge->attach(); !attached) return attached.error();
  return bridge;
}

Result<void> DdsBridge::attach() {
  // Read before attaching: a rebuild after this read is seen at the next poll.
  runtimes_seen_ = subsystem_.runtimes_built();
  ports_.reset();  // the old bridge leaves the domain (and the old region) before the new one joins
  RemotePortsOptions options;
  options.exports_written = exports_written_;
  auto ports = RemotePorts::create(spec_, table_name_, std::move(options));
  if (!ports) return ports.error();
  ports_ = std::move(*ports);
  return {};
}

std::vector<std::string> DdsBridge::poll() {
  std::vector<std::string> lines;
  if (subsystem_.runtimes_built() != runtimes_seen_) {
    if (ports_ != nullptr)
      for (auto& line : ports_->take_errors()) lines.push_back(std::move(line));
    if (auto attached = attach(); attached)
      lines.emplace_back("the table was made anew (a task added): the bridge follows it");
    else
      lines.push_back(
          fmt::format("the table was made anew and the bridge could not follow it: {}; imports and exports stop",
                      attached.error().message));
  }
  if (ports_ == nullptr) return lines;
  for (auto& line : ports_->take_errors()) lines.push_back(std::move(line));
  for (auto& line : ports_->take_changes()) lines.push_back(std::move(line));
  return lines;
}

std::vector<std::string> DdsBridge::stop() {
  std::vector<std::string> lines;
  if (ports_ != nullptr) lines = ports_->take_errors();
  ports_.reset();
  return lines;
}

}  // namespace chimera::cli

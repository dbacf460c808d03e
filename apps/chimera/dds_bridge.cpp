#include "dds_bridge.hpp"

#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

namespace chimera::cli {

DdsBridge::DdsBridge(Subsystem& subsystem, std::string shm_suffix)
    : subsystem_(subsystem), shm_suffix_(std::move(shm_suffix)) {}

Result<std::unique_ptr<DdsBridge>> DdsBridge::start(Subsystem& subsystem, std::string shm_suffix) {
  std::unique_ptr<DdsBridge> bridge(new DdsBridge(subsystem, std::move(shm_suffix)));
  if (auto attached = bridge->attach(); !attached) return attached.error();
  return bridge;
}

Result<void> DdsBridge::attach() {
  // Read before attaching: a rebuild after this read is seen at the next poll.
  runtimes_seen_ = subsystem_.runtimes_built();
  ports_.reset();  // the old bridge leaves the domain (and the old region) before the new one joins
  const SubsystemSpec spec = subsystem_.spec();
  // The subsystem keeps a watch across rebuilds: each variable is registered once.
  for (const auto& x : spec.exports) {
    if (watched_.contains(x.variable)) continue;
    if (auto watched = subsystem_.watch_writes(x.variable, exports_written_); !watched)
      spdlog::warn("dds: export {}: {}; it is polled", x.variable, watched.error().message);
    else
      watched_.insert(x.variable);
  }
  if (!spec.has_remote_variables()) return {};
  RemotePortsOptions options;
  options.exports_written = exports_written_;
  auto ports = RemotePorts::create(spec, spec.name + shm_suffix_, std::move(options));
  if (!ports) return ports.error();
  ports_ = std::move(*ports);
  return {};
}

std::vector<std::string> DdsBridge::follow() {
  std::vector<std::string> lines;
  const bool bridged = ports_ != nullptr;
  if (bridged)
    for (auto& line : ports_->take_errors()) lines.push_back(std::move(line));
  if (auto attached = attach(); attached && ports_ != nullptr)
    lines.emplace_back("the table was made anew (a task added, or a file opened): the bridge follows it");
  else if (attached && bridged)
    lines.emplace_back("the subsystem has no exports or imports now: the bridge stops");
  else if (!attached)
    lines.push_back(
        fmt::format("the table was made anew and the bridge could not follow it: {}; imports and exports stop",
                    attached.error().message));
  return lines;
}

std::vector<std::string> DdsBridge::news() {
  std::vector<std::string> lines;
  if (ports_ == nullptr) return lines;
  for (auto& line : ports_->take_errors()) lines.push_back(std::move(line));
  for (auto& line : ports_->take_changes()) lines.push_back(std::move(line));
  return lines;
}

std::vector<RemoteImport> DdsBridge::imports() const {
  std::vector<RemoteImport> out;
  if (ports_ == nullptr) return out;
  for (const auto& status : ports_->imports()) {
    RemoteImport& i = out.emplace_back();
    i.variable = status.variable;
    i.writer = status.writer;
    i.samples = status.samples;
    i.refused = status.refused;
    i.age_ns = status.age_ns;
    i.stale = status.stale;
    i.refusal = status.refusal;
    i.max_age_ns = status.max_age_ns;
  }
  return out;
}

std::vector<std::string> DdsBridge::stop() {
  std::vector<std::string> lines;
  if (ports_ != nullptr) lines = ports_->take_errors();
  ports_.reset();
  return lines;
}

}  // namespace chimera::cli

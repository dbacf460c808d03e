#include "chimera/svt/local_table.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <set>

#include <fmt/format.h>

namespace chimera {

namespace {

constexpr std::size_t kind_index(PortKind k) noexcept { return static_cast<std::size_t>(k); }

}  // namespace

Result<LocalTable> LocalTable::create(GlobalTable& global, std::span<const PortBinding> ports) {
  LocalTable table;
  table.global_ = &global;
  table.ports_.assign(ports.begin(), ports.end());
  table.slots_.reserve(ports.size());
  std::set<std::string_view> names;
  std::uint64_t offset = 0;
  std::uint64_t largest_input_words = 0;
  for (const PortBinding& p : ports) {
    if (!names.insert(p.port).second) {
      return make_error(Errc::kInvalidInput, fmt::format("port '{}' is declared twice", p.port));
    }
    const auto var = global.find(p.variable);
    if (!var) {
      return make_error(Errc::kNotFound, fmt::format("port '{}' is bound to state variable '{}', which is not in "
                                                     "the global table",
                                                     p.port, p.variable));
    }
    if (global.shape(*var) != p.shape) {
      return make_error(Errc::kIllegal, fmt::format("port '{}' is {} but state variable '{}' is {}", p.port,
                                                    to_string(p.shape), p.variable, to_string(global.shape(*var))));
    }
    // 8-aligned offsets: every element type's view is aligned, whatever came before it.
    offset = (offset + 7) / 8 * 8;
    const std::uint64_t bytes = p.shape.bytes();
    if (offset + bytes > std::numeric_limits<std::uint32_t>::max()) {
      return make_error(Errc::kInvalidInput, fmt::format("ports up to '{}' need more than 4 GiB", p.port));
    }
    table.slots_.push_back(
        Slot{*var, p.kind, static_cast<std::uint32_t>(offset), static_cast<std::uint32_t>(bytes), 0, -1});
    table.by_kind_[kind_index(p.kind)].push_back(static_cast<std::uint32_t>(table.slots_.size() - 1));
    if (is_input(p.kind)) largest_input_words = std::max(largest_input_words, (bytes + 7) / 8);
    offset += bytes;
  }
  table.storage_.resize((offset + sizeof(std::max_align_t) - 1) / sizeof(std::max_align_t));
  table.freshness_.assign(ports.size(), Freshness::kNoData);
  table.scratch_.resize(largest_input_words);
  // Every local copy starts at zero. Value-initialising max_align_t is not enough: its padding
  // (around the long double) keeps whatever the heap held.
  if (!table.storage_.empty()) std::memset(table.storage_.data(), 0, table.storage_.size() * sizeof(std::max_align_t));
  return table;
}

Result<const LocalTable::Slot*> LocalTable::find_slot(std::string_view port, bool want_input, ElemType type) const {
  for (std::size_t i = 0; i < ports_.size(); ++i) {
    if (ports_[i].port != port) continue;
    const Slot& s = slots_[i];
    if (is_input(s.kind) != want_input) {
      return make_error(Errc::kInvalidInput, want_input ? fmt::format("port '{}' is an output; use out<>()", port)
                                                        : fmt::format("port '{}' is an input; use in<>()", port));
    }
    if (ports_[i].shape.type != type) {
      return make_error(Errc::kInvalidInput, fmt::format("port '{}' holds {}, not {}", port,
                                                         elem_name(ports_[i].shape.type), elem_name(type)));
    }
    return &s;
  }
  return make_error(Errc::kNotFound, fmt::format("port '{}' does not exist", port));
}

PortWindow LocalTable::bind(std::string_view port, bool input, ElemType type, std::string& error) {
  auto slot = find_slot(port, input, type);
  if (!slot) {
    error = slot.error().message;
    return {};
  }
  const Slot* s = *slot;
  const auto index = static_cast<std::size_t>(s - slots_.data());
  // Storage is raw max-aligned bytes; each port's offset is 8-aligned, so any element type is
  // aligned there.
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): see above
  auto* bytes = reinterpret_cast<std::byte*>(storage_.data()) + s->offset;
  return PortWindow{bytes, s->bytes / elem_size(type), input ? &freshness_[index] : nullptr};
}

void LocalTable::pull(PortKind kind) noexcept {
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): storage_ is raw max-aligned bytes
  auto* base = reinterpret_cast<std::byte*>(storage_.data());
  for (const std::uint32_t i : by_kind_[kind_index(kind)]) {
    Slot& s = slots_[i];
    const ReadOutcome r = global_->read_via(s.var, base + s.offset, s.seen, scratch_.data());
    s.seen = r.version;
    freshness_[i] = r.freshness;
  }
}

void LocalTable::push(PortKind kind) noexcept {
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): storage_ is raw max-aligned bytes
  const auto* base = reinterpret_cast<const std::byte*>(storage_.data());
  for (const std::uint32_t i : by_kind_[kind_index(kind)]) global_->write(slots_[i].var, base + slots_[i].offset);
}

void LocalTable::pull_in_consts() noexcept { pull(PortKind::kInConst); }
void LocalTable::pull_in_vars() noexcept { pull(PortKind::kInVar); }

void LocalTable::push_out_vars(std::int64_t at_ns) noexcept {
  push(PortKind::kOutVar);
  if (history_ == nullptr) return;
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): storage_ is raw max-aligned bytes
  const auto* base = reinterpret_cast<const std::byte*>(storage_.data());
  for (const std::uint32_t i : by_kind_[kind_index(PortKind::kOutVar)])
    if (slots_[i].ring >= 0) history_->write(static_cast<std::size_t>(slots_[i].ring), at_ns, base + slots_[i].offset);
}

void LocalTable::keep_history(HistoryRings* rings, std::span<const std::int32_t> ring_of_var) noexcept {
  history_ = rings;
  for (Slot& s : slots_) s.ring = rings != nullptr && s.var < ring_of_var.size() ? ring_of_var[s.var] : -1;
}
void LocalTable::push_out_consts() noexcept { push(PortKind::kOutConst); }

void LocalTable::reset_inputs() noexcept {
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): storage_ is raw max-aligned bytes
  auto* base = reinterpret_cast<std::byte*>(storage_.data());
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    Slot& s = slots_[i];
    if (!is_input(s.kind)) continue;
    std::memset(base + s.offset, 0, s.bytes);
    s.seen = 0;
    freshness_[i] = Freshness::kNoData;
  }
}

}  // namespace chimera

#pragma once
// Template bodies of LocalTable's typed view lookups.

namespace chimera {

template <class T>
Result<In<T>> LocalTable::input(std::string_view port) {
  auto slot = find_slot(port, /*want_input=*/true, kElemTypeOf<T>);
  if (!slot) return slot.error();
  const Slot* s = *slot;
  const auto index = static_cast<std::size_t>(s - slots_.data());
  // Storage is raw max-aligned bytes; each port's offset is 8-aligned, so T is aligned there.
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): see above
  const auto* bytes = reinterpret_cast<const std::byte*>(storage_.data()) + s->offset;
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): see above
  return In<T>(reinterpret_cast<const T*>(bytes), s->bytes / sizeof(T), &freshness_[index]);
}

template <class T>
Result<Out<T>> LocalTable::output(std::string_view port) {
  auto slot = find_slot(port, /*want_input=*/false, kElemTypeOf<T>);
  if (!slot) return slot.error();
  const Slot* s = *slot;
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): as in input()
  auto* bytes = reinterpret_cast<std::byte*>(storage_.data()) + s->offset;
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): as in input()
  return Out<T>(reinterpret_cast<T*>(bytes), s->bytes / sizeof(T));
}

}  // namespace chimera

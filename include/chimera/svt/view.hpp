#pragma once
// Typed views a module receives in init(): windows onto its own local state variable table.
// All member functions are real-time safe: no allocation, no lookup, no lock.

#include <cstddef>
#include <span>

#include "chimera/svt/freshness.hpp"

namespace chimera {

/// An input port (in-var or in-const): read-only elements and their freshness.
template <class T>
class In {
 public:
  In() = default;
  In(const T* data, std::size_t count, const Freshness* freshness)
      : data_(data), count_(count), freshness_(freshness) {}

  [[nodiscard]] std::span<const T> values() const noexcept { return {data_, count_}; }
  [[nodiscard]] const T& operator[](std::size_t i) const noexcept { return data_[i]; }
  [[nodiscard]] std::size_t size() const noexcept { return count_; }
  [[nodiscard]] Freshness freshness() const noexcept { return *freshness_; }
  [[nodiscard]] bool has_data() const noexcept { return *freshness_ != Freshness::kNoData; }
  [[nodiscard]] bool bound() const noexcept { return data_ != nullptr; }

 private:
  const T* data_ = nullptr;
  std::size_t count_ = 0;
  const Freshness* freshness_ = nullptr;
};

/// An output port (out-var or out-const): writable elements, published after the method.
template <class T>
class Out {
 public:
  Out() = default;
  Out(T* data, std::size_t count) : data_(data), count_(count) {}

  [[nodiscard]] std::span<T> values() const noexcept { return {data_, count_}; }
  [[nodiscard]] T& operator[](std::size_t i) const noexcept { return data_[i]; }
  [[nodiscard]] std::size_t size() const noexcept { return count_; }
  [[nodiscard]] bool bound() const noexcept { return data_ != nullptr; }

 private:
  T* data_ = nullptr;
  std::size_t count_ = 0;
};

}  // namespace chimera

#pragma once
// What the fuzz targets share: the libFuzzer entry point's declaration and the input as text.
// The same targets build as libFuzzer programs (CHIMERA_FUZZ=ON) and as plain programs that
// replay the checked-in corpus and regression inputs (replay_main.cpp), so every input that once
// crashed stays a test of the main tree.

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace chimera::fuzz {

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): bytes viewed as chars, same size
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace chimera::fuzz

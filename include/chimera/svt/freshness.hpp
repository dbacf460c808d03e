#pragma once
#include <cstdint>

namespace chimera {

/// How fresh an input is after the transfer before a method (OROCOS RTT's FlowStatus idea).
enum class Freshness : std::uint8_t {
  kNoData,  // no task has written the variable yet; the view holds zeros
  kOld,     // the same value as at the previous transfer
  kNew,     // written since the previous transfer
};

}  // namespace chimera

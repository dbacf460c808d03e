#pragma once
// Something the subsystem interface should tell the operator: a task entering ERROR, a switch,
// a job overdue.

#include <cstdint>
#include <string>

namespace chimera {

struct Event {
  std::int64_t time_ns = 0;  // on the subsystem's clock
  std::string task;          // "" for the subsystem itself (a switch)
  std::string text;
};

}  // namespace chimera

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
  // The line of a committed switch: the switch's record says it whole, so what reports records
  // (the network API's events) leaves this line out; the shell prints it.
  bool is_switch = false;
};

}  // namespace chimera

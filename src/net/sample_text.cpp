#include "sample_text.hpp"

#include <cmath>
#include <iterator>

#include <fmt/format.h>

namespace chimera::net {

void append_sample_value(std::string& out, const Result<std::vector<double>>& value) {
  if (!value) {
    out += "null";
    return;
  }
  out += '[';
  for (std::size_t i = 0; i < value->size(); ++i) {
    if (i != 0) out += ',';
    const double x = (*value)[i];
    if (std::isfinite(x))
      fmt::format_to(std::back_inserter(out), "{}", x);  // the shortest text that reads back as x
    else
      out += "null";
  }
  out += ']';
}

}  // namespace chimera::net

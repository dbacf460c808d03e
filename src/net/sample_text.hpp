#pragma once
// A sampled state variable as the text of a stream's frame: what a batched "samples" frame is
// built from, one sample at a time as it is taken (formatting a whole batch at once lost one
// sample in thirty to the time it took). Not real-time safe: run on a stream's thread.

#include <string>
#include <vector>

#include "chimera/core/result.hpp"

namespace chimera::net {

/// Appends `value` to `out` as JSON: an array of its doubles, each the shortest text that reads
/// back as the same double, a non-finite one as null (JSON has no NaN; nlohmann's dump writes
/// null too); or null for a variable not written yet (an error).
void append_sample_value(std::string& out, const Result<std::vector<double>>& value);

}  // namespace chimera::net

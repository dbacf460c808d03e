#pragma once

// Parsing JSON text in the tests, compiled once per tree: nlohmann::json::parse's instantiation
// cost each test file that called it 18 s of compile time under ASAN (a one-function file,
// measured), which CI's clean machine paid a dozen times in its 45 minutes.

#include <string>

#include <nlohmann/json.hpp>

namespace chimera::test {

/// nlohmann::json::parse(text): throws nlohmann::json::parse_error on text that is not JSON, or,
/// with allow_exceptions false, returns a discarded value (is_discarded()) instead.
nlohmann::json parse_json(const std::string& text, bool allow_exceptions = true);

}  // namespace chimera::test

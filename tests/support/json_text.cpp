#include "support/json_text.hpp"

namespace chimera::test {

nlohmann::json parse_json(const std::string& text, bool allow_exceptions) {
  return nlohmann::json::parse(text, nullptr, allow_exceptions);
}

}  // namespace chimera::test

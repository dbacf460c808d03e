// Reading a YAML text's documents without YAML::LoadAll (see load_first_document in
// yaml_reader.hpp): one pass with yaml-cpp's event parser finds where documents start and stops at
// the second, or where the parser stops moving; then YAML::Load, which reads one document only,
// builds the first.

#include <sstream>
#include <string>

#include <fmt/format.h>
#include <yaml-cpp/anchor.h>
#include <yaml-cpp/emitterstyle.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/mark.h>
#include <yaml-cpp/parser.h>

#include "detail/yaml_reader.hpp"

namespace chimera::config_detail {
namespace {

// Only where each document starts matters here, and where its first node is (the line a
// message about a second document names, as the node's own mark would).
class DocumentStarts final : public YAML::EventHandler {
 public:
  void OnDocumentStart(const YAML::Mark& mark) override {
    start_ = mark;
    first_node_ = mark;
    seen_node_ = false;
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t /*anchor*/) override { node_at(mark); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t /*anchor*/) override { node_at(mark); }
  void OnScalar(const YAML::Mark& mark, const std::string& /*tag*/, YAML::anchor_t /*anchor*/,
                const std::string& /*value*/) override {
    node_at(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string& /*tag*/, YAML::anchor_t /*anchor*/,
                       YAML::EmitterStyle::value /*style*/) override {
    node_at(mark);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string& /*tag*/, YAML::anchor_t /*anchor*/,
                  YAML::EmitterStyle::value /*style*/) override {
    node_at(mark);
  }
  void OnMapEnd() override {}

  [[nodiscard]] const YAML::Mark& start() const { return start_; }
  [[nodiscard]] const YAML::Mark& first_node() const { return first_node_; }

 private:
  void node_at(const YAML::Mark& mark) {
    if (seen_node_) return;
    first_node_ = mark;
    seen_node_ = true;
  }

  YAML::Mark start_ = YAML::Mark::null_mark();
  YAML::Mark first_node_ = YAML::Mark::null_mark();
  bool seen_node_ = false;
};

int line_of(const YAML::Mark& mark) { return mark.is_null() ? 1 : mark.line + 1; }

}  // namespace

Result<FirstDocument> load_first_document(const Source& source, std::string_view text) {
  const std::string copy(text);
  try {
    std::istringstream in(copy);
    YAML::Parser parser(in);
    DocumentStarts starts;
    // Three documents at most: the first, a second that is either real or the parser stuck on a
    // token, and a third that tells which (a stuck parser starts it where the second started).
    int documents = 0;
    YAML::Mark previous = YAML::Mark::null_mark();
    std::optional<int> second_line;
    while (documents < 3 && parser.HandleNextDocument(starts)) {
      ++documents;
      if (documents > 1 && starts.start().pos == previous.pos)
        return source.fail(line_of(previous), "",
                           "YAML syntax error: the parser cannot go on from here (a ',' outside [ ] or { }?)");
      if (documents == 2) second_line = line_of(starts.first_node());
      previous = starts.start();
    }
    return FirstDocument{YAML::Load(copy), second_line};
  } catch (const YAML::ParserException& e) {
    return source.fail(line_of(e.mark), "", fmt::format("YAML syntax error: {}", e.msg));
  }
}

}  // namespace chimera::config_detail

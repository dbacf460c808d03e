// The module pages (docs/modules/NAME.md) against the modules: the build embeds each page as the
// module's summary and documentation (what `chimera modules NAME` prints), and the page's Ports
// and Parameters tables, which the command prints from the declarations instead, must say what
// the module declares. A port or parameter added, renamed or given a new default without its
// page fails here.

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/module/registry.hpp"

namespace chimera {
namespace {

const std::string kDocs = CHIMERA_DOCS_DIR;

std::string read_page(const std::string& name) {
  std::ifstream in(kDocs + "/" + name + ".md");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string trim(const std::string& s) {
  const auto first = s.find_first_not_of(' ');
  if (first == std::string::npos) return {};
  return s.substr(first, s.find_last_not_of(' ') - first + 1);
}

std::string unquote(std::string s) {
  if (s.size() >= 2 && s.front() == '`' && s.back() == '`') s = s.substr(1, s.size() - 2);
  return s;
}

// The rows of the first table under the heading `heading`, by the first cell (without backticks).
std::map<std::string, std::vector<std::string>> table_rows(const std::string& page, const std::string& heading) {
  std::map<std::string, std::vector<std::string>> rows;
  const auto at = page.find("\n" + heading + "\n");
  if (at == std::string::npos) return rows;
  std::istringstream lines(page.substr(at + heading.size() + 2));
  std::string line;
  int seen = 0;
  while (std::getline(lines, line)) {
    if (line.rfind("## ", 0) == 0) break;
    if (line.rfind('|', 0) != 0) {
      if (seen > 0) break;  // the end of the table
      continue;
    }
    if (++seen <= 2) continue;  // the header and the |---| line
    std::vector<std::string> cells;
    std::string cell;
    std::istringstream parts(line.substr(1));
    while (std::getline(parts, cell, '|')) cells.push_back(trim(cell));
    if (!cells.empty()) rows[unquote(cells[0])] = cells;
  }
  return rows;
}

TEST(ModuleDocs, EveryModuleHasAPageThatSaysWhatItDeclares) {
  const auto modules = Registry::global().list();
  ASSERT_GE(modules.size(), 11U);
  for (const ModuleInfo* m : modules) {
    SCOPED_TRACE(m->name);
    ASSERT_TRUE(std::filesystem::exists(kDocs + "/" + m->name + ".md")) << "no page docs/modules/" << m->name << ".md";
    const std::string page = read_page(m->name);
    // The title line is the summary the module registers, and the page's text its documentation.
    EXPECT_EQ(page.substr(0, page.find('\n')), "# " + m->name + " — " + m->summary);
    EXPECT_NE(page.find(m->doc.substr(0, 200)), std::string::npos) << "the build's copy of the page is stale";
    EXPECT_EQ(m->doc.find("\n## Ports\n"), std::string::npos);
    EXPECT_NE(page.find("## Reference"), std::string::npos) << "say where the algorithm comes from";

    const Declarations d = m->declarations(Params{});
    const auto ports = table_rows(page, "## Ports");
    EXPECT_EQ(ports.size(), d.ports().size()) << "the Ports table has a row per port";
    for (const auto& p : d.ports()) {
      const auto row = ports.find(p.name);
      ASSERT_NE(row, ports.end()) << "port " << p.name << " is not in the Ports table";
      ASSERT_GE(row->second.size(), 3U);
      EXPECT_EQ(row->second[1], port_kind_name(p.kind)) << p.name;
      EXPECT_EQ(row->second[2].rfind(to_string(p.dim), 0), 0U) << p.name << ": size " << row->second[2];
    }
    const auto params = table_rows(page, "## Parameters");
    EXPECT_EQ(params.size(), d.params().size()) << "the Parameters table has a row per parameter";
    for (const auto& p : d.params()) {
      const auto row = params.find(p.name);
      ASSERT_NE(row, params.end()) << "parameter " << p.name << " is not in the Parameters table";
      ASSERT_GE(row->second.size(), 5U);
      EXPECT_EQ(row->second[1], param_type_name(p.type)) << p.name;
      EXPECT_EQ(row->second[2], p.unit.empty() ? "—" : p.unit) << p.name;
      EXPECT_EQ(row->second[3], "`" + to_string(p.default_value) + "`") << p.name;
      EXPECT_EQ(row->second[4], p.rule.empty() ? "—" : "`" + describe(p.rule) + "`") << p.name << ": what it accepts";
    }
  }
}

}  // namespace
}  // namespace chimera

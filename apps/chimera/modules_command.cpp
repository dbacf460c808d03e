// chimera modules [NAME] [--plugin LIB]...: the module library (with every module library on
// CHIMERA_MODULE_PATH and those given), or one module's ports, parameters and docs. A library
// that does not load is named and left out; the rest is listed all the same.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "chimera/core/text_table.hpp"
#include "chimera/module/plugin_loader.hpp"
#include "chimera/module/registry.hpp"
#include "commands.hpp"
#include "exit_codes.hpp"

namespace chimera::cli {

namespace {

using Align = TextTable::Align;

constexpr std::size_t kTextWidth = 100;

// Terminal columns of UTF-8 text: one per code point (the pages' ⁻¹, ·, Δ take one column each).
std::size_t columns(std::string_view text) {
  return static_cast<std::size_t>(
      std::count_if(text.begin(), text.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0U) != 0x80U; }));
}

// One line of prose wrapped for a terminal at `width`, words kept whole.
void wrap_line(std::string_view line, std::size_t width, std::string& out) {
  std::size_t column = 0;
  std::size_t i = 0;
  while (i < line.size()) {
    if (line[i] == ' ') {
      ++i;
      continue;
    }
    const std::size_t end = std::min(line.find(' ', i), line.size());
    const std::string_view word = line.substr(i, end - i);
    if (column > 0 && column + 1 + columns(word) > width) {
      out += '\n';
      column = 0;
    } else if (column > 0) {
      out += ' ';
      ++column;
    }
    out += word;
    column += columns(word);
    i = end;
  }
}

// Module docs (Markdown) for a terminal: prose lines wrapped at `width`; indented code, fenced
// code and table rows kept as they are, their spaces being their layout.
std::string wrap(std::string_view text, std::size_t width) {
  std::string out;
  bool in_fence = false;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    const std::string_view line = text.substr(start, end - start);
    const bool fence = line.starts_with("```");
    if (fence) in_fence = !in_fence;
    if (fence || in_fence || line.starts_with(' ') || line.starts_with('|')) {
      out += line;
    } else {
      wrap_line(line, width, out);
    }
    if (end < text.size()) out += '\n';
    start = end + 1;
  }
  return out;
}

// Every library on CHIMERA_MODULE_PATH, then those of --plugin. One that does not load (broken,
// built for another Chimera, a duplicate of another) is named, one line each, and the others load
// on: one bad file on the path must not hide the rest of the library. Returns how many failed.
std::size_t load_plugins(const std::vector<std::string>& extra) {
  std::size_t failed = 0;
  const std::vector<std::string> search_path = module_search_path();
  for (const auto& file : plugins_on_path(search_path)) {
    if (auto loaded = load_plugin(std::filesystem::path(file).filename().string(), file); !loaded) {
      fmt::print(stderr, "CHIMERA_MODULE_PATH: {}\n", loaded.error().message);
      ++failed;
    }
  }
  for (const auto& name : extra) {
    auto found = find_plugin(name, search_path, ".");
    auto loaded = found ? load_plugin(name, *found) : Result<LoadedPlugin>(found.error());
    if (!loaded) {
      fmt::print(stderr, "--plugin: {}\n", loaded.error().message);
      ++failed;
    }
  }
  return failed;
}

// The closing line when libraries were left out, so that a listing is never taken for the whole.
void say_what_is_missing(std::size_t failed) {
  if (failed == 0) return;
  fmt::print(stderr, "chimera modules: {} module librar{} did not load (named above); {}\n", failed,
             failed == 1 ? "y" : "ies", "their modules are missing from what is shown");
}

void print_list(const Registry& registry) {
  const auto modules = registry.list();
  const bool any_plugin = std::any_of(modules.begin(), modules.end(),
                                      [&](const ModuleInfo* m) { return !registry.origin(m->name).empty(); });
  if (!any_plugin) {
    TextTable table({{"module", Align::kLeft}, {"summary", Align::kLeft}});
    for (const ModuleInfo* m : modules) table.add_row({m->name, m->summary});
    fmt::print("{}", table.render());
    return;
  }
  TextTable table({{"module", Align::kLeft}, {"summary", Align::kLeft}, {"library", Align::kLeft}});
  for (const ModuleInfo* m : modules) {
    const std::string_view origin = registry.origin(m->name);
    table.add_row({m->name, m->summary, origin.empty() ? std::string("(built in)") : std::string(origin)});
  }
  fmt::print("{}", table.render());
}

void print_module(const ModuleInfo& m, std::string_view origin) {
  // Ports may depend on parameters; the defaults show the usual shape (sizes stay symbolic).
  const Declarations decls = m.declarations(Params{});

  fmt::print("{}: {}\n", m.name, m.summary);
  if (!origin.empty()) fmt::print("library: {}\n", origin);
  if (!m.doc.empty()) fmt::print("\n{}\n", wrap(m.doc, kTextWidth));
  if (!decls.resource().empty()) fmt::print("\nresource: {}\n", decls.resource());

  fmt::print("\nports:\n");
  if (decls.ports().empty()) {
    fmt::print("  (none)\n");
  } else {
    TextTable ports({{"  kind", Align::kLeft},
                     {"name", Align::kLeft},
                     {"type", Align::kLeft},
                     {"size", Align::kLeft},
                     {"doc", Align::kLeft}});
    for (const auto& p : decls.ports()) {
      std::string size = to_string(p.dim);
      if (!p.value.empty()) size += fmt::format(" = [{}]", fmt::join(p.value, ", "));
      ports.add_row({fmt::format("  {}", port_kind_name(p.kind)), p.name, std::string(elem_name(p.type)), size, p.doc});
    }
    fmt::print("{}", ports.render());
  }

  fmt::print("\nparams:\n");
  if (decls.params().empty()) {
    fmt::print("  (none)\n");
  } else {
    TextTable params({{"  name", Align::kLeft},
                      {"type", Align::kLeft},
                      {"default", Align::kLeft},
                      {"accepts", Align::kLeft},
                      {"unit", Align::kLeft},
                      {"doc", Align::kLeft}});
    for (const auto& p : decls.params()) {
      const std::string accepts = describe(p.rule);
      params.add_row({fmt::format("  {}", p.name), std::string(param_type_name(p.type)), to_string(p.default_value),
                      accepts.empty() ? "any" : accepts, p.unit, p.doc});
    }
    fmt::print("{}", params.render());
  }
}

}  // namespace

int modules_command(const ModulesArgs& args) {
  const std::size_t failed = load_plugins(args.plugins);
  const Registry& registry = Registry::global();
  // Like ls over a directory with an unreadable entry: what loaded is shown, what did not is
  // named on stderr, and the exit code (2) says the answer is not whole.
  const int code = failed == 0 ? kExitOk : kExitInvalid;
  if (!args.name) {
    print_list(registry);
    std::fflush(stdout);  // the list first, then the closing line, whatever the streams are
    say_what_is_missing(failed);
    return code;
  }
  const ModuleInfo* module = registry.find(*args.name);
  if (module == nullptr) {
    fmt::print(stderr, "unknown module '{}' (chimera modules lists them)\n", *args.name);
    say_what_is_missing(failed);
    return kExitInvalid;
  }
  print_module(*module, registry.origin(module->name));
  std::fflush(stdout);
  say_what_is_missing(failed);
  return code;
}

}  // namespace chimera::cli

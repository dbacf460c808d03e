// chimera new-module NAME [--lang cpp|c] [--dir DIR]: writes DIR/NAME/, a module library ready to
// build against the installed package and to load without rebuilding chimera.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>

#include <fmt/format.h>

#include "commands.hpp"
#include "exit_codes.hpp"
#include "module_templates.hpp"

namespace chimera::cli {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kTemplateName = "my_module";
constexpr std::string_view kTemplateClass = "MyModule";
constexpr std::size_t kMaxNameLength = 64;

// Lower case, digits and _: the name becomes a module name, a C identifier and a library file.
bool valid_name(std::string_view name) {
  if (name.empty() || name.size() > kMaxNameLength || !(name.front() >= 'a' && name.front() <= 'z')) return false;
  return std::all_of(name.begin(), name.end(),
                     [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_'; });
}

// my_filter -> MyFilter, for the C++ class.
std::string class_name(std::string_view name) {
  std::string out;
  bool upper = true;
  for (char c : name) {
    if (c == '_') {
      upper = true;
      continue;
    }
    out += upper && c >= 'a' && c <= 'z' ? static_cast<char>(c - 'a' + 'A') : c;
    upper = false;
  }
  return out;
}

std::string replace_all(std::string_view text, std::string_view from, std::string_view to) {
  std::string out;
  std::size_t at = 0;
  for (std::size_t hit = text.find(from); hit != std::string_view::npos; hit = text.find(from, at)) {
    out.append(text.substr(at, hit - at)).append(to);
    at = hit + from.size();
  }
  out.append(text.substr(at));
  return out;
}

std::string instantiate(std::string_view text, std::string_view name) {
  return replace_all(replace_all(text, kTemplateClass, class_name(name)), kTemplateName, name);
}

// The prefix chimera runs from, when it is an install (bin/chimera beside lib*/cmake/chimera).
std::string install_prefix() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  const fs::path prefix = exe.parent_path().parent_path();
  for (const char* lib : {"lib", "lib64", "lib/x86_64-linux-gnu", "lib/aarch64-linux-gnu"})
    if (fs::exists(prefix / lib / "cmake" / "chimera" / "chimeraConfig.cmake", ec)) return prefix.string();
  return {};
}

}  // namespace

int new_module_command(const NewModuleArgs& args) {
  if (!valid_name(args.name)) {
    fmt::print(stderr,
               "new-module: '{}' is not a valid module name (a lower-case letter, then lower-case letters, digits "
               "and _; at most {} characters)\n",
               args.name, kMaxNameLength);
    return kExitInvalid;
  }
  const fs::path folder = fs::path(args.dir) / args.name;
  std::error_code ec;
  if (fs::exists(folder, ec)) {
    fmt::print(stderr, "new-module: {} already exists; choose another name or --dir\n", folder.string());
    return kExitInvalid;
  }
  if (!fs::create_directories(folder, ec) || ec) {
    fmt::print(stderr, "new-module: cannot create {}: {}\n", folder.string(), ec.message());
    return kExitInvalid;
  }
  const auto files = module_template(args.c ? TemplateLanguage::kC : TemplateLanguage::kCpp);
  for (const TemplateFile& file : files) {
    const fs::path path = folder / instantiate(file.name, args.name);
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    const std::string text = instantiate(file.text, args.name);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    if (!out) {
      fmt::print(stderr, "new-module: cannot write {}\n", path.string());
      return kExitInvalid;
    }
  }

  const std::string prefix = install_prefix();
  const std::string folder_text = folder.string();
  fmt::print("wrote {}/ ({} module {}):\n", folder_text, args.c ? "a C" : "a C++", args.name);
  for (const TemplateFile& file : files) fmt::print("  {}\n", instantiate(file.name, args.name));
  fmt::print(
      "build it and run it:\n"
      "  cmake -S {0} -B {0}/build -DCMAKE_PREFIX_PATH={1}\n"
      "  cmake --build {0}/build\n"
      "  export CHIMERA_MODULE_PATH={0}/build\n"
      "  chimera modules {2}\n"
      "  printf 'wait 1s\\nget y\\n' | chimera run {0}/{2}.yaml --clock virtual --for 2s\n",
      folder_text, prefix.empty() ? std::string("<chimera's install prefix>") : prefix, args.name);
  return kExitOk;
}

}  // namespace chimera::cli

#include "chimera/net/opened_files.hpp"

#include <stdlib.h>  // mkdtemp

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include "chimera/net/access_tokens.hpp"

namespace chimera::net {

namespace {

bool plain_file_name(std::string_view name) {
  return !name.empty() && name.size() <= 100 && name.front() != '.' &&
         std::all_of(name.begin(), name.end(), [](char c) {
           return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '.' || c == '_' || c == '-';
         });
}

}  // namespace

OpenedFiles::~OpenedFiles() {
  if (dir_.empty()) return;
  std::error_code ignored;
  std::filesystem::remove_all(dir_, ignored);
}

Result<std::string> OpenedFiles::write(std::string_view name, std::string_view text) {
  if (!plain_file_name(name))
    return make_error(Errc::kInvalidInput,
                      fmt::format("file: '{}' is not a plain file name (letters, digits, '.', '_' and '-', not "
                                  "starting with '.'; at most 100)",
                                  name));
  if (dir_.empty()) {
    // NOLINTNEXTLINE(concurrency-mt-unsafe): nothing of ours sets the environment
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = fmt::format("{}/chimera-open-XXXXXX", tmp != nullptr && *tmp == '/' ? tmp : "/tmp");
    std::vector<char> buffer(pattern.begin(), pattern.end());
    buffer.push_back('\0');
    if (::mkdtemp(buffer.data()) == nullptr)
      return make_error(Errc::kSystem, fmt::format("open: cannot make a directory {}: {}", pattern,
                                                   std::generic_category().message(errno)));
    dir_ = buffer.data();  // mkdtemp makes it mode 0700
  }
  const std::string path = fmt::format("{}/{}", dir_, name);
  // A file the disk cut short is not opened: the write's error is the reply.
  if (auto done = write_private_file(path, text); !done)
    return make_error(Errc::kSystem, "open: " + done.error().message);
  return path;
}

std::string OpenedFiles::as_named(std::string_view message) const {
  std::string out(message);
  if (dir_.empty()) return out;
  const std::string prefix = dir_ + "/";
  for (auto at = out.find(prefix); at != std::string::npos; at = out.find(prefix, at)) out.erase(at, prefix.size());
  return out;
}

}  // namespace chimera::net

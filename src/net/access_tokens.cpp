#include "chimera/net/access_tokens.hpp"

#include <fcntl.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <system_error>

#include <fmt/format.h>

namespace chimera::net {

namespace {

constexpr std::size_t kRandomBytes = 32;

// strerror() is not thread-safe; the error_code's message is.
std::string errno_text(int error) { return std::error_code(error, std::generic_category()).message(); }

Result<std::string> random_hex() {
  std::array<unsigned char, kRandomBytes> bytes{};
  std::size_t got = 0;
  while (got < bytes.size()) {
    const ssize_t n = ::getrandom(bytes.data() + got, bytes.size() - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return make_error(Errc::kSystem, fmt::format("getrandom: {}", errno_text(errno)));
    got += static_cast<std::size_t>(n);
  }
  std::string hex;
  for (unsigned char b : bytes) hex += fmt::format("{:02x}", b);
  return hex;
}

bool visible_ascii(std::string_view token) {
  return std::ranges::all_of(token, [](char c) { return c >= '!' && c <= '~'; });
}

std::vector<std::string_view> words_of(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

// Equal lengths are compared byte by byte to the end: no early exit tells where they differ.
bool same_token(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

Result<void> private_directory(const std::string& dir) {
  if (::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST)
    return make_error(Errc::kSystem, fmt::format("cannot create {}: {}", dir, errno_text(errno)));
  struct stat st {};
  if (::lstat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
    return make_error(Errc::kSystem, fmt::format("{} is not a directory", dir));
  // Another user's directory (or one open to others) could be watched or swapped under us.
  if (st.st_uid != ::geteuid() || (st.st_mode & 077) != 0)
    return make_error(Errc::kSystem, fmt::format("{} is not this user's private directory (owner and mode 0700)", dir));
  return {};
}

}  // namespace

std::string_view role_name(Role role) { return role == Role::kOperator ? "operator" : "viewer"; }

Result<AccessTokens> AccessTokens::generate() {
  AccessTokens tokens;
  for (Role role : {Role::kOperator, Role::kViewer}) {
    auto token = random_hex();
    if (!token) return token.error();
    tokens.entries_.push_back(Entry{role, std::move(*token)});
  }
  return tokens;
}

Result<AccessTokens> AccessTokens::load(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    return make_error(Errc::kInvalidInput, fmt::format("--token-file {}: {}", path, errno_text(errno)));
  if ((st.st_mode & 077) != 0)
    return make_error(Errc::kInvalidInput,
                      fmt::format("--token-file {}: other users may read it (mode {:04o}); chmod 600 {}", path,
                                  st.st_mode & 07777, path));
  std::ifstream in(path);
  if (!in) return make_error(Errc::kInvalidInput, fmt::format("--token-file {}: cannot read it", path));
  std::stringstream text;
  text << in.rdbuf();
  return parse(text.str(), path);
}

Result<AccessTokens> AccessTokens::parse(std::string_view text, std::string_view origin) {
  AccessTokens tokens;
  int line_number = 0;
  while (!text.empty()) {
    ++line_number;
    const auto newline = text.find('\n');
    std::string_view line = text.substr(0, newline);
    text = newline == std::string_view::npos ? std::string_view{} : text.substr(newline + 1);
    if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    const auto words = words_of(line);
    if (words.empty()) continue;
    auto bad = [&](const std::string& why) {
      return make_error(Errc::kInvalidInput, fmt::format("{}:{}: {}", origin, line_number, why));
    };
    if (words.size() > 2) return bad("expected [ROLE] TOKEN (ROLE: operator or viewer)");
    Role role = Role::kOperator;
    if (words.size() == 2) {
      if (words[0] == "viewer")
        role = Role::kViewer;
      else if (words[0] != "operator")
        return bad(fmt::format("unknown role '{}' (operator or viewer)", words[0]));
    }
    const std::string_view token = words.back();
    if (token.size() < kMinTokenChars || !visible_ascii(token))
      return bad(fmt::format("a token is at least {} visible ASCII characters", kMinTokenChars));
    for (const auto& e : tokens.entries_)
      if (e.token == token) return bad("this token is already listed");
    tokens.entries_.push_back(Entry{role, std::string(token)});
  }
  if (tokens.entries_.empty()) return make_error(Errc::kInvalidInput, fmt::format("{}: no token in it", origin));
  return tokens;
}

std::optional<Role> AccessTokens::role_of(std::string_view presented) const {
  std::optional<Role> role;
  for (const auto& e : entries_)  // every entry, matched or not: the time does not say which
    if (same_token(presented, e.token)) role = e.role;
  return role;
}

std::optional<std::string> AccessTokens::first(Role role) const {
  for (const auto& e : entries_)
    if (e.role == role) return e.token;
  return std::nullopt;
}

std::string AccessTokens::file_text() const {
  std::string out = "# chimera control API tokens: ROLE TOKEN (operator: everything; viewer: read only)\n";
  for (const auto& e : entries_) out += fmt::format("{} {}\n", role_name(e.role), e.token);
  return out;
}

Result<void> write_private_file(const std::string& path, std::string_view text) {
  // A fresh file, so that its mode is ours from the first byte; never through a link left there.
  if (::unlink(path.c_str()) != 0 && errno != ENOENT)
    return make_error(Errc::kSystem, fmt::format("cannot replace {}: {}", path, errno_text(errno)));
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-vararg): open() takes the mode as its vararg; no other call sets it
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0600);
  if (fd < 0) return make_error(Errc::kSystem, fmt::format("cannot write {}: {}", path, errno_text(errno)));
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = errno;
      ::close(fd);
      return make_error(Errc::kSystem, fmt::format("cannot write {}: {}", path, errno_text(error)));
    }
    done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) return make_error(Errc::kSystem, fmt::format("cannot write {}: {}", path, errno_text(errno)));
  return {};
}

Result<std::string> default_token_path(std::string_view name) {
  std::string dir;
  // NOLINTNEXTLINE(concurrency-mt-unsafe): read once at start, before any thread of ours sets the environment
  if (const char* runtime = std::getenv("XDG_RUNTIME_DIR"); runtime != nullptr && runtime[0] == '/') {
    if (auto made = private_directory(std::string(runtime) + "/chimera"); !made) return made.error();
    dir = std::string(runtime) + "/chimera";
  } else {
    dir = fmt::format("/tmp/chimera-{}", ::geteuid());
    if (auto made = private_directory(dir); !made) return made.error();
  }
  return fmt::format("{}/{}.token", dir, name);
}

}  // namespace chimera::net

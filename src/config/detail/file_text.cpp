// An input file (a subsystem file, a profile) is read only if it is a regular file of bounded size: a FIFO with no
// writer would block `chimera verify` forever, /dev/zero would be read without end, and a file of gigabytes would take
// many times that in YAML nodes before any message.

#include "file_text.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string_view>

#include <fmt/format.h>

#include "chimera/config/loader.hpp"

namespace chimera::config_detail {
namespace {

class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  ~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  [[nodiscard]] int get() const { return fd_; }

 private:
  int fd_;
};

std::string_view kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

Error too_large(const std::string& path, std::string_view what) {
  return Error{Errc::kInvalidInput,
               fmt::format("{}: larger than {} bytes, the most a {} may hold", path, kMaxSubsystemFileBytes, what)};
}

}  // namespace

Result<std::string> read_file_text(const std::string& path, std::string_view what) {
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer, before fstat could
  // tell it is one. It changes nothing for a regular file.
  const FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));  // NOLINT(*-vararg)
  if (fd.get() < 0)
    return make_error(Errc::kInvalidInput,
                      fmt::format("{}: cannot open the {} ({})", path, what, std::strerror(errno)));
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0)
    return make_error(Errc::kInvalidInput,
                      fmt::format("{}: cannot read the {} ({})", path, what, std::strerror(errno)));
  if (!S_ISREG(st.st_mode))
    return make_error(Errc::kInvalidInput, fmt::format("{}: is {}, not a {} (only regular files are read)", path,
                                                       kind_of(st.st_mode), what));
  if (static_cast<std::uintmax_t>(st.st_size) > kMaxSubsystemFileBytes) return too_large(path, what);

  // Read to the end, not st_size bytes: the file may change meanwhile; the bound holds either way.
  std::string text;
  text.resize(static_cast<std::size_t>(st.st_size) + 1);
  std::size_t used = 0;
  for (;;) {
    if (used == text.size()) {
      if (text.size() > kMaxSubsystemFileBytes) return too_large(path, what);
      text.resize(text.size() * 2);
    }
    const ssize_t n = ::read(fd.get(), text.data() + used, text.size() - used);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0)
      return make_error(Errc::kInvalidInput,
                        fmt::format("{}: cannot read the {} ({})", path, what, std::strerror(errno)));
    if (n == 0) break;
    used += static_cast<std::size_t>(n);
  }
  if (used > kMaxSubsystemFileBytes) return too_large(path, what);
  text.resize(used);
  return text;
}

}  // namespace chimera::config_detail

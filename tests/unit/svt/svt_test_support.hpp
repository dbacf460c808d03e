#pragma once
// Helpers shared by the state variable tests: names that do not collide when ctest runs tests
// in parallel, and a way to look at a region the way another process would.

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cstddef>
#include <string>
#include <string_view>

namespace chimera::test {

/// A subsystem name unique to this process and call: "t<pid>_<tag>_<n>".
inline std::string unique_subsystem(std::string_view tag) {
  static std::atomic<int> counter{0};
  return "t" + std::to_string(::getpid()) + "_" + std::string(tag) + "_" + std::to_string(counter++);
}

/// A second, independent mapping of /chimera_<name>, as another process would have it.
class RawMapping {
 public:
  explicit RawMapping(const std::string& subsystem) {
    const std::string shm = "/chimera_" + subsystem;
    const int fd = ::shm_open(shm.c_str(), O_RDWR, 0);
    if (fd < 0) return;
    struct stat st {};
    if (::fstat(fd, &st) == 0 && st.st_size > 0) {
      size_ = static_cast<std::size_t>(st.st_size);
      void* p = ::mmap(nullptr, size_, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
      if (p != MAP_FAILED) base_ = static_cast<std::byte*>(p);
    }
    ::close(fd);
  }
  RawMapping(const RawMapping&) = delete;
  RawMapping& operator=(const RawMapping&) = delete;
  ~RawMapping() {
    if (base_ != nullptr) ::munmap(base_, size_);
  }
  [[nodiscard]] std::byte* base() const { return base_; }
  [[nodiscard]] std::size_t size() const { return size_; }

 private:
  std::byte* base_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace chimera::test

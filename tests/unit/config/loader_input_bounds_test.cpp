// What the loader reads at all: only a regular file (a FIFO or a device is refused without
// reading from it; a directory: loader_test.cpp) and at most kMaxSubsystemFileBytes, from a file or as text.

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "unit/config/fake_modules.hpp"

namespace chimera {
namespace {

const Registry& registry() { return test::config_test_registry(); }

constexpr std::string_view kSmallFile = "subsystem: s\ntasks:\n  - {name: a, module: visual_servo}\n";

class LoaderInputBounds : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (std::filesystem::temp_directory_path() / "chimera_bounds_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  [[nodiscard]] std::string write(const std::string& name, std::string_view text) const {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  std::filesystem::path dir_;
};

std::string error_of_file(const std::string& path) {
  auto r = load_subsystem_file(path, registry());
  EXPECT_FALSE(r.ok()) << path << " loaded";
  if (r.ok()) return {};
  EXPECT_EQ(r.error().code, Errc::kInvalidInput);
  return r.error().message;
}

// A FIFO with no writer: opened without waiting for one, and refused before any read (the test
// would hang here otherwise).
TEST_F(LoaderInputBounds, AFifoIsRefusedWithoutBlocking) {
  const std::string fifo = (dir_ / "fifo.yaml").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(error_of_file(fifo), fifo + ": is a FIFO, not a subsystem file (only regular files are read)");
  auto plugins = read_plugin_names_file(fifo);
  ASSERT_FALSE(plugins.ok());
  EXPECT_EQ(plugins.error().message, fifo + ": is a FIFO, not a subsystem file (only regular files are read)");
}

// /dev/zero would be read without end.
TEST_F(LoaderInputBounds, ADeviceIsRefusedUnread) {
  EXPECT_EQ(error_of_file("/dev/zero"),
            "/dev/zero: is a character device, not a subsystem file (only regular files are read)");
}

// A link to a regular file is that file.
TEST_F(LoaderInputBounds, ASymlinkToARegularFileIsRead) {
  const std::string target = write("real.yaml", kSmallFile);
  const std::string link = (dir_ / "link.yaml").string();
  std::filesystem::create_symlink(target, link);
  auto r = load_subsystem_file(link, registry());
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r->name, "s");
}

// The bound is exact: a file of kMaxSubsystemFileBytes loads, one byte more does not.
TEST_F(LoaderInputBounds, AFileOfTheBoundLoadsAndOneByteMoreIsRefused) {
  std::string text(kSmallFile);
  text += '#';
  text.resize(kMaxSubsystemFileBytes - 1, ' ');
  text += '\n';
  ASSERT_EQ(text.size(), kMaxSubsystemFileBytes);
  auto at_bound = load_subsystem_file(write("at_bound.yaml", text), registry());
  EXPECT_TRUE(at_bound.ok()) << at_bound.error().message;

  const std::string over = write("over.yaml", text + "\n");
  EXPECT_EQ(error_of_file(over), over + ": larger than 4194304 bytes, the most a subsystem file may hold");
}

TEST_F(LoaderInputBounds, TextOverTheBoundIsRefusedBeforeParsing) {
  // Unbalanced brackets: were it parsed, the message would be a syntax error.
  const std::string text(kMaxSubsystemFileBytes + 1, '[');
  auto r = load_subsystem_text(text, "big.yaml", registry());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, "big.yaml:1: larger than 4194304 bytes, the most a subsystem file may hold");
}

}  // namespace
}  // namespace chimera

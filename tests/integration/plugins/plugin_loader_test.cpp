// Module libraries found on a search path and loaded into the process (plugin_loader.hpp,
// config/plugins.hpp): what a good library brings, and one clear refusal for each way a library
// can be broken. The libraries are built beside this test (CMakeLists.txt).

#include "chimera/module/plugin_loader.hpp"

#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/config/plugins.hpp"
#include "chimera/module/registry.hpp"

namespace chimera {
namespace {

namespace fs = std::filesystem;

const std::string kGood = PLUGIN_GOOD_DIR;
const std::string kBad = PLUGIN_BAD_DIR;

std::string good(const std::string& file) { return kGood + "/" + file; }
std::string bad(const std::string& file) { return kBad + "/" + file; }

// The message of a load that must fail.
std::string load_error(const std::string& path) {
  auto r = load_plugin(fs::path(path).filename().string(), path);
  EXPECT_FALSE(r.ok()) << path << " loaded";
  return r.ok() ? std::string() : r.error().message;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

class ScratchDir {
 public:
  ScratchDir() : path_(fs::temp_directory_path() / ("chimera_plugins_" + std::to_string(::getpid()))) {
    fs::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  [[nodiscard]] std::string file(const std::string& name, const std::string& text) const {
    const std::string p = (path_ / name).string();
    std::ofstream(p) << text;
    return p;
  }
  [[nodiscard]] std::string path() const { return path_.string(); }

 private:
  fs::path path_;
};

TEST(ModuleSearchPath, SplitsAtColonsAndSkipsEmptyEntries) {
  ::setenv("CHIMERA_MODULE_PATH", "/a::/b/c:", 1);  // NOLINT(concurrency-mt-unsafe): one thread
  EXPECT_EQ(module_search_path(), (std::vector<std::string>{"/a", "/b/c"}));
  ::unsetenv("CHIMERA_MODULE_PATH");  // NOLINT(concurrency-mt-unsafe): one thread
  EXPECT_TRUE(module_search_path().empty());
}

TEST(FindPlugin, LooksInEachDirectoryAsWrittenAndAsLibNameSo) {
  const std::vector<std::string> path{kBad, kGood};
  auto as_written = find_plugin("libchimera_test_template.so", path, "/nowhere");
  ASSERT_TRUE(as_written.ok()) << as_written.error().message;
  EXPECT_EQ(*as_written, fs::canonical(good("libchimera_test_template.so")).string());
  auto short_name = find_plugin("chimera_test_template", path, "/nowhere");
  ASSERT_TRUE(short_name.ok()) << short_name.error().message;
  EXPECT_EQ(*short_name, *as_written);
}

TEST(FindPlugin, SaysWhereItLooked) {
  auto missing = find_plugin("libnope.so", std::vector<std::string>{"/x", "/y"}, ".");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().message, "cannot find 'libnope.so' on CHIMERA_MODULE_PATH (/x:/y)");
  auto unset = find_plugin("libnope.so", std::vector<std::string>{}, ".");
  ASSERT_FALSE(unset.ok());
  EXPECT_TRUE(contains(unset.error().message, "CHIMERA_MODULE_PATH is not set")) << unset.error().message;
}

TEST(FindPlugin, APathIsTakenFromTheBaseDirectory) {
  auto relative = find_plugin("good/libchimera_test_template.so", {}, fs::path(kGood).parent_path().string());
  ASSERT_TRUE(relative.ok()) << relative.error().message;
  EXPECT_EQ(*relative, fs::canonical(good("libchimera_test_template.so")).string());
  auto absent = find_plugin("./libnope.so", {}, "/tmp");
  ASSERT_FALSE(absent.ok());
  EXPECT_EQ(absent.error().message, "cannot find './libnope.so' (no such file: /tmp/./libnope.so)");
}

TEST(LoadPlugin, AGoodLibraryRegistersItsModulesWithTheirOrigin) {
  const std::string path = fs::canonical(good("libchimera_test_template.so")).string();
  auto loaded = load_plugin("libchimera_test_template.so", path);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  EXPECT_EQ(loaded->path, path);
  EXPECT_EQ(loaded->modules, (std::vector<std::string>{"my_module"}));
  const ModuleInfo* info = Registry::global().find("my_module");
  ASSERT_NE(info, nullptr);
  EXPECT_EQ(Registry::global().origin("my_module"), path);
  EXPECT_EQ(info->declarations(Params{}).ports().size(), 3u);
  EXPECT_NE(info->make(), nullptr);
  // Its static initializers ran once; loading it again gives the same answer, not "no modules".
  auto again = load_plugin("libchimera_test_template.so", path);
  ASSERT_TRUE(again.ok()) << again.error().message;
  EXPECT_EQ(again->modules, loaded->modules);
}

TEST(LoadPlugin, ALibraryThatIsNoLibrary) {
  const ScratchDir dir;
  const std::string junk = dir.file("libjunk.so", "this is not an ELF file\n");
  const std::string message = load_error(junk);
  EXPECT_TRUE(message.starts_with("cannot load 'libjunk.so': ")) << message;
  EXPECT_TRUE(contains(message, junk)) << "dlerror names the file: " << message;
}

TEST(LoadPlugin, AMissingSymbol) {
  const std::string message = load_error(bad("libchimera_test_undefined_symbol.so"));
  EXPECT_TRUE(message.starts_with("cannot load 'libchimera_test_undefined_symbol.so': ")) << message;
  EXPECT_TRUE(contains(message, "undefined symbol")) << message;
  EXPECT_EQ(Registry::global().find("test_flawed"), nullptr);
}

TEST(LoadPlugin, ALibraryWithoutModules) {
  const std::string message = load_error(bad("libchimera_test_no_modules.so"));
  EXPECT_TRUE(contains(message, "registers no modules")) << message;
  EXPECT_TRUE(contains(message, "CHIMERA_REGISTER_MODULE")) << message;
}

TEST(LoadPlugin, APortWithABadName) {
  const std::string message = load_error(bad("libchimera_test_bad_name.so"));
  EXPECT_TRUE(contains(message, "module test_flawed: port 'theta d' is not a valid name")) << message;
  EXPECT_EQ(Registry::global().find("test_flawed"), nullptr) << "a refused library leaves no module behind";
}

TEST(LoadPlugin, APortSizedByAConstPortItLacks) {
  const std::string message = load_error(bad("libchimera_test_bad_size.so"));
  EXPECT_TRUE(contains(message,
                       "module test_flawed: port theta_d is sized by ndof, which is not one of the "
                       "module's f64 const ports"))
      << message;
}

TEST(LoadPlugin, ADeclareThatThrows) {
  const std::string message = load_error(bad("libchimera_test_throwing_declare.so"));
  EXPECT_TRUE(contains(message, "module test_flawed: declare() threw: no ports today")) << message;
}

TEST(LoadPlugin, AModuleNameTakenAlready) {
  ASSERT_TRUE(load_plugin("scale", good("libchimera_test_template.so")).ok());
  const std::string message = load_error(bad("libchimera_test_duplicate.so"));
  EXPECT_TRUE(contains(message, "module 'my_module' is registered twice (the first comes from " +
                                    fs::canonical(good("libchimera_test_template.so")).string() + ")"))
      << message;
  EXPECT_EQ(Registry::global().find("test_companion"), nullptr) << "its other module left with it";
  EXPECT_EQ(Registry::global().origin("my_module"), fs::canonical(good("libchimera_test_template.so")).string());
}

TEST(LoadPlugin, ACModuleOfAnotherAbi) {
  const std::string message = load_error(bad("libchimera_test_c_other_abi.so"));
  EXPECT_TRUE(contains(message, "a C module was built for C ABI version 43, but this chimera has version 2"))
      << message;
}

TEST(LoadPlugin, ACModuleWhoseStructHasAnotherShapeIsRefusedByItsFields) {
  // Today's version and size, but no state_size: every later field is one place off. Nothing of
  // it may be called; the message names the field that gave it away.
  const std::string message = load_error(bad("libchimera_test_c_lacks_state_size.so"));
  EXPECT_TRUE(contains(message, "C module 'test_c_shorter': its state_size is ")) << message;
  EXPECT_TRUE(contains(message, "built against another chimera/module/c_module.h")) << message;
  EXPECT_EQ(Registry::global().find("test_c_shorter"), nullptr);
}

TEST(LoadPlugin, ACxxModuleBuiltAgainstStaleHeadersIsRefusedBeforeAnyOfItRuns) {
  // Built against a module.hpp with one more virtual method: its vtable is not ours. The stamp
  // CHIMERA_REGISTER_MODULE put into it says so, before its add function could run.
  const std::string message = load_error(bad("libchimera_test_stale_cxx.so"));
  EXPECT_TRUE(
      contains(message, "module my_module was built for Chimera " + std::string(kChimeraVersion) + " (module ABI "))
      << message;
  std::array<char, 128> ours{};
  std::snprintf(ours.data(), ours.size(), "but this is Chimera %s (module ABI %016llx)", kChimeraVersion,
                static_cast<unsigned long long>(kModuleAbiFingerprint));
  EXPECT_TRUE(contains(message, ours.data())) << message;
  EXPECT_TRUE(contains(message, "rebuild the library against this version")) << message;
  EXPECT_EQ(Registry::global().origin("my_module").find("stale"), std::string_view::npos);
}

TEST(PluginsOnPath, EverySharedLibraryOfEachDirectoryOnce) {
  const auto files = plugins_on_path(std::vector<std::string>{kGood, kGood, "/no/such/dir"});
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(fs::path(files[0]).filename(), "libchimera_test_c_counter.so");
  EXPECT_EQ(fs::path(files[1]).filename(), "libchimera_test_template.so");
}

TEST(LoadFilePlugins, LoadsTheListFromThePathAndBesideTheFile) {
  ::setenv("CHIMERA_MODULE_PATH", kGood.c_str(), 1);  // NOLINT(concurrency-mt-unsafe): one thread
  const ScratchDir dir;
  fs::copy_file(bad("libchimera_test_no_modules.so"), dir.path() + "/libempty.so");
  const std::string file =
      dir.file("p.yaml",
               "subsystem: p\nplugins:\n  - libchimera_test_template.so\n  - chimera_test_c_counter\n"
               "tasks:\n  - {name: a, module: my_module}\n");
  auto loaded = load_file_plugins(file);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  ASSERT_EQ(loaded->size(), 2u);
  EXPECT_EQ((*loaded)[1].modules, (std::vector<std::string>{"test_c_counter"}));

  const std::string broken = dir.file("q.yaml",
                                      "subsystem: q\nplugins:\n  - libchimera_test_template.so\n  - ./libempty.so\n"
                                      "tasks:\n  - {name: a, module: my_module}\n");
  auto refused = load_file_plugins(broken);
  ASSERT_FALSE(refused.ok());
  EXPECT_TRUE(refused.error().message.starts_with(broken + ":4: plugins[1]: './libempty.so' ("))
      << refused.error().message;
  EXPECT_TRUE(contains(refused.error().message, "registers no modules")) << refused.error().message;

  const std::string unknown = dir.file("r.yaml", "subsystem: r\nplugins: [libnope.so]\ntasks: []\n");
  auto missing = load_file_plugins(unknown);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().message,
            unknown + ":2: plugins[0]: cannot find 'libnope.so' on CHIMERA_MODULE_PATH (" + kGood + ")");
  ::unsetenv("CHIMERA_MODULE_PATH");  // NOLINT(concurrency-mt-unsafe): one thread
}

}  // namespace
}  // namespace chimera

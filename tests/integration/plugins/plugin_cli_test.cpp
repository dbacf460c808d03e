// The chimera command with module libraries: a file's plugins: list, CHIMERA_MODULE_PATH,
// `chimera modules --plugin`, and the one message (file, line, key) for a library that fails.

#include <unistd.h>

#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "run_chimera.hpp"

namespace chimera::test {
namespace {

const std::string kGood = PLUGIN_GOOD_DIR;
const std::string kBad = PLUGIN_BAD_DIR;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

class PluginCliTest : public ::testing::Test {
 protected:
  Outcome chimera(const std::string& args, const std::string& input = {}, const std::string& path = kGood) {
    return run_chimera(dir_, args, input, "CHIMERA_MODULE_PATH=" + quoted(path));
  }
  // A subsystem file in the scratch directory, named so that no other test process shares its memory.
  std::string file(const std::string& name, const std::string& body) {
    const std::string path = dir_.file(name);
    write_text(path, "subsystem: plugin_cli_" + std::to_string(::getpid()) + "\n" + body);
    return path;
  }

  TempDir dir_;
};

// NOLINTNEXTLINE(cppcoreguidelines-macro-usage): gtest reports the caller's line only from a macro
#define EXPECT_EXIT_CODE(outcome, code) \
  EXPECT_EQ((outcome).exit_code, code) << "stdout:\n" << (outcome).out << "stderr:\n" << (outcome).err

constexpr const char* kTwoPlugins =
    "plugins: [libchimera_test_template.so, chimera_test_c_counter]\n"
    "constants: { ndof: 2, u: [1, 2], tick: [0] }\n"
    "tasks:\n"
    "  - { name: scale, module: my_module, period: 10ms }\n"
    "  - { name: counter, module: test_c_counter, period: 10ms, rename: { u: tick } }\n";

TEST_F(PluginCliTest, RunsModulesOfLibrariesNamedInTheFile) {
  const std::string f = file("two.yaml", kTwoPlugins);
  const auto verify = chimera("verify " + quoted(f));
  EXPECT_EXIT_CODE(verify, 0);
  const auto run = chimera("run " + quoted(f) + " --clock virtual --for 1s", "wait 95ms\nget y\nget count\nquit\n");
  EXPECT_EXIT_CODE(run, 0);
  EXPECT_TRUE(contains(run.out, "y = [2, 4]")) << run.out;
  EXPECT_TRUE(contains(run.out, "count = [10]")) << run.out;
}

TEST_F(PluginCliTest, WithoutTheLibraryTheModuleIsUnknown) {
  const std::string f = file("none.yaml", "tasks:\n  - { name: scale, module: my_module, period: 10ms }\n");
  const auto o = chimera("verify " + quoted(f));
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "tasks[0].module: no module named my_module")) << o.err;
}

TEST_F(PluginCliTest, ALibraryThatDoesNotLoadIsOneMessageWithFileLineAndKey) {
  write_text(dir_.file("libjunk.so"), "not a library\n");
  const std::string f = file("junk.yaml", "plugins:\n  - libchimera_test_template.so\n  - ./libjunk.so\ntasks: []\n");
  const auto o = chimera("run " + quoted(f) + " --clock virtual --for 1s");
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(o.err.starts_with(f + ":4: plugins[1]: cannot load './libjunk.so': ")) << o.err;
  EXPECT_EQ(o.err.find('\n'), o.err.size() - 1) << "one line: " << o.err;
  EXPECT_EQ(o.out, "");
}

TEST_F(PluginCliTest, ALibraryNotOnThePathSaysWhereItLooked) {
  const std::string f = file("missing.yaml", "plugins: [libnope.so]\ntasks: []\n");
  const auto o = chimera("verify " + quoted(f));
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_EQ(o.err, f + ":2: plugins[0]: cannot find 'libnope.so' on CHIMERA_MODULE_PATH (" + kGood + ")\n");
}

TEST_F(PluginCliTest, AModuleThatDeclaresPortsBadlyIsRefusedWithItsFlaw) {
  const std::string f = file("ports.yaml", "plugins: [libchimera_test_bad_name.so]\ntasks: []\n");
  const auto o = chimera("verify " + quoted(f), {}, kBad);
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(o.err.starts_with(f + ":2: plugins[0]: 'libchimera_test_bad_name.so' (")) << o.err;
  EXPECT_TRUE(contains(o.err, "module test_flawed: port 'theta d' is not a valid name")) << o.err;
}

TEST_F(PluginCliTest, ALibraryBuiltForAnotherAbiIsOneMessageAndExit2NotACrash) {
  // A C++ library built against a stale module.hpp, and a C library whose struct lacks a field:
  // both loaded, verified and then crashed before; now they are refused at load, naming why.
  const std::vector<std::pair<std::string, std::string>> cases{
      {"libchimera_test_stale_cxx.so", "rebuild the library against this version"},
      {"libchimera_test_c_lacks_state_size.so", "its state_size is "}};
  for (const auto& [lib, why] : cases) {
    const std::string f = file("stale.yaml", "plugins: [" + lib + "]\ntasks: []\n");
    for (const char* command : {"verify ", "run "}) {
      const auto o = chimera(command + quoted(f) + (command[0] == 'r' ? " --clock virtual --for 10ms" : ""), {}, kBad);
      EXPECT_EXIT_CODE(o, 2);
      EXPECT_TRUE(o.err.starts_with(f + ":2: plugins[0]: '" + lib + "' (")) << o.err;
      EXPECT_TRUE(contains(o.err, why)) << o.err;
      EXPECT_EQ(o.err.find('\n'), o.err.size() - 1) << "one line: " << o.err;
    }
  }
}

TEST_F(PluginCliTest, ModulesListsWhatThePathOffersWithTheLibrary) {
  const auto o = chimera("modules");
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(contains(o.out, "library")) << o.out;
  for (const char* line : {"my_module ", "test_c_counter "}) EXPECT_TRUE(contains(o.out, line)) << o.out;
  EXPECT_TRUE(contains(o.out, kGood + "/libchimera_test_template.so")) << o.out;
  EXPECT_TRUE(contains(o.out, "(built in)")) << o.out;

  const auto one = chimera("modules test_c_counter");
  EXPECT_EXIT_CODE(one, 0);
  EXPECT_TRUE(contains(one.out, "test_c_counter: counts cycles (test plugin in C)")) << one.out;
  EXPECT_TRUE(contains(one.out, "library: " + kGood + "/libchimera_test_c_counter.so")) << one.out;
  EXPECT_TRUE(contains(one.out, "resource: nothing (a test)")) << one.out;
}

TEST_F(PluginCliTest, ModulesLoadsAPluginGivenOnTheCommandLine) {
  const auto o = chimera("modules my_module --plugin " + quoted(kGood + "/libchimera_test_template.so"), {}, "");
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(contains(o.out, "my_module: y = k u, channel by channel")) << o.out;

  const auto refused = chimera("modules --plugin " + quoted(kBad + "/libchimera_test_no_modules.so"), {}, "");
  EXPECT_EXIT_CODE(refused, 2);
  EXPECT_TRUE(refused.err.starts_with("--plugin: ")) << refused.err;
  EXPECT_TRUE(contains(refused.err, "registers no modules")) << refused.err;
}

TEST_F(PluginCliTest, ModulesReportsABrokenLibraryOnThePath) {
  const auto o = chimera("modules", {}, kGood + ":" + kBad);
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(o.err.starts_with("CHIMERA_MODULE_PATH: ")) << o.err;
}

}  // namespace
}  // namespace chimera::test

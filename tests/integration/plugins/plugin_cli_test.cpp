// The chimera command with module libraries: a file's plugins: list, CHIMERA_MODULE_PATH,
// `chimera modules --plugin`, and the one message (file, line, key) for a library that fails.

#include <unistd.h>

#include <filesystem>
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
      {"libchimera_test_c_other_abi.so", "a C module was built for C ABI version 43"},
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

TEST_F(PluginCliTest, ModulesListsWhatLoadsAndNamesEachBrokenLibraryOnThePath) {
  // bad/ holds a library of every flaw: none may hide the built-in modules or the good libraries.
  const auto o = chimera("modules", {}, kGood + ":" + kBad);
  EXPECT_EXIT_CODE(o, 2);  // the answer is not whole, and says so
  for (const char* line : {"pid_joint ", "data_logger ", "my_module ", "test_c_counter "})
    EXPECT_TRUE(contains(o.out, line)) << line << "\n" << o.out;
  EXPECT_TRUE(contains(o.out, kGood + "/libchimera_test_template.so")) << o.out;
  // What a refused library brought leaves with it.
  EXPECT_FALSE(contains(o.out, "test_companion")) << o.out;
  EXPECT_FALSE(contains(o.out, "test_flawed")) << o.out;
  // One line each, naming the library and its flaw, then a closing line with the count.
  const std::vector<std::pair<std::string, std::string>> named{
      {"libchimera_test_no_modules.so", "registers no modules"},
      {"libchimera_test_undefined_symbol.so", "cannot load 'libchimera_test_undefined_symbol.so': "},
      {"libchimera_test_duplicate.so", "module 'my_module' is registered twice (the first comes from " + kGood},
      {"libchimera_test_c_other_abi.so", "a C module was built for C ABI version 43"},
      {"libchimera_test_bad_name.so", "port 'theta d' is not a valid name"},
  };
  for (const auto& [lib, why] : named) {
    const auto at = o.err.find("CHIMERA_MODULE_PATH: '" + lib + "' (" + kBad + "/" + lib + "): ");
    const auto line = at == std::string::npos ? o.err.find("CHIMERA_MODULE_PATH: cannot load '" + lib + "'") : at;
    ASSERT_NE(line, std::string::npos) << lib << "\n" << o.err;
    EXPECT_TRUE(contains(o.err.substr(line, o.err.find('\n', line) - line), why)) << lib << "\n" << o.err;
  }
  std::size_t lines = 0;
  for (char c : o.err) lines += c == '\n' ? 1 : 0;
  const std::string last = o.err.substr(o.err.rfind('\n', o.err.size() - 2) + 1);
  EXPECT_EQ(last, "chimera modules: " + std::to_string(lines - 1) +
                      " module libraries did not load (named above); their modules are missing from what is shown\n")
      << o.err;

  // One module of a good library: shown, with the broken ones named all the same.
  const auto one = chimera("modules my_module", {}, kGood + ":" + kBad);
  EXPECT_EXIT_CODE(one, 2);
  EXPECT_TRUE(contains(one.out, "my_module: y = k u, channel by channel")) << one.out;
  EXPECT_TRUE(contains(one.err, "libchimera_test_no_modules.so")) << one.err;
}

TEST_F(PluginCliTest, ADuplicateLibraryOnThePathIsNamedAndTheFirstCopyListed) {
  const std::string copies = dir_.file("copies");
  std::filesystem::create_directories(copies);
  std::filesystem::copy_file(kGood + "/libchimera_test_template.so", copies + "/libchimera_test_template.so");
  const auto o = chimera("modules", {}, kGood + ":" + copies);
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.out, kGood + "/libchimera_test_template.so")) << o.out;
  EXPECT_TRUE(contains(o.out, "test_c_counter ")) << o.out;
  EXPECT_TRUE(o.err.starts_with("CHIMERA_MODULE_PATH: 'libchimera_test_template.so' (" + copies +
                                "/libchimera_test_template.so): module 'my_module' is registered twice (the first "
                                "comes from " +
                                kGood + "/libchimera_test_template.so)\n"))
      << o.err;
}

TEST_F(PluginCliTest, ABrokenLibraryOnThePathDoesNotStopAFileThatDoesNotUseIt) {
  // Run and verify load only the libraries the file names: a broken one elsewhere on the path is
  // not theirs to refuse.
  const std::string f = file("good.yaml", kTwoPlugins);
  const std::string path = kBad + ":" + kGood;
  EXPECT_EXIT_CODE(chimera("verify " + quoted(f), {}, path), 0);
  const auto run = chimera("run " + quoted(f) + " --clock virtual --for 100ms", "get count\n", path);
  EXPECT_EXIT_CODE(run, 0);
  EXPECT_TRUE(contains(run.out, "count = [")) << run.out;
  // A file that names a broken library is refused, naming the file, line, key and library.
  const std::string g =
      file("bad.yaml", "plugins: [libchimera_test_template.so, libchimera_test_no_modules.so]\ntasks: []\n");
  const auto refused = chimera("verify " + quoted(g), {}, path);
  EXPECT_EXIT_CODE(refused, 2);
  EXPECT_TRUE(refused.err.starts_with(g + ":2: plugins[1]: 'libchimera_test_no_modules.so' (" + kBad +
                                      "/libchimera_test_no_modules.so): registers no modules"))
      << refused.err;
}

// A hard task (the C counter, failing at its third cycle) in a scripted run: its events on stderr
// and never among the replies, status telling its past error from its present state, and the
// run's exit 1 explained in its last line.
TEST_F(PluginCliTest, EventsGoToStderrStatusTellsAPastErrorAndExit1SaysWhy) {
  const std::string f = file("failing.yaml",
                             "plugins: [chimera_test_c_counter]\n"
                             "constants: { tick: [0] }\n"
                             "tasks:\n"
                             "  - name: counter\n"
                             "    module: test_c_counter\n"
                             "    period: 10ms\n"
                             "    rename: { u: tick }\n"
                             "    params: { fail_at: 3 }\n");
  const auto o = chimera("run " + quoted(f) + " --clock virtual --for 1s",
                         "wait 50ms\nstatus\nclear counter\non counter\nstatus\nquit\n");
  EXPECT_EXIT_CODE(o, 1);
  // The events: on stderr, not among the replies.
  EXPECT_TRUE(contains(o.err, "counter: cycle failed: counter failed on purpose\n")) << o.err;
  EXPECT_TRUE(contains(o.err, "counter: ERROR: operator intervention required (clear): counter failed on purpose\n"))
      << o.err;
  EXPECT_FALSE(contains(o.out, "counter: cycle failed")) << o.out;
  // The replies: the first status shows the error as the task's state, the second (after clear
  // and on) shows the task ON and the error as past, cleared at 50 ms.
  const auto first = o.out.find("last error");
  ASSERT_NE(first, std::string::npos) << o.out;
  const auto second = o.out.find("last error", first + 1);
  ASSERT_NE(second, std::string::npos) << o.out;
  const std::string before = o.out.substr(first, second - first);
  const std::string after = o.out.substr(second);
  EXPECT_TRUE(contains(before, " ERROR ")) << before;
  EXPECT_TRUE(contains(before, "  ERROR: operator intervention required (clear): counter failed on purpose\n"))
      << before;
  EXPECT_TRUE(contains(after, " ON ")) << after;
  EXPECT_TRUE(contains(after,
                       "cleared at 0.050 s, was: ERROR: operator intervention required (clear): counter failed on "
                       "purpose\n"))
      << after;
  EXPECT_TRUE(contains(o.out, "counter: OFF\ncounter: ON\n")) << o.out;
  // The last line of the run says why it exits 1.
  const std::string last = o.err.substr(o.err.rfind('\n', o.err.size() - 2) + 1);
  EXPECT_EQ(last,
            "chimera: exit 1: hard task counter entered ERROR (ERROR: operator intervention required (clear): counter "
            "failed on purpose)\n")
      << o.err;
}

}  // namespace
}  // namespace chimera::test

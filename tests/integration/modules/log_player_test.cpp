// log_player: a log's rows published at their times on the virtual clock, its `nan` cells leaving
// an element as it was, the `from` shift, and every refusal naming the file and the line.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "module_harness.hpp"

namespace chimera::test {
namespace {

// A log in the temporary folder, unique to this process and `tag`.
std::string write_log(const std::string& tag, const std::string& text) {
  const auto path =
      std::filesystem::temp_directory_path() / ("log_player_" + std::to_string(::getpid()) + "_" + tag + ".csv");
  std::ofstream(path) << text;
  return path.string();
}

// joint_lowpass gives u its size (ndof = 2); a cutoff far above the rate makes y follow u within 1e-9.
std::string player_file(const std::string& log, double from = 0) {
  return "subsystem: play_test\nconstants: { ndof: [2] }\ntasks:\n"
         "  - { name: play, module: log_player, period: 1ms, criticality: soft, params: { file: \"" +
         log + "\", variables: [u], from: " + std::to_string(from) +
         " } }\n"
         "  - { name: filter, module: joint_lowpass, period: 1ms, criticality: soft, params: { cutoff_hz: 1e6 } }\n";
}

constexpr const char* kLog = "t,other[0],u[0],u[1]\n0,9,1,2\n0.0025,9,3,nan\n0.004,9,5,6\n";

TEST(LogPlayer, PlaysEachRowWhenItsTimeComesAndHoldsTheLast) {
  auto sub = start_subsystem(player_file(write_log("rows", kLog)));
  ASSERT_NE(sub, nullptr);
  sub->run_for(kMs / 2);  // the release at 0 ran: the row of t = 0
  EXPECT_EQ(value_of(*sub, "u"), (std::vector<double>{1, 2}));
  sub->run_for(2 * kMs);  // releases at 1 and 2 ms: no new row came due
  EXPECT_EQ(value_of(*sub, "u"), (std::vector<double>{1, 2}));
  sub->run_for(kMs);  // 3 ms: the row of 2.5 ms, whose nan leaves u[1] as it was
  EXPECT_EQ(value_of(*sub, "u"), (std::vector<double>{3, 2}));
  sub->run_for(kMs);  // 4 ms: the last row
  EXPECT_EQ(value_of(*sub, "u"), (std::vector<double>{5, 6}));
  sub->run_for(20 * kMs);
  EXPECT_EQ(value_of(*sub, "u"), (std::vector<double>{5, 6})) << "the last row holds";
  const auto y = value_of(*sub, "y");
  ASSERT_EQ(y.size(), 2U);
  EXPECT_NEAR(y[0], 5, 1e-9) << "a module reads the played values as any producer's";
}

TEST(LogPlayer, FromShiftsTheLogAgainstTheSubsystemsClock) {
  auto sub = start_subsystem(player_file(write_log("from", kLog), 0.0025));
  ASSERT_NE(sub, nullptr);
  sub->run_for(kMs / 2);  // the release at 0 plays the log's 2.5 ms
  EXPECT_EQ(value_of(*sub, "u"), (std::vector<double>{3, 0})) << "u[1]'s nan: never written, so 0";
  sub->run_for(2 * kMs);  // 2 ms + 2.5 ms: the row of 4 ms
  EXPECT_EQ(value_of(*sub, "u"), (std::vector<double>{5, 6}));
}

TEST(LogPlayer, RefusesWhatIsNotAPlayableLogNamingTheFileAndLine) {
  const std::string missing_column = write_log("column", "t,u[0]\n0,1\n");
  EXPECT_NE(start_error(player_file(missing_column)).find(missing_column + ":1: no column u[1]"), std::string::npos)
      << start_error(player_file(missing_column));
  const std::string bad_cell = write_log("cell", "t,u[0],u[1]\n0,1,2\n0.001,x,2\n");
  EXPECT_NE(start_error(player_file(bad_cell)).find(bad_cell + ":3: 'x' in column u[0] is not a number"),
            std::string::npos)
      << start_error(player_file(bad_cell));
  const std::string backwards = write_log("back", "t,u[0],u[1]\n0.002,1,2\n0.001,1,2\n");
  EXPECT_NE(start_error(player_file(backwards)).find(backwards + ":3: t is"), std::string::npos);
  const std::string not_a_log = write_log("header", "time,u[0],u[1]\n");
  EXPECT_NE(start_error(player_file(not_a_log)).find(":1: the first column is not t"), std::string::npos);
  EXPECT_NE(start_error(player_file("/nonexistent/log.csv")).find("/nonexistent/log.csv: cannot read the log"),
            std::string::npos);
  for (const auto* tag : {"column", "cell", "back", "header"})
    std::filesystem::remove(std::filesystem::temp_directory_path() /
                            ("log_player_" + std::to_string(::getpid()) + "_" + tag + ".csv"));
}

}  // namespace
}  // namespace chimera::test

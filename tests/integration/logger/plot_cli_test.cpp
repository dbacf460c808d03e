// chimera plot: a data_logger log drawn as a PNG, a log that is no log refused with its file and
// line, and the demo's path (a logged run of the Figure 4 example, then its plot).

#include <unistd.h>

#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "run_chimera.hpp"

namespace chimera::test {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

bool is_png(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string magic(8, '\0');
  in.read(magic.data(), 8);
  return in && magic == "\x89PNG\r\n\x1a\n";
}

// NOLINTNEXTLINE(cppcoreguidelines-macro-usage): gtest reports the caller's line only from a macro
#define EXPECT_EXIT_CODE(outcome, code) \
  EXPECT_EQ((outcome).exit_code, code) << "stdout:\n" << (outcome).out << "stderr:\n" << (outcome).err

class PlotCliTest : public ::testing::Test {
 protected:
  std::string log(const std::string& name, const std::string& text) {
    const std::string path = dir_.file(name);
    write_text(path, text);
    return path;
  }
  TempDir dir_;
};

constexpr const char* kLog =
    "t,theta_d[0],theta_d[1],theta_m[0],theta_m[1],count\n"
    "0,0,0,0.1,0,1\n"
    "0.01,0.1,0.2,0.15,0.1,2\n"
    "0.02,0.2,0.4,0.2,0.3,3\n";

TEST_F(PlotCliTest, DrawsALog) {
  const std::string csv = log("run.csv", kLog);
  const auto o = run_chimera(dir_, "plot " + quoted(csv) + " -o " + quoted(dir_.file("run.png")));
  EXPECT_EXIT_CODE(o, 0);
  EXPECT_TRUE(is_png(dir_.file("run.png")));
  // Without -o the picture takes the log's name; --vars picks variables.
  const auto chosen = run_chimera(dir_, "plot " + quoted(csv) + " --vars count --title 'a title'");
  EXPECT_EXIT_CODE(chosen, 0);
  EXPECT_TRUE(contains(chosen.out, dir_.file("run.png"))) << chosen.out;
}

TEST_F(PlotCliTest, ALogThatIsNoLogIsOneMessageWithItsLine) {
  const std::string ragged = log("ragged.csv", "t,x\n0,1\n0.1\n");
  auto o = run_chimera(dir_, "plot " + quoted(ragged));
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_EQ(o.err, "chimera plot: " + ragged + ":3: 1 values, but the header has 2 columns\n");

  const std::string text = log("text.csv", "t,x\n0,one\n");
  o = run_chimera(dir_, "plot " + quoted(text));
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_EQ(o.err, "chimera plot: " + text + ":2: column x: 'one' is not a number\n");

  const std::string other = log("other.csv", "time,x\n0,1\n");
  o = run_chimera(dir_, "plot " + quoted(other));
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, other + ":1: the first column is 'time', not t")) << o.err;

  o = run_chimera(dir_, "plot " + quoted(dir_.file("none.csv")));
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "none.csv: cannot open the file")) << o.err;

  o = run_chimera(dir_, "plot " + quoted(log("run.csv", kLog)) + " --vars nosuch");
  EXPECT_EXIT_CODE(o, 2);
  EXPECT_TRUE(contains(o.err, "no variable 'nosuch' in the log (variables: theta_d, theta_m, count)")) << o.err;
}

TEST_F(PlotCliTest, TheDemosPathALoggedRunOfFigure4ThenItsPlot) {
  // The example's logger writes fig4.csv below CHIMERA_LOG_DIR; a copy of the example gets a
  // subsystem name of its own (a running subsystem owns the shared memory of its name).
  std::ifstream in(std::string(CHIMERA_EXAMPLES_DIR) + "/fig4_pid_joint.yaml");
  std::string file;
  for (std::string line; std::getline(in, line);)
    file += (line.rfind("subsystem:", 0) == 0 ? "subsystem: plot_fig4_" + std::to_string(::getpid()) : line) + "\n";
  const std::string yaml = dir_.file("fig4.yaml");
  write_text(yaml, file);
  const auto run = run_chimera(dir_, "run " + quoted(yaml) + " --clock virtual --for 2s", "",
                               "CHIMERA_LOG_DIR=" + quoted(dir_.path()));
  EXPECT_EXIT_CODE(run, 0);
  std::ifstream csv(dir_.file("fig4.csv"));
  std::string header;
  std::getline(csv, header);
  EXPECT_TRUE(header.starts_with("t,theta_d[0],")) << header;
  std::size_t rows = 0;
  for (std::string line; std::getline(csv, line);) ++rows;
  EXPECT_EQ(rows, 2000u) << "2 s of the logger's 1 ms cycles";
  const auto plot = run_chimera(dir_, "plot " + quoted(dir_.file("fig4.csv")) + " --vars theta_d,theta_m");
  EXPECT_EXIT_CODE(plot, 0);
  EXPECT_TRUE(is_png(dir_.file("fig4.png")));
}

}  // namespace
}  // namespace chimera::test

#include "chimera/control/control.hpp"

#include <unistd.h>

#include <map>
#include <memory>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "chimera/control/subsystem.hpp"
#include "unit/control/test_modules.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;

TaskSpec task(std::string name, std::string module, std::int64_t period_ns,
              Criticality criticality = Criticality::kHard) {
  TaskSpec t;
  t.name = std::move(name);
  t.module = std::move(module);
  t.period_ns = period_ns;
  t.deadline_ns = period_ns;
  t.criticality = criticality;
  t.loc = {"control_test.yaml", 1};
  return t;
}

std::vector<std::string> words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

// counter -> doubler, a faulty task beside them, and a spare counter outside the start
// configuration (so it begins NOT-CREATED).
SubsystemSpec make_spec() {
  SubsystemSpec s;
  s.name = "control_test";
  s.file = "control_test.yaml";
  s.tasks.push_back(task("counter", "test_counter", 1 * kMs));
  s.tasks.push_back(task("doubler", "test_doubler", 1 * kMs));
  s.tasks.push_back(task("faulty", "test_faulty", 1 * kMs, Criticality::kSoft));
  auto spare = task("spare", "test_counter", 2 * kMs);
  spare.rename["count"] = "spare_count";
  s.tasks.push_back(spare);
  s.configurations.push_back({"main", {"counter", "doubler", "faulty"}, {"control_test.yaml", 1}});
  s.start = "main";
  return s;
}

class ControlTest : public ::testing::Test {
 protected:
  void SetUp() override {
    test::Faulty::fail = false;
    static int instance = 0;
    RunOptions options;
    options.clock = ClockKind::kVirtual;
    // Tests run in parallel processes; each needs its own shared memory name.
    options.shm_suffix = fmt::format(".{}.{}", ::getpid(), instance++);
    auto created = Subsystem::create(make_spec(), test::test_registry(), options);
    ASSERT_TRUE(created.ok()) << created.error().message;
    subsystem_ = std::move(*created);
    auto started = subsystem_->start();
    ASSERT_TRUE(started.ok()) << started.error().message;
    control_ = std::make_unique<Control>(*subsystem_);
  }
  void TearDown() override {
    control_.reset();
    if (subsystem_) subsystem_->stop();
    test::Faulty::fail = false;
  }

  Reply run(std::string_view line) { return control_->execute_line(line); }

  TaskState state_of(std::string_view name) const {
    for (const auto& t : subsystem_->snapshot())
      if (t.name == name) return t.state;
    ADD_FAILURE() << "no task " << name;
    return TaskState::kNotCreated;
  }

  // The status table's row for `name`, split into words.
  std::vector<std::string> status_row(std::string_view name) {
    const Reply r = run("status");
    std::istringstream lines(r.text);
    std::string line;
    while (std::getline(lines, line)) {
      std::vector<std::string> row = words(line);
      if (!row.empty() && row.front() == name) return row;
    }
    ADD_FAILURE() << "no row for " << name << " in\n" << r.text;
    return {};
  }

  std::unique_ptr<Subsystem> subsystem_;
  std::unique_ptr<Control> control_;
};

TEST_F(ControlTest, StatusIsATableOfEveryTask) {
  subsystem_->run_for(10 * kMs);
  const Reply r = run("status");
  ASSERT_TRUE(r.ok) << r.text;
  EXPECT_EQ(r.text.rfind("task", 0), 0U) << r.text;
  for (const char* header : {"module", "state", "period", "cycles", "missed"})
    EXPECT_NE(r.text.find(header), std::string::npos) << header;
  // task module state cpu period(2 words) cycles missed; the cpu is the plan's assignment
  std::map<std::string, std::string> cpu;
  for (const auto& t : subsystem_->snapshot()) cpu[t.name] = std::to_string(t.cpu);
  EXPECT_EQ(status_row("counter"),
            (std::vector<std::string>{"counter", "test_counter", "ON", cpu["counter"], "1", "ms", "10", "0"}));
  EXPECT_EQ(status_row("spare"),
            (std::vector<std::string>{"spare", "test_counter", "NOT-CREATED", cpu["spare"], "2", "ms", "0", "0"}));
}

// The imports other subsystems feed (the DDS bridge's report) are a second table of `status`: one
// row each, fresh or STALE, whom from, and the last remote refused. Without a report there is none.
TEST_F(ControlTest, StatusShowsTheImportsTheBridgeReports) {
  EXPECT_EQ(run("status").text.find("import"), std::string::npos);
  RemoteImport fed{"x_d", "vision", 120, 0, 2 * kMs, 50 * kMs, false, ""};
  RemoteImport refused{"x_m", "", 0, 3, -1, 50 * kMs, true, "import x_m: a remote of another size"};
  int asked = 0;
  subsystem_->report_remote_imports([&] {
    ++asked;
    return std::vector<RemoteImport>{fed, refused};
  });
  const Reply r = run("status");
  ASSERT_TRUE(r.ok) << r.text;
  EXPECT_EQ(asked, 1);
  const auto table = r.text.find("\nimport ");
  ASSERT_NE(table, std::string::npos) << r.text;
  std::istringstream lines(r.text.substr(table + 1));
  std::string header;
  std::getline(lines, header);
  for (const char* column : {"state", "from", "samples", "refused", "age", "max_age", "refused from"})
    EXPECT_NE(header.find(column), std::string::npos) << column;
  std::string row;
  std::getline(lines, row);
  EXPECT_EQ(words(row), (std::vector<std::string>{"x_d", "fresh", "vision", "120", "0", "2.00", "ms", "50.00", "ms"}));
  std::getline(lines, row);
  EXPECT_EQ(words(row), (std::vector<std::string>{"x_m", "STALE", "-", "0", "3", "-", "50.00", "ms", "import",
                                                  "x_m:", "a", "remote", "of", "another", "size"}));
  subsystem_->report_remote_imports({});
  EXPECT_EQ(run("status").text.find("import"), std::string::npos);
}

TEST_F(ControlTest, SignalsAreReflectedInStatus) {
  Reply r = run("off doubler");
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.text, "doubler: OFF\n");
  EXPECT_EQ(status_row("doubler").at(2), "OFF");

  EXPECT_EQ(run("spawn spare").text, "spare: OFF\n");
  EXPECT_EQ(run("on spare doubler").text, "spare: ON\ndoubler: ON\n");
  EXPECT_EQ(status_row("spare").at(2), "ON");
  subsystem_->run_for(10 * kMs);
  EXPECT_EQ(status_row("spare").at(6), "5");  // 2 ms period

  EXPECT_EQ(run("kill spare").text, "spare: NOT-CREATED\n");
  EXPECT_EQ(status_row("spare").at(2), "NOT-CREATED");
  EXPECT_EQ(run("off counter doubler").text, "counter: OFF\ndoubler: OFF\n");
  EXPECT_EQ(run("kill counter").text, "counter: NOT-CREATED\n");
  EXPECT_EQ(state_of("counter"), TaskState::kNotCreated);
}

TEST_F(ControlTest, UnknownTaskChangesNothing) {
  const Reply r = run("off counter nosuch doubler");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.text, "unknown task 'nosuch'\n");
  EXPECT_EQ(state_of("counter"), TaskState::kOn);
  EXPECT_EQ(state_of("doubler"), TaskState::kOn);

  // An unknown name is reported before a task in the wrong state.
  EXPECT_EQ(run("on counter nosuch").text, "unknown task 'nosuch'\n");
  EXPECT_FALSE(run("spawn nosuch").ok);
  EXPECT_FALSE(run("kill nosuch").ok);
  EXPECT_FALSE(run("clear nosuch").ok);
}

TEST_F(ControlTest, SignalNotAllowedInSomeStateChangesNothing) {
  // spare is NOT-CREATED, so `off` cannot reach it; counter must stay ON.
  const Reply r = run("off counter spare");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.text, "off spare: task is NOT-CREATED, off needs ON\n");
  EXPECT_EQ(state_of("counter"), TaskState::kOn);

  EXPECT_EQ(run("on counter").text, "on counter: task is ON, on needs OFF\n");
  EXPECT_EQ(run("spawn counter").text, "spawn counter: task is ON, spawn needs NOT-CREATED\n");
  EXPECT_EQ(run("kill spare").text, "kill spare: task is NOT-CREATED, kill needs OFF, ON or ERROR\n");
  EXPECT_EQ(run("clear counter").text, "clear counter: task is ON, clear needs ERROR\n");
  EXPECT_EQ(state_of("spare"), TaskState::kNotCreated);
}

TEST_F(ControlTest, NameListedTwiceIsSignalledOnce) {
  const Reply r = run("off counter counter");
  EXPECT_TRUE(r.ok) << r.text;
  EXPECT_EQ(r.text, "counter: OFF\n");
}

TEST_F(ControlTest, SetRefusedForAVariableAnOnTaskProduces) {
  subsystem_->run_for(3 * kMs);
  const Reply r = run("set count 42");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.text.find("counter"), std::string::npos) << r.text;  // names the producer
  EXPECT_EQ(r.text.find('\n'), r.text.size() - 1) << "one line: " << r.text;
  EXPECT_EQ(run("get count").text, "count = [3]\n");
}

TEST_F(ControlTest, SetAcceptedWhenNoOnTaskProducesThenVisible) {
  ASSERT_TRUE(run("off counter").ok);
  const Reply r = run("set count 21");
  EXPECT_TRUE(r.ok) << r.text;
  EXPECT_EQ(r.text, "count = [21]\n");
  EXPECT_EQ(run("get count").text, "count = [21]\n");
  subsystem_->run_for(2 * kMs);
  EXPECT_EQ(run("get doubled").text, "doubled = [42]\n");  // the consumer saw it
}

TEST_F(ControlTest, SetAndGetRefuseUnknownVariablesAndWrongCounts) {
  ASSERT_TRUE(run("off counter").ok);
  EXPECT_FALSE(run("set count 1 2").ok);
  EXPECT_FALSE(run("set nosuch 1").ok);
  EXPECT_FALSE(run("get nosuch").ok);
}

TEST_F(ControlTest, FaultGoesToErrorAndClearBringsItBack) {
  test::Faulty::fail = true;
  subsystem_->run_for(3 * kMs);
  const std::string events = control_->drain_events();
  EXPECT_NE(events.find("faulty: ERROR"), std::string::npos) << events;
  EXPECT_EQ(control_->drain_events(), "");  // drained
  EXPECT_EQ(status_row("faulty").at(2), "ERROR");
  EXPECT_EQ(state_of("counter"), TaskState::kOn);  // the others run on
  // A task in ERROR holds the illegal-configuration flag, and status says so.
  const std::string flag_line = "illegal-configuration flag raised: the robot interfaces hold the arm\n";
  EXPECT_TRUE(run("status").text.ends_with(flag_line)) << run("status").text;

  // clear while the fault persists: refused by the module, still ERROR
  Reply r = run("clear faulty");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(state_of("faulty"), TaskState::kError);

  test::Faulty::fail = false;
  r = run("clear faulty");
  EXPECT_TRUE(r.ok) << r.text;
  EXPECT_EQ(r.text, "faulty: OFF\n");
  EXPECT_EQ(run("status").text.find("illegal-configuration flag"), std::string::npos) << run("status").text;
  EXPECT_EQ(run("on faulty").text, "faulty: ON\n");
  subsystem_->run_for(2 * kMs);
  EXPECT_EQ(run("get health").text, "health = [1]\n");
  EXPECT_FALSE(subsystem_->hard_task_failed());  // faulty is soft
}

TEST_F(ControlTest, WaitAndQuitAreLeftToTheCaller) {
  const std::int64_t before = subsystem_->now_ns();
  Reply r = run("wait 10ms");
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.wait_ns, 10 * kMs);
  EXPECT_EQ(r.text, "");
  EXPECT_EQ(subsystem_->now_ns(), before);

  r = run("quit");
  EXPECT_TRUE(r.quit);
  EXPECT_EQ(state_of("counter"), TaskState::kOn);
}

TEST_F(ControlTest, StatsIsTheTimingTable) {
  subsystem_->run_for(5 * kMs);
  const Reply r = run("stats");
  ASSERT_TRUE(r.ok);
  for (const char* header : {"exec mean", "exec max", "latency p50", "latency p99", "latency max"})
    EXPECT_NE(r.text.find(header), std::string::npos) << header;
  EXPECT_NE(r.text.find("counter"), std::string::npos);
}

TEST_F(ControlTest, StatsOfOneTaskIsItsProfile) {
  subsystem_->run_for(10 * kMs);
  const Reply r = run("stats counter");
  ASSERT_TRUE(r.ok) << r.text;
  EXPECT_EQ(r.text.rfind("counter (test_counter), ON, cpu ", 0), 0U) << r.text;
  EXPECT_NE(r.text.find("  cycles 10, missed 0, overruns 0, skipped 0"), std::string::npos) << r.text;
  EXPECT_NE(r.text.find("execution time:\n  <= "), std::string::npos) << r.text;
  // On the virtual clock execution times are simulated, and the host's are shown apart.
  EXPECT_NE(r.text.find(" (simulated time)\n  host     mean "), std::string::npos) << r.text;
  // On the virtual clock every release starts on time: one bucket, all ten cycles, a full bar.
  EXPECT_NE(r.text.find("release latency:\n  <=       0 ns        10  ########################################\n"),
            std::string::npos)
      << r.text;
  const Reply spare = run("stats spare");
  EXPECT_NE(spare.text.find("execution time:\n  (no cycles yet)\n"), std::string::npos) << spare.text;
  const Reply bad = run("stats nosuch");
  EXPECT_FALSE(bad.ok);
  EXPECT_EQ(bad.text, "unknown task 'nosuch'\n");
}

TEST_F(ControlTest, HelpUnknownAndBlankLines) {
  const Reply help = run("help");
  for (const char* verb :
       {"status", "spawn", "on", "off", "kill", "clear", "switch", "get", "set", "wait", "stats", "quit"})
    EXPECT_NE(help.text.find(verb), std::string::npos) << verb;

  const Reply unknown = run("swap other");
  EXPECT_FALSE(unknown.ok);
  EXPECT_EQ(unknown.text, "unknown command 'swap' (try help)\n");
  const Reply no_such = run("switch other");
  EXPECT_FALSE(no_such.ok);
  EXPECT_NE(no_such.text.find("no configuration named other"), std::string::npos) << no_such.text;

  const Reply blank = run("   # nothing");
  EXPECT_TRUE(blank.ok);
  EXPECT_EQ(blank.text, "");
}

}  // namespace
}  // namespace chimera

// Dynamic reconfiguration on the virtual clock (issue 4): switches back and forth without a lost
// cycle, refusals that change nothing, the illegal-configuration flag, reinit exactly when a
// constant changes value, switches around a task in ERROR, and switches that tasks ask for.

#include <string>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "support/reconfig_modules.hpp"
#include "support/run_subsystem.hpp"

namespace chimera {
namespace {

constexpr std::int64_t kMs = 1'000'000;

std::unique_ptr<Subsystem> start(const std::string& yaml) {
  return testing::start_subsystem(yaml, testing::reconfig_registry());
}

double value(Subsystem& s, const std::string& var) { return s.get(var)->at(0); }

TaskSnapshot task(Subsystem& s, const std::string& name) { return testing::task_of(s, name); }

// Two producers of one variable, one consumer that stays (the robot interface's place), and a
// watcher of the flag.
const std::string kTwoProducers = R"(subsystem: sw
tasks:
  - {name: a, module: stamper, period: 1ms}
  - {name: b, module: stamper, period: 1ms}
  - {name: robot, module: stamp_checker, period: 1ms}
  - {name: watch, module: flag_watch, period: 1ms}
  - {name: broken, module: stamp_checker, period: 1ms, rename: {stamp: nobody_writes, stale: s2, checked: c2}}
configurations:
  with_a: [a, robot, watch]
  with_b: [b, robot, watch]
  illegal: [robot, watch, broken]
)";

TEST(Switch, AThousandSwitchesBackAndForthLoseNoCycle) {
  auto s = start(kTwoProducers);
  ASSERT_TRUE(s);
  for (int i = 0; i < 1000; ++i) {
    s->run_for(3 * kMs);
    auto r = s->switch_to(i % 2 == 0 ? "with_b" : "with_a");
    ASSERT_TRUE(r.ok()) << r.error().message;
  }
  s->run_for(3 * kMs);
  // The first switch created b, which takes a cycle (the flag is up meanwhile): 1 ms more.
  const double elapsed_ms = 1000 * 3 + 3 + 1;
  EXPECT_EQ(s->now_ns(), static_cast<std::int64_t>(elapsed_ms) * kMs);
  EXPECT_EQ(value(*s, "checked"), elapsed_ms) << "the robot ran every release";
  EXPECT_EQ(task(*s, "robot").stats.cycles, static_cast<std::uint64_t>(elapsed_ms));
  EXPECT_EQ(task(*s, "robot").stats.missed, 0u);
  EXPECT_EQ(value(*s, "stale"), 0.0) << "and always read the stamp of its own release";
  EXPECT_EQ(task(*s, "a").stats.cycles + task(*s, "b").stats.cycles, static_cast<std::uint64_t>(elapsed_ms))
      << "exactly one producer ran at each release";
  EXPECT_EQ(s->switches().size(), 1000u);
  EXPECT_EQ(s->configuration(), "with_a");
}

TEST(Switch, TheFlagIsUpWhileASwitchCreatesTasks) {
  auto s = start(kTwoProducers);
  ASSERT_TRUE(s);
  s->run_for(3 * kMs);
  auto first = s->switch_to("with_b");
  ASSERT_TRUE(first.ok()) << first.error().message;
  EXPECT_TRUE(first->flag_raised);
  EXPECT_EQ(first->spawned, (std::vector<std::string>{"b"}));
  EXPECT_EQ(first->committed_ns - first->requested_ns, 1 * kMs) << "the old configuration ran one more cycle";
  EXPECT_EQ(value(*s, "flag_cycles"), 1.0) << "modules saw the flag up during that cycle";
  EXPECT_FALSE(s->illegal_configuration()) << "and lowered once committed";
  auto back = s->switch_to("with_a");
  ASSERT_TRUE(back.ok());
  EXPECT_FALSE(back->flag_raised) << "every task exists: the commit is immediate";
  EXPECT_EQ(back->committed_ns, back->requested_ns);
  s->run_for(3 * kMs);
  EXPECT_EQ(value(*s, "flag_cycles"), 1.0);
}

TEST(Switch, ARefusedSwitchChangesNothing) {
  auto s = start(kTwoProducers);
  ASSERT_TRUE(s);
  s->run_for(5 * kMs);
  const auto before = s->snapshot();
  auto unknown = s->switch_to("nowhere");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().message.find("no configuration named nowhere (configurations: with_a, with_b, illegal)"),
            std::string::npos)
      << unknown.error().message;
  auto illegal = s->switch_to("illegal");
  ASSERT_FALSE(illegal.ok());
  EXPECT_EQ(illegal.error().message,
            "switch: configuration 'illegal': rule 2: nobody_writes is consumed by broken (port stamp) but produced by "
            "no task");
  auto same = s->switch_to("with_a");
  ASSERT_FALSE(same.ok());
  EXPECT_EQ(same.error().message, "switch: configuration 'with_a' is already on");
  EXPECT_EQ(s->configuration(), "with_a");
  EXPECT_TRUE(s->switches().empty());
  const auto after = s->snapshot();
  for (std::size_t i = 0; i < before.size(); ++i) {
    EXPECT_EQ(after[i].state, before[i].state) << after[i].name;
    EXPECT_EQ(after[i].stats.cycles, before[i].stats.cycles) << after[i].name;
  }
  EXPECT_FALSE(s->illegal_configuration());
}

const std::string kTools = R"(subsystem: tools
tasks:
  - {name: short_tool, module: tool_const, period: 10ms, params: {value: 0.1}}
  - {name: long_tool, module: tool_const, period: 10ms, params: {value: 0.3}}
  - {name: same_tool, module: tool_const, period: 10ms, params: {value: 0.1}}
  - {name: user, module: tool_user, period: 1ms}
configurations:
  short: [short_tool, user]
  long: [long_tool, user]
  same: [same_tool, user]
  both: [short_tool, long_tool, user]
)";

TEST(Switch, ReinitExactlyWhenAConstantChangesValue) {
  auto s = start(kTools);
  ASSERT_TRUE(s);
  s->run_for(2 * kMs);
  EXPECT_EQ(value(*s, "tool_seen"), 0.1);
  auto to_long = s->switch_to("long");
  ASSERT_TRUE(to_long.ok()) << to_long.error().message;
  EXPECT_EQ(to_long->reinit, (std::vector<std::string>{"user"}));
  s->run_for(2 * kMs);
  EXPECT_EQ(value(*s, "reinits"), 1.0);
  EXPECT_EQ(value(*s, "tool_seen"), 0.3) << "the next cycle already used the new tool";
  auto to_short = s->switch_to("short");
  ASSERT_TRUE(to_short.ok());
  s->run_for(2 * kMs);
  EXPECT_EQ(value(*s, "reinits"), 2.0) << "the first tool came back: its value is the table's again";
  EXPECT_EQ(value(*s, "tool_seen"), 0.1);
  auto to_same = s->switch_to("same");
  ASSERT_TRUE(to_same.ok());
  EXPECT_TRUE(to_same->reinit.empty()) << "another producer of the same value: no reinit";
  s->run_for(2 * kMs);
  EXPECT_EQ(value(*s, "reinits"), 2.0);
}

TEST(Switch, TwoValuesOfOneConstantInAConfigurationAreRefused) {
  auto s = start(kTools);
  ASSERT_TRUE(s);
  auto both = s->switch_to("both");
  ASSERT_FALSE(both.ok());
  EXPECT_EQ(both.error().message, "switch: configuration 'both': rule 1: tool is produced by short_tool and long_tool");
}

const std::string kWithProbe = R"(subsystem: err
tasks:
  - {name: a, module: stamper, period: 1ms}
  - {name: b, module: stamper, period: 1ms}
  - {name: robot, module: stamp_checker, period: 1ms}
  - {name: p, module: probe, period: 1ms, params: {fail: cycle, fail_after: 2}}
configurations:
  with_a: [a, robot, p]
  with_b: [b, robot]
  with_b_and_p: [b, robot, p]
)";

TEST(Switch, AroundATaskInError) {
  auto s = start(kWithProbe);
  ASSERT_TRUE(s);
  s->run_for(5 * kMs);
  ASSERT_EQ(task(*s, "p").state, TaskState::kError);
  EXPECT_TRUE(s->illegal_configuration()) << "the flag also marks an error in the subsystem";
  auto refused = s->switch_to("with_b_and_p");
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().message, "switch to 'with_b_and_p' refused: p is in ERROR (clear it first)");
  EXPECT_EQ(s->configuration(), "with_a");
  auto done = s->switch_to("with_b");
  ASSERT_TRUE(done.ok()) << done.error().message;
  EXPECT_EQ(task(*s, "p").state, TaskState::kError) << "outside the target it stays as it is";
  EXPECT_EQ(done->off, (std::vector<std::string>{"a"}));
  s->run_for(5 * kMs);
  EXPECT_EQ(value(*s, "stale"), 0.0);
  ASSERT_TRUE(s->signal("p", Signal::kClear).ok());
  EXPECT_FALSE(s->illegal_configuration()) << "cleared: no task in ERROR, the flag is down";
}

const std::string kRequests = R"(subsystem: req
tasks:
  - {name: a, module: stamper, period: 1ms}
  - {name: b, module: stamper, period: 1ms}
  - {name: robot, module: stamp_checker, period: 1ms}
  - {name: monitor, module: asker, period: 1ms, params: {target: with_b, at: 5}}
  - {name: rogue, module: asker, period: 1ms, params: {target: with_a, at: 3}}
configurations:
  with_a: [a, robot, monitor]
  with_b: [b, robot, monitor, rogue]
requests:
  - {from: with_a, to: with_b, by: monitor}
)";

TEST(Switch, ATaskAsksAndTheFileDecides) {
  auto s = start(kRequests);
  ASSERT_TRUE(s);
  s->run_for(20 * kMs);
  const auto history = s->switches();
  ASSERT_EQ(history.size(), 1u);
  EXPECT_EQ(history[0].cause, "requested by monitor");
  EXPECT_EQ(history[0].requested_ns, 4 * kMs) << "its 5th cycle, at 4 ms, asked";
  EXPECT_EQ(history[0].committed_ns, 5 * kMs) << "b had to be created: one cycle later";
  EXPECT_EQ(s->configuration(), "with_b");
  // rogue asks for with_a from its 3rd cycle in with_b: the file allows no such request.
  std::string events;
  for (const auto& e : s->drain_events()) events += e.task + ": " + e.text + "\n";
  EXPECT_NE(events.find("rogue: asked for a switch to 'with_a' from 'with_b', which the file's requests: do not "
                        "allow; refused\n"),
            std::string::npos)
      << events;
  EXPECT_NE(events.find(": switch with_a -> with_b (requested by monitor): off a; on b, rogue; created b, rogue; "
                        "committed after 1.00 ms, illegal-configuration flag raised meanwhile\n"),
            std::string::npos)
      << events;
  EXPECT_EQ(value(*s, "stale"), 0.0);
  EXPECT_EQ(value(*s, "checked"), 20.0);
}

TEST(Switch, TheSameRunGivesTheSameSwitches) {
  auto first = start(kRequests);
  ASSERT_TRUE(first);
  first->run_for(30 * kMs);
  const auto a = first->switches();
  first->stop();
  auto second = start(kRequests);
  ASSERT_TRUE(second);
  second->run_for(30 * kMs);
  const auto b = second->switches();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].requested_ns, b[i].requested_ns);
    EXPECT_EQ(a[i].committed_ns, b[i].committed_ns);
    EXPECT_EQ(a[i].to, b[i].to);
  }
}

}  // namespace
}  // namespace chimera

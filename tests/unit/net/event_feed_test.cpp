// The feed of what happens (chimera/net/event_feed.hpp) as the streams see it, through the
// command gate on the virtual clock: state changes from commands and from a task's fault,
// switches, tasks added and removed, the subsystem's events, and the bounded history.

#include "chimera/net/event_feed.hpp"

#include <unistd.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/net/control_gate.hpp"
#include "support/json_text.hpp"
#include "unit/control/test_modules.hpp"

namespace chimera::net {
namespace {

using nlohmann::json;

constexpr std::int64_t kMs = 1'000'000;

constexpr std::string_view kFile = R"(subsystem: feed
tasks:
  - {name: counter, module: test_counter, period: 1ms}
  - {name: doubler, module: test_doubler, period: 1ms, criticality: soft}
  - {name: faulty, module: test_faulty, period: 1ms, criticality: soft}
  - {name: spare, module: test_counter, period: 2ms, rename: {count: spare_count}}
configurations:
  main: [counter, doubler, faulty]
  more: [counter, doubler, spare]
start: main
)";

class EventFeedTest : public ::testing::Test {
 protected:
  void SetUp() override {
    test::Faulty::fail = false;
    static int instance = 0;
    auto spec = load_subsystem_text(kFile, "feed.yaml", test::test_registry());
    ASSERT_TRUE(spec) << spec.error().message;
    RunOptions options;
    options.clock = ClockKind::kVirtual;
    options.shm_suffix = fmt::format(".feed.{}.{}", ::getpid(), instance++);
    auto created = Subsystem::create(*spec, test::test_registry(), options);
    ASSERT_TRUE(created) << created.error().message;
    subsystem_ = std::move(*created);
    ASSERT_TRUE(subsystem_->start());
    gate_ = std::make_unique<ControlGate>(*subsystem_);
    (void)gate_->drain_events();  // the feed's first look: nothing has changed yet
    first_ = gate_->feed().next_seq();
  }
  void TearDown() override {
    gate_.reset();
    if (subsystem_) subsystem_->stop();
    test::Faulty::fail = false;
  }

  void run(std::string_view line) {
    const Reply reply = gate_->execute_line(line);
    ASSERT_TRUE(reply.ok) << line << ": " << reply.text;
  }

  // The items from `first_` on, as JSON, checking that their numbers follow one another.
  std::vector<json> items() {
    std::vector<EventFeed::Item> got;
    EXPECT_EQ(gate_->feed().since(first_, EventFeed::kCapacity, got), 0U);
    std::vector<json> out;
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].seq, first_ + i);
      out.push_back(test::parse_json(got[i].json));
    }
    return out;
  }

  std::unique_ptr<Subsystem> subsystem_;
  std::unique_ptr<ControlGate> gate_;
  std::uint64_t first_ = 0;
};

TEST_F(EventFeedTest, StartingToWatchReportsNothing) {
  EXPECT_EQ(first_, 0U);
  gate_->run_for(10 * kMs);
  EXPECT_TRUE(items().empty());
}

TEST_F(EventFeedTest, EachCommandsStateChangesComeAfterIt) {
  run("off doubler");
  run("on doubler");
  run("kill doubler");
  const auto got = items();
  ASSERT_EQ(got.size(), 3U);
  const std::vector<std::pair<std::string, std::string>> changes = {
      {"ON", "OFF"}, {"OFF", "ON"}, {"ON", "NOT-CREATED"}};
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i]["type"], "state") << got[i];
    EXPECT_EQ(got[i]["task"], "doubler") << got[i];
    EXPECT_EQ(got[i]["from"], changes[i].first) << got[i];
    EXPECT_EQ(got[i]["to"], changes[i].second) << got[i];
  }
}

TEST_F(EventFeedTest, ASwitchComesWithItsRecordAndTheStatesItChanged) {
  gate_->run_for(5 * kMs);
  run("switch more");
  // The shell prints the switch's line; the feed has the switch once, as its record.
  EXPECT_NE(gate_->drain_events().find("switch main -> more"), std::string::npos);
  const auto got = items();
  std::vector<json> states;
  std::vector<json> switches;
  for (const auto& item : got) {
    EXPECT_NE(item["type"], "log") << item;
    (item["type"] == "switch" ? switches : states).push_back(item);
  }
  ASSERT_EQ(switches.size(), 1U) << json(got);
  EXPECT_EQ(switches[0]["from"], "main");
  EXPECT_EQ(switches[0]["to"], "more");
  EXPECT_EQ(switches[0]["cause"], "operator");
  EXPECT_EQ(switches[0]["off"], json::array({"faulty"}));
  EXPECT_EQ(switches[0]["on"], json::array({"spare"}));
  EXPECT_GE(switches[0]["committed_ns"].get<std::int64_t>(), 5 * kMs);
  // faulty ON -> OFF, spare NOT-CREATED -> ON; nothing about the tasks the switch left alone.
  ASSERT_EQ(states.size(), 2U) << json(got);
  for (const auto& s : states) {
    if (s["task"] == "faulty") {
      EXPECT_EQ(s["from"], "ON");
      EXPECT_EQ(s["to"], "OFF");
    } else {
      EXPECT_EQ(s["task"], "spare") << s;
      EXPECT_EQ(s["from"], "NOT-CREATED");
      EXPECT_EQ(s["to"], "ON");
    }
  }
}

TEST_F(EventFeedTest, AFaultIsSeenWithTheEventThatSaysWhy) {
  test::Faulty::fail = true;
  gate_->run_for(5 * kMs);  // each step looks: the state change without waiting for a command
  auto got = items();
  ASSERT_FALSE(got.empty());
  EXPECT_EQ(got[0]["type"], "state") << got[0];
  EXPECT_EQ(got[0]["task"], "faulty");
  EXPECT_EQ(got[0]["to"], "ERROR");
  EXPECT_LE(got[0]["t_ns"].get<std::int64_t>(), 5 * kMs);
  const std::string lines = gate_->drain_events();  // the shell's lines, and the same into the feed
  EXPECT_NE(lines.find("faulty"), std::string::npos) << lines;
  got = items();
  const auto log = std::find_if(got.begin(), got.end(), [](const json& j) { return j["type"] == "log"; });
  ASSERT_NE(log, got.end()) << json(got);
  EXPECT_EQ((*log)["task"], "faulty");
  EXPECT_NE(lines.find((*log)["text"].get<std::string>()), std::string::npos) << lines;
}

TEST_F(EventFeedTest, TasksAddedAndRemovedComeFromAndToNull) {
  for (const char* task : {"counter", "doubler", "faulty"})
    run(fmt::format("kill {}", task));  // add wants none created
  first_ = gate_->feed().next_seq();
  run("add {name: extra, module: test_counter, period: 1ms, rename: {count: extra_count}}");
  run("remove extra");
  const auto got = items();
  ASSERT_EQ(got.size(), 2U) << json(got);
  EXPECT_EQ(got[0]["task"], "extra");
  EXPECT_TRUE(got[0]["from"].is_null()) << got[0];
  EXPECT_EQ(got[0]["to"], "NOT-CREATED");
  EXPECT_EQ(got[1]["from"], "NOT-CREATED");
  EXPECT_TRUE(got[1]["to"].is_null()) << got[1];
}

TEST_F(EventFeedTest, AReaderTooFarBehindIsToldHowManyItMissed) {
  constexpr int kPairs = 600;  // 1,200 items: more than the history keeps
  for (int i = 0; i < kPairs; ++i) {
    run("off doubler");
    run("on doubler");
  }
  const std::uint64_t next = gate_->feed().next_seq();
  ASSERT_EQ(next, first_ + (std::uint64_t{2} * kPairs));
  std::vector<EventFeed::Item> got;
  const std::uint64_t missed = gate_->feed().since(first_, 10, got);
  EXPECT_EQ(missed, next - EventFeed::kCapacity - first_);
  ASSERT_EQ(got.size(), 10U);
  EXPECT_EQ(got[0].seq, next - EventFeed::kCapacity) << "the oldest kept comes first";
  // From the newest on: nothing missed, nothing yet.
  EXPECT_EQ(gate_->feed().since(next, 10, got), 0U);
  EXPECT_TRUE(got.empty());
}

}  // namespace
}  // namespace chimera::net

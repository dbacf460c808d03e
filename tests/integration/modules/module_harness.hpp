#pragma once
// What the tests of the paper's modules share: subsystems from YAML text on the virtual clock, a
// producer the test scripts (for inputs no module of the library would give exactly), and the
// arm's kinematics and simulation to check the modules against.

#include <unistd.h>

#include <atomic>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/control/subsystem.hpp"
#include "chimera/module/registry.hpp"

namespace chimera::test {

constexpr std::int64_t kMs = 1'000'000;

inline std::string unique_suffix() {
  static std::atomic<int> counter{0};
  return "_mod_" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
}

/// The subsystem of `text`, created on the virtual clock and started; nullptr (and a test
/// failure) if any step fails.
inline std::unique_ptr<Subsystem> start_subsystem(const std::string& text, const std::string& config = {}) {
  auto spec = load_subsystem_text(text, "test.yaml", Registry::global());
  EXPECT_TRUE(spec.ok()) << (spec.ok() ? "" : spec.error().message);
  if (!spec.ok()) return nullptr;
  RunOptions options;
  options.clock = ClockKind::kVirtual;
  options.shm_suffix = unique_suffix();
  if (!config.empty()) options.configuration = config;
  auto sub = Subsystem::create(*spec, Registry::global(), options);
  EXPECT_TRUE(sub.ok()) << (sub.ok() ? "" : sub.error().message);
  if (!sub.ok()) return nullptr;
  auto started = (*sub)->start();
  EXPECT_TRUE(started.ok()) << (started.ok() ? "" : started.error().message);
  if (!started.ok()) return nullptr;
  return std::move(sub).value();
}

/// A variable's value; an empty vector (and a test failure) if it cannot be read.
inline std::vector<double> value_of(const Subsystem& sub, const std::string& variable) {
  auto v = sub.get(variable);
  EXPECT_TRUE(v.ok()) << variable << ": " << (v.ok() ? "" : v.error().message);
  return v.ok() ? *v : std::vector<double>{};
}

/// The first init or start failure of a file, or "" if it starts.
inline std::string start_error(const std::string& text) {
  auto spec = load_subsystem_text(text, "test.yaml", Registry::global());
  if (!spec.ok()) return spec.error().message;
  RunOptions options;
  options.clock = ClockKind::kVirtual;
  options.shm_suffix = unique_suffix();
  auto sub = Subsystem::create(*spec, Registry::global(), options);
  if (!sub.ok()) return sub.error().message;
  auto started = (*sub)->start();
  return started.ok() ? std::string() : started.error().message;
}

/// `text` with its first `from` replaced by `to` (a test fixture bug if absent).
inline std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "no '" << from << "' in the test's file";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

/// A producer the test drives: at init, on and every cycle it publishes the values last given
/// to ScriptedSource::set under its task's name, on its one out-var (parameters `port`, `size`).
/// Real-time safe as long as set() is called between runs, as the virtual clock allows.
class ScriptedSource final : public Module {
 public:
  static constexpr const char* kName = "scripted_source";
  static constexpr const char* kSummary = "test producer of scripted values";
  static constexpr const char* kDoc = "publishes what the test sets";
  static void declare(Declarations& d, const Params& p) {
    d.out_var(p.text("port", "value"), Dim::fixed(static_cast<std::uint32_t>(p.number("size", 1))), "scripted");
    d.param("port", std::string("value"), "", "name of the output");
    d.param("size", 1.0, "", "elements of the output");
  }
  static void set(const std::string& task, std::vector<double> values) { table()[task] = std::move(values); }

 protected:
  Status init(InitContext& ctx) override {
    values_ = &table()[std::string(ctx.task_name())];  // a map's elements stay where they are
    out_ = ctx.out<double>(ctx.params().text("port", "value"));
    publish();
    return Status::ok();
  }
  Status on() override {
    publish();
    return Status::ok();
  }
  Status cycle() override {
    publish();
    return Status::ok();
  }

 private:
  static std::map<std::string, std::vector<double>>& table() {
    static std::map<std::string, std::vector<double>> t;
    return t;
  }
  void publish() noexcept {
    for (std::size_t i = 0; i < out_.size() && i < values_->size(); ++i) out_[i] = (*values_)[i];
  }
  const std::vector<double>* values_ = nullptr;
  Out<double> out_;
};

}  // namespace chimera::test

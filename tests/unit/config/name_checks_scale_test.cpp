// The loader's and verification's name checks are linear in the file: a file of many thousand
// tasks, variables, constants and configurations costs a bounded number of name lookups per name
// written in it. Counted (config_detail::name_lookups_in_this_thread), never timed; before the
// name index, every task name was compared with every earlier one.

#include <cstdint>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "chimera/config/loader.hpp"
#include "chimera/config/verify.hpp"
#include "config/detail/name_index.hpp"
#include "unit/config/fake_modules.hpp"

namespace chimera {
namespace {

struct GeneratedFile {
  std::string text;
  std::uint64_t names = 0;  // names written in it: tasks, renames, constants, configurations, entries
};

// A chain of `tasks` visual_servo tasks, task i reading v<i> and writing v<i+1> (renamed ports),
// v0 a constant, as many unused constants, one configuration of the whole chain (legal) and one
// of each single task (legal only for the first: the others miss their input).
GeneratedFile chain(int tasks) {
  GeneratedFile f;
  f.text = "subsystem: chain\nconstants:\n  v0: [0, 0, 0, 0, 0, 0]\n";
  auto n_of = [](int i) { return std::to_string(i); };
  for (int i = 0; i < tasks; ++i) f.text += "  unused" + n_of(i) + ": 1\n";
  f.text += "tasks:\n";
  for (int i = 0; i < tasks; ++i)
    f.text += "  - {name: t" + n_of(i) + ", module: visual_servo, period: 1ms, rename: {x_m: v" + n_of(i) + ", x_d: v" +
              n_of(i + 1) + "}}\n";
  f.text += "configurations:\n  whole:\n";
  for (int i = 0; i < tasks; ++i) f.text += "    - t" + n_of(i) + "\n";
  for (int i = 0; i < tasks; ++i) f.text += "  only" + n_of(i) + ": [t" + n_of(i) + "]\n";
  const auto n = static_cast<std::uint64_t>(tasks);
  f.names = 1 + n /*constants*/ + 3 * n /*task, two renames*/ + 1 + n /*whole*/ + 2 * n /*singles*/;
  return f;
}

// Lookups per name written, for loading, resolving and verifying `file`.
double lookups_per_name(const GeneratedFile& file, std::size_t& violations) {
  const std::uint64_t before = config_detail::name_lookups_in_this_thread();
  auto spec = load_subsystem_text(file.text, "chain.yaml", test::config_test_registry());
  EXPECT_TRUE(spec.ok()) << spec.error().message;
  if (!spec) return 0;
  const Resolution resolution = resolve_subsystem(*spec, test::config_test_registry());
  violations = verify_subsystem(resolution).size();
  const std::uint64_t lookups = config_detail::name_lookups_in_this_thread() - before;
  return static_cast<double>(lookups) / static_cast<double>(file.names);
}

TEST(NameChecksScale, LookupsPerNameStayBoundedAsTheFileGrows) {
  std::size_t small_violations = 0;
  std::size_t large_violations = 0;
  const double small = lookups_per_name(chain(500), small_violations);
  const double large = lookups_per_name(chain(8000), large_violations);
  // Every single-task configuration but the first misses its input: the checks really ran.
  EXPECT_EQ(small_violations, 499U);
  EXPECT_EQ(large_violations, 7999U);
  // A handful per name (find and insert in the loader, two per configuration entry when
  // verifying, one per variable a configuration uses); a check per pair of names would grow
  // with the file, 16 times from the small file to the large one.
  std::printf("lookups per name: %.3f (500 tasks), %.3f (8000 tasks)\n", small, large);
  EXPECT_GT(small, 0.5);
  EXPECT_LT(small, 6.0);
  EXPECT_LT(large, 6.0);
  EXPECT_LT(large, small * 1.1);
}

}  // namespace
}  // namespace chimera

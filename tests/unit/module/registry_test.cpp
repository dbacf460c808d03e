// The registry's bookkeeping for module libraries: where each module came from, and what one
// library's loading added and had refused (begin_capture / end_capture).

#include "chimera/module/registry.hpp"

#include <memory>
#include <string>

#include <gtest/gtest.h>

namespace chimera {
namespace {

class Nothing final : public Module {};

ModuleInfo module(std::string name) {
  return ModuleInfo{std::move(name), "test", "", [](Declarations&, const Params&) {},
                    []() -> std::unique_ptr<Module> { return std::make_unique<Nothing>(); }};
}

TEST(Registry, CaptureRecordsWhatOneLibraryAddedAndWhatWasRefused) {
  Registry r;
  ASSERT_TRUE(r.add(module("built_in")).ok());
  r.refuse("ignored: nobody is capturing");
  r.begin_capture("/lib/libx.so");
  ASSERT_TRUE(r.add(module("from_x")).ok());
  EXPECT_FALSE(r.add(module("built_in")).ok());
  r.refuse("C module 'y' was built for another ABI");
  const Registry::Capture c = r.end_capture();
  EXPECT_EQ(c.added, (std::vector<std::string>{"from_x"}));
  ASSERT_EQ(c.refused.size(), 2u);
  EXPECT_EQ(c.refused[0], "module 'built_in' is registered twice (the first comes from the program itself)");
  EXPECT_EQ(c.refused[1], "C module 'y' was built for another ABI");

  EXPECT_EQ(r.origin("built_in"), "");
  EXPECT_EQ(r.origin("from_x"), "/lib/libx.so");
  ASSERT_TRUE(r.add(module("after")).ok());
  EXPECT_EQ(r.origin("after"), "") << "the capture ended";
  EXPECT_TRUE(r.end_capture().added.empty());
}

TEST(Registry, RemoveTakesAModuleOut) {
  Registry r;
  ASSERT_TRUE(r.add(module("a")).ok());
  ASSERT_TRUE(r.add(module("b")).ok());
  r.remove("a");
  EXPECT_EQ(r.find("a"), nullptr);
  ASSERT_EQ(r.list().size(), 1u);
  EXPECT_EQ(r.list()[0]->name, "b");
  EXPECT_TRUE(r.add(module("a")).ok()) << "its name is free again";
}

}  // namespace
}  // namespace chimera

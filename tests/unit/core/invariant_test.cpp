// Invariants stay checked in every build type (chimera/core/invariant.hpp): this test runs in the
// RelWithDebInfo tree, which defines NDEBUG, and in the sanitizer trees.

#include "chimera/core/invariant.hpp"

#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "chimera/core/result.hpp"

namespace chimera {
namespace {

struct Broken : std::runtime_error {
  using std::runtime_error::runtime_error;
};

[[noreturn]] void throwing_handler(const char* what, const char* /*file*/, int /*line*/) { throw Broken(what); }

// A test's own handler for the scope of one test, so that a check can be seen to fire in-process.
class ThrowingHandler {
 public:
  ThrowingHandler() : previous_(set_invariant_handler(&throwing_handler)) {}
  ~ThrowingHandler() { set_invariant_handler(previous_); }
  ThrowingHandler(const ThrowingHandler&) = delete;
  ThrowingHandler& operator=(const ThrowingHandler&) = delete;

 private:
  InvariantHandler previous_;
};

TEST(Invariant, HoldsSilently) {
  ThrowingHandler handler;
  EXPECT_NO_THROW(CHIMERA_INVARIANT(1 + 1 == 2, "arithmetic"));
}

TEST(Invariant, TheErrorOfASuccessIsABrokenInvariantEvenWithNdebug) {
  ThrowingHandler handler;
  const Result<void> ok;
  EXPECT_THROW((void)ok.error(), Broken);
  const Result<int> value = 3;
  EXPECT_THROW((void)value.error(), Broken);
  const Result<int> failure = make_error(Errc::kNotFound, "gone");
  EXPECT_THROW((void)failure.value(), Broken);
  try {
    (void)ok.error();
  } catch (const Broken& e) {
    EXPECT_EQ(std::string(e.what()), "Result<void>::error() of a success");
  }
}

TEST(InvariantDeathTest, TheDefaultHandlerNamesTheInvariantAndAborts) {
  const Result<void> ok;
  EXPECT_DEATH((void)ok.error(),
               "chimera: invariant broken: Result<void>::error\\(\\) of a success \\(.*result\\.hpp:");
  EXPECT_DEATH(CHIMERA_INVARIANT(false, "a test's own invariant"), "invariant broken: a test's own invariant");
}

}  // namespace
}  // namespace chimera

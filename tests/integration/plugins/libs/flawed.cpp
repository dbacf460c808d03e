// Module libraries broken in the ways the loader must report, one library per flaw: CMakeLists.txt
// compiles this file once for each, defining one of the FLAW_* macros below.
#include <stdexcept>

#include "chimera/module/registry.hpp"

#if defined(FLAW_UNDEFINED_SYMBOL)
int chimera_test_function_nobody_defines(int x);  // dlopen with RTLD_NOW refuses the library
#endif

namespace {

class Flawed final : public chimera::Module {
 public:
#if defined(FLAW_DUPLICATE)
  static constexpr const char* kName = "my_module";  // the good library's module
#else
  static constexpr const char* kName = "test_flawed";
#endif
  static constexpr const char* kSummary = "broken on purpose";
  static constexpr const char* kDoc = "";
  static void declare(chimera::Declarations& d, const chimera::Params& /*params*/) {
#if defined(FLAW_BAD_NAME)
    d.out_var("theta d", chimera::Dim::fixed(6), "a name with a space");
#elif defined(FLAW_BAD_SIZE)
    d.out_var("theta_d", chimera::Dim::of("ndof"), "sized by a const port the module lacks");
#elif defined(FLAW_THROWING_DECLARE)
    throw std::runtime_error("no ports today");
#elif defined(FLAW_UNDEFINED_SYMBOL)
    d.param("x", static_cast<double>(chimera_test_function_nobody_defines(1)), "", "");
#endif
    (void)d;
  }
};

#if defined(FLAW_DUPLICATE)
// Comes with the duplicate; the loader must take it out again when it refuses the library.
class Companion final : public chimera::Module {
 public:
  static constexpr const char* kName = "test_companion";
  static constexpr const char* kSummary = "leaves with the duplicate";
  static constexpr const char* kDoc = "";
  static void declare(chimera::Declarations& /*d*/, const chimera::Params& /*params*/) {}
};
CHIMERA_REGISTER_MODULE(Companion);
#endif

}  // namespace

CHIMERA_REGISTER_MODULE(Flawed);

#pragma once
// The module library: every module type available by name, with its ports and documentation.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/core/result.hpp"
#include "chimera/module/declarations.hpp"
#include "chimera/module/module.hpp"
#include "chimera/module/params.hpp"
#include "chimera/module_abi.hpp"

// NOLINTBEGIN(readability-identifier-naming): a C interface keeps C's names
extern "C" {
/// Who a library of C++ modules was built against. Its layout never changes, so that any
/// libchimera can read the stamp of any library, however old or new.
struct chimera_cxx_abi_stamp {
  std::uint64_t magic;        // kCxxAbiStampMagic
  std::uint64_t fingerprint;  // kModuleAbiFingerprint of the headers the library was built with
  const char* version;        // the Chimera version of those headers
};
/// What CHIMERA_REGISTER_MODULE calls as a library loads. If `stamp` is this libchimera's,
/// `add` runs (the library's own code adds module `module` to the registry); otherwise the
/// library is refused with a message naming its version and this one, and nothing of it is
/// called. Not real-time safe.
void chimera_register_cxx_module(const chimera_cxx_abi_stamp* stamp, const char* module, void (*add)());
}
// NOLINTEND(readability-identifier-naming)

namespace chimera {

/// "CHIMCXX1": marks a stamp as one.
inline constexpr std::uint64_t kCxxAbiStampMagic = 0x31585843'4d494843ULL;

struct ModuleInfo {
  std::string name;
  std::string summary;  // one line
  std::string doc;      // what it computes, equations, references
  std::function<void(Declarations&, const Params&)> declare;
  std::function<std::unique_ptr<Module>()> make;

  /// The declarations for `params` (ports may depend on parameters).
  [[nodiscard]] Declarations declarations(const Params& params) const {
    Declarations d;
    declare(d, params);
    return d;
  }
};

/// All module types known to this process. Not real-time safe.
class Registry {
 public:
  /// The process-wide registry that CHIMERA_REGISTER_MODULE adds to.
  static Registry& global();

  /// Adds a module type; a second module of the same name is refused.
  Result<void> add(ModuleInfo info);
  [[nodiscard]] const ModuleInfo* find(std::string_view name) const;
  /// Sorted by name.
  [[nodiscard]] std::vector<const ModuleInfo*> list() const;
  /// The library module `name` was loaded from; "" for a module linked into the program.
  [[nodiscard]] std::string_view origin(std::string_view name) const;

  /// What happened to registrations between begin_capture() and end_capture(): the plugin
  /// loader brackets a library's loading with them to learn what the library brought.
  struct Capture {
    std::vector<std::string> added;    // module names, in registration order
    std::vector<std::string> refused;  // one message per refused registration
  };
  /// Modules added from now on come from `origin` (a library's path), and refusals are kept.
  void begin_capture(std::string origin);
  Capture end_capture();
  /// Records a registration refused before it reached add() (a C module of another ABI, say).
  void refuse(std::string message);
  /// Removes module `name` (a library that failed its checks takes its modules back).
  void remove(std::string_view name);

 private:
  struct Entry {
    std::unique_ptr<ModuleInfo> info;
    std::string origin;
  };
  std::vector<Entry> modules_;
  bool capturing_ = false;
  std::string origin_;
  Capture capture_;
};

namespace detail {
/// The stamp of whatever includes this header: compiled into each module library.
inline constexpr chimera_cxx_abi_stamp kAbiStamp{kCxxAbiStampMagic, kModuleAbiFingerprint, kChimeraVersion};

template <class M>
void add_module() {
  auto added = Registry::global().add(ModuleInfo{M::kName, M::kSummary, M::kDoc,
                                                 [](Declarations& d, const Params& p) { M::declare(d, p); },
                                                 []() -> std::unique_ptr<Module> { return std::make_unique<M>(); }});
  (void)added;  // a duplicate name keeps the first; `chimera modules` shows which
}

template <class M>
struct Registration {
  Registration() { chimera_register_cxx_module(&kAbiStamp, M::kName, &add_module<M>); }
};
}  // namespace detail

}  // namespace chimera

#define CHIMERA_DETAIL_CAT2(a, b) a##b
#define CHIMERA_DETAIL_CAT(a, b) CHIMERA_DETAIL_CAT2(a, b)
/// Registers module class M (with static kName, kSummary, kDoc and declare()) at load time, stamped
/// with the module ABI it was compiled against: a library built for another one is refused.
#define CHIMERA_REGISTER_MODULE(M) \
  static const ::chimera::detail::Registration<M> CHIMERA_DETAIL_CAT(chimera_registration_, __LINE__) {}

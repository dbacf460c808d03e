#pragma once
// The module library: every module type available by name, with its ports and documentation.

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/core/result.hpp"
#include "chimera/module/declarations.hpp"
#include "chimera/module/module.hpp"
#include "chimera/module/params.hpp"

namespace chimera {

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
template <class M>
struct Registration {
  Registration() {
    auto added = Registry::global().add(ModuleInfo{M::kName, M::kSummary, M::kDoc,
                                                   [](Declarations& d, const Params& p) { M::declare(d, p); },
                                                   []() -> std::unique_ptr<Module> { return std::make_unique<M>(); }});
    (void)added;  // a duplicate name keeps the first; `chimera modules` shows which
  }
};
}  // namespace detail

}  // namespace chimera

#define CHIMERA_DETAIL_CAT2(a, b) a##b
#define CHIMERA_DETAIL_CAT(a, b) CHIMERA_DETAIL_CAT2(a, b)
/// Registers module class M (with static kName, kSummary, kDoc and declare()) at load time.
#define CHIMERA_REGISTER_MODULE(M) \
  static const ::chimera::detail::Registration<M> CHIMERA_DETAIL_CAT(chimera_registration_, __LINE__) {}

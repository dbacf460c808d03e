// Defines a module outside the Chimera tree, registers it with CHIMERA_REGISTER_MODULE, then
// finds it in the process-wide registry and prints its ports. The package test checks the output.

#include <cstdio>
#include <memory>
#include <string>

#include <chimera/module/module.hpp>
#include <chimera/module/registry.hpp>

namespace {

/// y = k * u, channel by channel: the smallest module that has every kind of declaration.
class Gain final : public chimera::Module {
 public:
  static constexpr const char* kName = "consumer_gain";
  static constexpr const char* kSummary = "y = k u, defined outside the Chimera tree";
  static constexpr const char* kDoc = "Multiplies each input channel by the parameter k.";

  static void declare(chimera::Declarations& d, const chimera::Params& /*params*/) {
    d.in_const("ndof", chimera::Dim::fixed(1), "number of channels");
    d.in_var("u", chimera::Dim::of("ndof"), "input");
    d.out_var("y", chimera::Dim::of("ndof"), "output");
    d.param("k", 2.0, "", "gain");
  }
};

CHIMERA_REGISTER_MODULE(Gain);

}  // namespace

int main() {
  const chimera::ModuleInfo* info = chimera::Registry::global().find("consumer_gain");
  if (info == nullptr) {
    std::fprintf(stderr, "consumer_gain is not in chimera::Registry::global()\n");
    return 1;
  }
  std::printf("module %s: %s\n", info->name.c_str(), info->summary.c_str());
  const chimera::Declarations decl = info->declarations(chimera::Params{});
  for (const chimera::PortDecl& port : decl.ports()) {
    const std::string kind(chimera::port_kind_name(port.kind));
    const std::string type(chimera::elem_name(port.type));
    std::printf("port %s %s %s[%s]\n", kind.c_str(), port.name.c_str(), type.c_str(),
                chimera::to_string(port.dim).c_str());
  }
  // The factory builds the module through the library's vtable: links and constructs.
  const std::unique_ptr<chimera::Module> module = info->make();
  std::printf("made: %s\n", module != nullptr ? "yes" : "no");
  return module != nullptr ? 0 : 1;
}

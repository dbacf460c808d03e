#pragma once
// Module libraries loaded at run time, without rebuilding chimera: a shared library built against
// the installed package (find_package(chimera)) whose modules register themselves with
// CHIMERA_REGISTER_MODULE, or CHIMERA_REGISTER_C_MODULE in C, as the library is loaded. It is
// found by name on a search path (CHIMERA_MODULE_PATH) and loaded with dlopen.
//
// None of this is real-time safe, nor thread-safe: load libraries from one thread, before the
// subsystems that use their modules are created. A loaded library stays loaded until the process
// ends, since the registry's modules point into its code.

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/core/result.hpp"

namespace chimera {

/// A library that loaded and passed the checks.
struct LoadedPlugin {
  std::string path;                  // the file loaded, absolute
  std::vector<std::string> modules;  // what it registered, in registration order
};

/// The directories of the environment variable CHIMERA_MODULE_PATH, ':'-separated, in order;
/// empty entries are skipped.
std::vector<std::string> module_search_path();

/// Where library `name` is. A name holding a '/' is a path, relative ones taken from `base_dir`
/// (the directory of the subsystem file that names it). A bare name is looked up in each
/// directory of `search_path` in turn, as written and, when it does not end in ".so", as
/// lib<name>.so. Errors (Errc::kNotFound) say where it looked.
Result<std::string> find_plugin(std::string_view name, std::span<const std::string> search_path,
                                const std::string& base_dir);

/// Loads the library at `path` into the process and checks what it registered in
/// Registry::global(): at least one module, none refused (a name already taken, say), every one
/// declaring ports and parameters well (module_detail::check_module). On any problem the library's
/// modules are taken out of the registry again. `name` is the library as the user wrote it, for
/// messages such as "cannot load 'libx.so': <dlerror>". A path loaded before gives the first
/// outcome again. Errors carry Errc::kInvalidInput.
Result<LoadedPlugin> load_plugin(std::string_view name, const std::string& path);

/// Every "*.so" file in the directories of `search_path`, directory by directory, by name within
/// one (for `chimera modules`, which lists what the path offers).
std::vector<std::string> plugins_on_path(std::span<const std::string> search_path);

}  // namespace chimera

// Keeps chimera_modules a valid library whatever modules are present; the modules themselves
// live in one folder each beside this file.
namespace chimera::modules {
int registration_anchor = 0;
}  // namespace chimera::modules

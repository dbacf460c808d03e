// Keeps chimera_modules a valid library whatever modules are present; the modules themselves
// live in one folder each beside this file.
namespace chimera::modules {
extern const int kRegistrationAnchor;  // external linkage: a namespace-scope const is file-local otherwise
const int kRegistrationAnchor = 0;
}  // namespace chimera::modules

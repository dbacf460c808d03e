// A library that registers nothing: the loader refuses it.
namespace chimera_test_plugin {
int nothing_here = 0;
}  // namespace chimera_test_plugin

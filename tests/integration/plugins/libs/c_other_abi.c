/* A C module built for another version of the C interface: the loader refuses the library. */
#include "chimera/module/c_module.h"

static void other_declare(chimera_decl* d, const chimera_params* p) {
  (void)d;
  (void)p;
}

static const chimera_c_module other = {
    .abi_version = CHIMERA_C_ABI_VERSION + 41u,
    .struct_size = (uint32_t)sizeof(chimera_c_module),
    .name = "test_c_other_abi",
    .summary = "from the future",
    .doc = "",
    .state_size = 0,
    .declare = other_declare,
};

CHIMERA_REGISTER_C_MODULE(other)

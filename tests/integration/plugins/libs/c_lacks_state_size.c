/* A C module whose struct lacks state_size: written against a c_module.h of another shape (here
 * spelled out by hand), it claims today's version and size. Every field after `doc` is one place
 * off: state_size reads the declare pointer. The loader must refuse it by its fields, not crash. */
#include <stdint.h>

#include "chimera/module/c_module.h"

typedef struct shorter_module {
  uint32_t abi_version;
  uint32_t struct_size;
  const char* name;
  const char* summary;
  const char* doc;
  /* no state_size */
  void (*declare)(chimera_decl* d, const chimera_params* params);
  chimera_status (*init)(void* state, chimera_ctx* ctx);
  chimera_status (*on)(void* state);
  chimera_status (*cycle)(void* state);
  chimera_status (*off)(void* state);
  chimera_status (*kill)(void* state);
  chimera_status (*error)(void* state);
  chimera_status (*clear)(void* state);
  chimera_status (*reinit)(void* state);
  chimera_status (*sync)(void* state);
} shorter_module;

static void shorter_declare(chimera_decl* d, const chimera_params* p) {
  (void)p;
  chimera_out_var(d, "y", chimera_dim_fixed(1), "an output");
}
static chimera_status shorter_cycle(void* self) {
  (void)self;
  return CHIMERA_OK;
}

/* Padded, so that the loader reading the struct as today's stays inside this object (the real
 * mistake would read whatever follows it). */
static const struct {
  shorter_module module;
  char padding[64];
} holder = {{CHIMERA_C_ABI_VERSION, (uint32_t)sizeof(chimera_c_module), "test_c_shorter", "missing a field", "",
             shorter_declare, 0, 0, shorter_cycle, 0, 0, 0, 0, 0, 0},
            {0}};

__attribute__((constructor)) static void register_shorter(void) {
  chimera_register_c_module((const chimera_c_module*)&holder.module);
}

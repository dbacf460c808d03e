/* The port-based object in C, for module authors who write C (the paper's choice for control
 * engineers, section 3.3). A module is a struct of function pointers, one for each method the
 * framework calls, and a declare function that names its ports and parameters:
 *
 *   #include <chimera/module/c_module.h>
 *
 *   typedef struct { chimera_in u; chimera_out y; double k; } gain_state;
 *
 *   static void gain_declare(chimera_decl* d, const chimera_params* p) {
 *     chimera_in_const(d, "ndof", chimera_dim_fixed(1), "number of channels");
 *     chimera_in_var(d, "u", chimera_dim_of("ndof", 1), "input");
 *     chimera_out_var(d, "y", chimera_dim_of("ndof", 1), "output");
 *     chimera_param_number(d, "k", 2.0, "", "gain");
 *   }
 *   static chimera_status gain_init(void* self, chimera_ctx* ctx) {
 *     gain_state* s = self;                         // zeroed by the framework, state_size bytes
 *     s->u = chimera_input(ctx, "u");               // views, resolved once by port name
 *     s->y = chimera_output(ctx, "y");
 *     s->k = chimera_number(chimera_ctx_params(ctx), "k", 2.0);
 *     return CHIMERA_OK;
 *   }
 *   static chimera_status gain_cycle(void* self) {
 *     gain_state* s = self;
 *     for (size_t i = 0; i < s->y.size; ++i) s->y.data[i] = s->k * s->u.data[i];
 *     return CHIMERA_OK;
 *   }
 *   static const chimera_c_module gain = {
 *       CHIMERA_C_MODULE_STAMP, .name = "c_gain", .summary = "y = k u",
 *       .doc = "...", .state_size = sizeof(gain_state), .declare = gain_declare,
 *       .init = gain_init, .cycle = gain_cycle};
 *   CHIMERA_REGISTER_C_MODULE(gain)
 *
 * Build it as a shared library against the installed package (find_package(chimera), link
 * chimera::chimera) and name it in a subsystem file's plugins: list.
 *
 * Methods return CHIMERA_OK, or a string literal saying why they failed: the framework then
 * takes the lifecycle's error path, as for a C++ module. Methods left NULL succeed, except
 * error, whose absence means a fault is not recovered. init and kill may allocate; on, cycle,
 * off, error, clear and sync run on the task's real-time thread and should not. Every port of a
 * C module has 64-bit float elements. */
#ifndef CHIMERA_MODULE_C_MODULE_H
#define CHIMERA_MODULE_C_MODULE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif
/* NOLINTBEGIN(readability-identifier-naming, modernize-*): a C header keeps C's names and forms */

/* The layout of chimera_c_module below; a library built for another one is refused. Version 2
 * added struct_size. */
#define CHIMERA_C_ABI_VERSION 2u

/* A method's outcome: CHIMERA_OK, or a string literal (it must outlive the program). */
typedef const char* chimera_status;
#define CHIMERA_OK ((chimera_status)0)

typedef struct chimera_decl chimera_decl;     /* what declare() fills in */
typedef struct chimera_params chimera_params; /* a task's parameter values */
typedef struct chimera_ctx chimera_ctx;       /* one task's context, from init until kill */

/* An element count: `factor`, or `factor` times the first element of the const port `symbol`
 * (e.g. ndof), or (follows) whatever size the variable has at its other ends. */
typedef struct chimera_dim {
  uint32_t factor;
  const char* symbol;
  int follows;
} chimera_dim;

static inline chimera_dim chimera_dim_fixed(uint32_t count) {
  chimera_dim d = {count, NULL, 0};
  return d;
}
static inline chimera_dim chimera_dim_of(const char* symbol, uint32_t factor) {
  chimera_dim d = {factor, symbol, 0};
  return d;
}
static inline chimera_dim chimera_dim_follow(void) {
  chimera_dim d = {1, NULL, 1};
  return d;
}

/* ---- declare: ports, parameters, resource. Strings are copied. ---- */
void chimera_in_const(chimera_decl* d, const char* name, chimera_dim dim, const char* doc);
void chimera_in_var(chimera_decl* d, const char* name, chimera_dim dim, const char* doc);
void chimera_out_var(chimera_decl* d, const char* name, chimera_dim dim, const char* doc);
/* An out-const's value is known when the module is declared (from its parameters). */
void chimera_out_const(chimera_decl* d, const char* name, const double* values, size_t count, const char* doc);
void chimera_param_number(chimera_decl* d, const char* name, double value, const char* unit, const char* doc);
void chimera_param_bool(chimera_decl* d, const char* name, int value, const char* unit, const char* doc);
void chimera_param_string(chimera_decl* d, const char* name, const char* value, const char* unit, const char* doc);
void chimera_param_vector(chimera_decl* d, const char* name, const double* values, size_t count, const char* unit,
                          const char* doc);
/* The values a parameter declared above accepts (docs/writing-modules.md, "Parameter ranges"):
 * a bound below or above for a number (each element of a vector), choices for a string. Checked
 * by chimera verify with the file's line. A rule for a name not declared refuses the module. */
void chimera_param_at_least(chimera_decl* d, const char* name, double lower);
void chimera_param_greater_than(chimera_decl* d, const char* name, double lower);
void chimera_param_at_most(chimera_decl* d, const char* name, double upper);
void chimera_param_less_than(chimera_decl* d, const char* name, double upper);
void chimera_param_one_of(chimera_decl* d, const char* name, const char* const* choices, size_t count);
/* Whole numbers only (counts, sizes, ports): 2.5 is refused at its line. */
void chimera_param_whole(chimera_decl* d, const char* name);
/* What the module's resource port talks to (hardware, a simulation, a socket), for docs. */
void chimera_resource(chimera_decl* d, const char* what);

/* ---- parameter values, in declare and init. Absent or of another type: the fallback. ---- */
double chimera_number(const chimera_params* p, const char* name, double fallback);
int chimera_flag(const chimera_params* p, const char* name, int fallback);
/* The text, or NULL; valid while the params are (declare: until it returns; init: until kill). */
const char* chimera_text(const chimera_params* p, const char* name);
/* Copies up to `capacity` elements into `out` and returns how many the vector has. */
size_t chimera_vector(const chimera_params* p, const char* name, double* out, size_t capacity);

/* ---- ports, in init. Views stay valid until kill; reading and writing them is real-time safe. */
typedef struct chimera_in {
  const double* data; /* NULL if the port could not be bound (init then fails, naming it) */
  size_t size;
  const void* port_; /* for chimera_fresh(); not to be touched */
} chimera_in;
typedef struct chimera_out {
  double* data;
  size_t size;
} chimera_out;

/* How fresh an input is after the transfer before a method. */
typedef enum chimera_freshness { CHIMERA_NO_DATA = 0, CHIMERA_OLD = 1, CHIMERA_NEW = 2 } chimera_freshness;

chimera_in chimera_input(chimera_ctx* ctx, const char* port);   /* an in-var or in-const */
chimera_out chimera_output(chimera_ctx* ctx, const char* port); /* an out-var or out-const */
/* Real-time safe. */
chimera_freshness chimera_fresh(chimera_in in);

/* ---- the task. ---- */
typedef struct chimera_timing {
  int64_t release_ns; /* nominal release of the current cycle, since the subsystem started */
  int64_t period_ns;  /* 0 for an aperiodic task */
  uint64_t cycle;     /* cycles completed before this one */
} chimera_timing;

const chimera_params* chimera_ctx_params(const chimera_ctx* ctx);
const char* chimera_task_name(const chimera_ctx* ctx);
/* Up to date at the start of every method; keep the pointer (valid until kill). Real-time safe. */
const chimera_timing* chimera_timing_of(const chimera_ctx* ctx);
/* Period in seconds, 0 for an aperiodic task. */
double chimera_period_s(const chimera_ctx* ctx);
/* In init: refuse parameter `param`'s value; returns `reason` for init to return. The framework's
 * message then points at the line of the subsystem file that gives the parameter (or the task's,
 * if the file leaves it at its default): "robot.yaml:12: arm.params.model: init failed: ...". */
chimera_status chimera_refuse(chimera_ctx* ctx, const char* param, chimera_status reason);
/* The paper's illegal-configuration flag (section 3.4); keep ctx to ask in cycle. Real-time safe. */
int chimera_illegal_configuration(const chimera_ctx* ctx);

/* ---- the module. ---- */
typedef struct chimera_c_module {
  uint32_t abi_version; /* CHIMERA_C_ABI_VERSION        these two first, in every version:  */
  uint32_t struct_size; /* sizeof(chimera_c_module)     write CHIMERA_C_MODULE_STAMP         */
  const char* name;     /* the module type's name in subsystem files */
  const char* summary;  /* one line */
  const char* doc;      /* what it computes, equations, references */
  size_t state_size;    /* bytes of per-task state, zeroed by the framework and passed to every method */
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
} chimera_c_module;

/* The first two fields of every chimera_c_module, for a designated initializer. */
#define CHIMERA_C_MODULE_STAMP .abi_version = CHIMERA_C_ABI_VERSION, .struct_size = (uint32_t)sizeof(chimera_c_module)

/* Adds `module` to the module library. `module` must outlive the process (a static object).
 * Every field is checked before anything is called: the version and the size of the struct, a
 * name and a declare function, state_size within reason, and every pointer inside the library
 * that registers it. A problem (another ABI, a struct of another shape, a missing name or
 * declare, a name taken) is recorded for the loader, which then refuses the library with a
 * message naming the field. */
void chimera_register_c_module(const chimera_c_module* module);

/* Registers `def` (a chimera_c_module object) when the library is loaded. */
#define CHIMERA_REGISTER_C_MODULE(def) \
  __attribute__((constructor)) static void chimera_register_c_module_##def(void) { chimera_register_c_module(&(def)); }

/* NOLINTEND(readability-identifier-naming, modernize-*) */
#ifdef __cplusplus
}
#endif

#endif /* CHIMERA_MODULE_C_MODULE_H */

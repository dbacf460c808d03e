/* my_module: a first-order low-pass filter, written in C. A port-based object (the paper's
 * section 3.3): the framework calls the methods and transfers the state variables around them. */

#include <chimera/module/c_module.h>

/* Per-task state: the framework allocates state_size bytes, zeroed, for every task. */
typedef struct my_module_state {
  chimera_in u;
  chimera_out y;
  double tau;
  double dt;
} my_module_state;

static void my_module_declare(chimera_decl* d, const chimera_params* params) {
  (void)params; /* ports may depend on parameters; these do not */
  chimera_in_const(d, "ndof", chimera_dim_fixed(1), "number of channels");
  chimera_in_var(d, "u", chimera_dim_of("ndof", 1), "input");
  chimera_out_var(d, "y", chimera_dim_of("ndof", 1), "filtered input");
  chimera_param_number(d, "tau", 0.1, "s", "time constant (> 0)");
  /* What it accepts: chimera verify refuses tau <= 0 with the file's line, before init could. */
  chimera_param_greater_than(d, "tau", 0.0);
}

/* init may fail: a string literal says why, and the task is not created. */
static chimera_status my_module_init(void* self, chimera_ctx* ctx) {
  my_module_state* s = (my_module_state*)self;
  s->u = chimera_input(ctx, "u");
  s->y = chimera_output(ctx, "y");
  s->tau = chimera_number(chimera_ctx_params(ctx), "tau", 0.1);
  s->dt = chimera_period_s(ctx);
  if (!(s->tau > 0.0)) return "tau must be greater than 0";
  if (s->dt <= 0.0) return "my_module must run periodically (give the task a period)";
  return CHIMERA_OK;
}

/* Turned on: the filter starts at rest. */
static chimera_status my_module_on(void* self) {
  my_module_state* s = (my_module_state*)self;
  for (size_t i = 0; i < s->y.size; ++i) s->y.data[i] = 0.0;
  return CHIMERA_OK;
}

/* One period, real-time: y += (u - y) dt / (tau + dt), the backward-Euler step of
 * tau dy/dt = u - y. No allocation, no blocking, no formatting. */
static chimera_status my_module_cycle(void* self) {
  my_module_state* s = (my_module_state*)self;
  if (chimera_fresh(s->u) == CHIMERA_NO_DATA) return CHIMERA_OK;
  const double a = s->dt / (s->tau + s->dt);
  for (size_t i = 0; i < s->y.size; ++i) s->y.data[i] += a * (s->u.data[i] - s->y.data[i]);
  return CHIMERA_OK;
}

static const chimera_c_module my_module = {
    CHIMERA_C_MODULE_STAMP,
    .name = "my_module",
    .summary = "first-order low-pass filter, in C",
    .doc =
        "Each channel of y follows u through tau dy/dt = u - y, discretised by backward Euler: "
        "y_k = y_(k-1) + (u_k - y_(k-1)) dt / (tau + dt), dt the task's period. y starts at 0 "
        "when the task is turned on.",
    .state_size = sizeof(my_module_state),
    .declare = my_module_declare,
    .init = my_module_init,
    .on = my_module_on,
    .cycle = my_module_cycle,
};

CHIMERA_REGISTER_C_MODULE(my_module)

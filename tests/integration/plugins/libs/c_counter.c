/* A C module library for the plugin tests: test_c_counter counts its cycles into `count`, adds
 * `offset` (a parameter) and copies the freshness of its input and the release time, so that a
 * test can see every part of the C interface work. It fails on purpose when asked to. */
#include <string.h>

#include "chimera/module/c_module.h"

typedef struct counter_state {
  chimera_in u;
  chimera_out count;
  chimera_out seen;
  const chimera_timing* timing;
  double offset;
  double fail_at;
  int recover;
} counter_state;

static void counter_declare(chimera_decl* d, const chimera_params* p) {
  /* Ports may depend on parameters: `width` sizes `seen`. */
  const double width = chimera_number(p, "width", 3.0);
  chimera_in_var(d, "u", chimera_dim_fixed(1), "any input");
  chimera_out_var(d, "count", chimera_dim_fixed(1), "cycles + offset");
  chimera_out_var(d, "seen", chimera_dim_fixed((uint32_t)width), "[freshness of u, release s, period s]");
  chimera_param_number(d, "offset", 0.0, "", "added to the count");
  chimera_param_number(d, "width", 3.0, "", "size of seen (at least 3)");
  chimera_param_at_least(d, "width", 3.0); /* a rule chimera verify checks, with the file's line */
  chimera_param_whole(d, "width");
  chimera_param_number(d, "fail_at", -1.0, "cycles", "cycle that fails (-1: none)");
  chimera_param_bool(d, "recover", 0, "", "error() recovers");
  chimera_param_string(d, "label", "counter", "", "a text parameter");
  {
    const char* const labels[] = {"counter", "other", "refuse"}; /* refuse: init says no */
    chimera_param_one_of(d, "label", labels, 3);
  }
  {
    const double gains[2] = {1.0, 2.0};
    chimera_param_vector(d, "gains", gains, 2, "", "a vector parameter");
  }
  chimera_resource(d, "nothing (a test)");
}

static chimera_status counter_init(void* self, chimera_ctx* ctx) {
  counter_state* s = (counter_state*)self;
  const chimera_params* p = chimera_ctx_params(ctx);
  double gains[4] = {0, 0, 0, 0};
  const char* label = chimera_text(p, "label");
  s->u = chimera_input(ctx, "u");
  s->count = chimera_output(ctx, "count");
  s->seen = chimera_output(ctx, "seen");
  s->timing = chimera_timing_of(ctx);
  s->offset = chimera_number(p, "offset", 0.0);
  s->fail_at = chimera_number(p, "fail_at", -1.0);
  s->recover = chimera_flag(p, "recover", 0);
  if (label == NULL || strcmp(label, "refuse") == 0) return chimera_refuse(ctx, "label", "label says refuse");
  if (chimera_vector(p, "gains", gains, 4) != 2 || gains[1] != 2.0) return "gains are not [1, 2]";
  if (strcmp(chimera_task_name(ctx), "") == 0) return "no task name";
  if (s->seen.size < 3) return "width must be at least 3";
  return CHIMERA_OK;
}

static chimera_status counter_on(void* self) {
  counter_state* s = (counter_state*)self;
  s->count.data[0] = s->offset;
  return CHIMERA_OK;
}

static chimera_status counter_cycle(void* self) {
  counter_state* s = (counter_state*)self;
  s->count.data[0] += 1.0;
  s->seen.data[0] = (double)chimera_fresh(s->u);
  s->seen.data[1] = (double)s->timing->release_ns * 1e-9;
  s->seen.data[2] = (double)s->timing->period_ns * 1e-9;
  if (s->count.data[0] - s->offset == s->fail_at) return "counter failed on purpose";
  return CHIMERA_OK;
}

static chimera_status counter_error(void* self) {
  counter_state* s = (counter_state*)self;
  return s->recover ? CHIMERA_OK : "counter does not recover";
}

static const chimera_c_module counter = {
    CHIMERA_C_MODULE_STAMP,
    .name = "test_c_counter",
    .summary = "counts cycles (test plugin in C)",
    .doc = "count = offset + cycles since on.",
    .state_size = sizeof(counter_state),
    .declare = counter_declare,
    .init = counter_init,
    .on = counter_on,
    .cycle = counter_cycle,
    .error = counter_error,
};

CHIMERA_REGISTER_C_MODULE(counter)

// The C interface of include/chimera/module/c_module.h: a C module is a struct of function
// pointers, and CModule is the one C++ module that calls them. The opaque C handles wrap the C++
// objects: chimera_decl a Declarations, chimera_params a Params, chimera_ctx a task's context.

#include "chimera/module/c_module.h"

#include <dlfcn.h>

#include <array>
#include <cstddef>
#include <cstring>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include "chimera/core/identifier.hpp"
#include "chimera/module/registry.hpp"

struct chimera_decl {
  chimera::Declarations* decls;
};

struct chimera_params {
  const chimera::Params* params;
};

// The context a C module's methods see, from init until kill.
struct chimera_ctx {
  chimera::InitContext* init = nullptr;  // only while init runs: ports are bound then
  chimera_params params{nullptr};
  std::string task_name;
  const chimera::CycleTiming* source = nullptr;
  const chimera::SubsystemFlags* flags = nullptr;
  chimera_timing timing{};
  std::deque<chimera::In<double>> inputs;  // a deque: chimera_in::port_ points at its elements
};

namespace {

using chimera::Declarations;
using chimera::Params;
using chimera::Status;

static_assert(static_cast<int>(chimera::Freshness::kNoData) == CHIMERA_NO_DATA);
static_assert(static_cast<int>(chimera::Freshness::kOld) == CHIMERA_OLD);
static_assert(static_cast<int>(chimera::Freshness::kNew) == CHIMERA_NEW);

Declarations& decl_of(chimera_decl* d) { return *d->decls; }
const Params& params_of(const chimera_params* p) { return *p->params; }

std::string text_or_empty(const char* s) { return s != nullptr ? std::string(s) : std::string(); }

chimera::Dim dim_of(chimera_dim d) { return chimera::Dim{d.factor, text_or_empty(d.symbol), d.follows != 0}; }

Status status_of(chimera_status s) { return s == CHIMERA_OK ? Status::ok() : Status::fail(s); }

/// More per-task state than any module needs: a state_size past it is a struct of another shape
/// (its next field, a code address, read as a size).
constexpr std::size_t kMaxStateBytes = std::size_t{16} << 20;
constexpr std::size_t kMaxNameBytes = 64;

/// The base address of the loaded object that `p` points into, or nullptr if none does.
const void* object_of(const void* p) {
  Dl_info info{};
  if (p == nullptr || ::dladdr(p, &info) == 0) return nullptr;
  return info.dli_fbase;
}

template <class F>
const void* address_of(F* f) {
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-reinterpret-cast): a function's address, for dladdr only
  return reinterpret_cast<const void*>(f);
}

/// Whether `text` points into a loaded object and ends within `max` bytes (it is read only then).
bool readable_text(const char* text, std::size_t max) {
  return object_of(text) != nullptr && ::strnlen(text, max) < max;
}

/// What is wrong with a struct whose version matches, before any of its functions is called or
/// its strings read: "" if nothing.
std::string struct_problem(const chimera_c_module& m) {
  if (m.struct_size != sizeof(chimera_c_module))
    return fmt::format("its struct is {} bytes, this chimera's is {}", m.struct_size, sizeof(chimera_c_module));
  const void* home = object_of(&m);
  if (m.name == nullptr) return "it has no name";
  if (!readable_text(m.name, kMaxNameBytes) || !chimera::is_identifier(m.name))
    return "its name is not a valid module name";
  for (const char* text : {m.summary, m.doc})
    if (text != nullptr && object_of(text) == nullptr) return "its summary or doc is not a string of the library";
  if (m.state_size > kMaxStateBytes)
    return fmt::format("its state_size is {} bytes, more than {} MiB", m.state_size, kMaxStateBytes >> 20U);
  if (m.declare == nullptr) return "it has no declare function";
  if (object_of(address_of(m.declare)) != home) return "its declare is not a function of the library";
  const std::array<std::pair<const char*, const void*>, 9> methods{{{"init", address_of(m.init)},
                                                                    {"on", address_of(m.on)},
                                                                    {"cycle", address_of(m.cycle)},
                                                                    {"off", address_of(m.off)},
                                                                    {"kill", address_of(m.kill)},
                                                                    {"error", address_of(m.error)},
                                                                    {"clear", address_of(m.clear)},
                                                                    {"reinit", address_of(m.reinit)},
                                                                    {"sync", address_of(m.sync)}}};
  for (const auto& [method, address] : methods)
    if (address != nullptr && object_of(address) != home)
      return fmt::format("its {} is not a function of the library", method);
  return {};
}

/// The module's name for a message about it: only if it is safe to read.
std::string name_for_message(const chimera_c_module& m) {
  if (m.struct_size == sizeof(chimera_c_module) && m.name != nullptr && readable_text(m.name, kMaxNameBytes))
    return fmt::format("'{}'", m.name);
  return "(name unreadable)";
}

class CModule final : public chimera::Module {
 public:
  explicit CModule(const chimera_c_module& def)
      : def_(def), state_((def.state_size + sizeof(std::max_align_t) - 1) / sizeof(std::max_align_t)) {}

 protected:
  Status init(chimera::InitContext& ctx) override {
    ctx_.init = &ctx;
    ctx_.params.params = &ctx.params();
    ctx_.task_name = std::string(ctx.task_name());
    ctx_.source = &ctx.timing();
    ctx_.flags = &ctx.flags();
    refresh_timing();
    const Status s = def_.init != nullptr ? status_of(def_.init(state(), &ctx_)) : Status::ok();
    ctx_.init = nullptr;
    return s;
  }
  Status on() override { return call(def_.on); }
  Status cycle() override { return call(def_.cycle); }
  Status off() override { return call(def_.off); }
  Status kill() override { return call(def_.kill); }
  Status error() override {
    return def_.error != nullptr ? call(def_.error) : Status::fail("module has no error handler");
  }
  Status clear() override { return call(def_.clear); }
  Status reinit() override { return call(def_.reinit); }
  Status sync() override { return call(def_.sync); }

 private:
  using Method = chimera_status (*)(void*);

  // Real-time safe: three words copied, one indirect call.
  Status call(Method method) noexcept {
    if (method == nullptr) return Status::ok();
    refresh_timing();
    return status_of(method(state()));
  }
  void refresh_timing() noexcept {
    ctx_.timing = chimera_timing{ctx_.source->release_ns, ctx_.source->period_ns, ctx_.source->cycle};
  }
  void* state() noexcept { return state_.empty() ? nullptr : state_.data(); }

  const chimera_c_module& def_;
  std::vector<std::max_align_t> state_;  // zeroed, aligned for anything the module keeps there
  chimera_ctx ctx_;
};

}  // namespace

extern "C" {

void chimera_in_const(chimera_decl* d, const char* name, chimera_dim dim, const char* doc) {
  decl_of(d).in_const<double>(text_or_empty(name), dim_of(dim), text_or_empty(doc));
}
void chimera_in_var(chimera_decl* d, const char* name, chimera_dim dim, const char* doc) {
  decl_of(d).in_var<double>(text_or_empty(name), dim_of(dim), text_or_empty(doc));
}
void chimera_out_var(chimera_decl* d, const char* name, chimera_dim dim, const char* doc) {
  decl_of(d).out_var<double>(text_or_empty(name), dim_of(dim), text_or_empty(doc));
}
void chimera_out_const(chimera_decl* d, const char* name, const double* values, size_t count, const char* doc) {
  std::vector<double> v;
  if (values != nullptr) v.assign(values, values + count);
  decl_of(d).out_const(text_or_empty(name), std::move(v), text_or_empty(doc));
}
void chimera_param_number(chimera_decl* d, const char* name, double value, const char* unit, const char* doc) {
  decl_of(d).param(text_or_empty(name), value, text_or_empty(unit), text_or_empty(doc));
}
void chimera_param_bool(chimera_decl* d, const char* name, int value, const char* unit, const char* doc) {
  decl_of(d).param(text_or_empty(name), value != 0, text_or_empty(unit), text_or_empty(doc));
}
void chimera_param_string(chimera_decl* d, const char* name, const char* value, const char* unit, const char* doc) {
  decl_of(d).param(text_or_empty(name), text_or_empty(value), text_or_empty(unit), text_or_empty(doc));
}
void chimera_param_vector(chimera_decl* d, const char* name, const double* values, size_t count, const char* unit,
                          const char* doc) {
  chimera::Vector v;
  if (values != nullptr) v.assign(values, values + count);
  decl_of(d).param(text_or_empty(name), std::move(v), text_or_empty(unit), text_or_empty(doc));
}
namespace {
// The rule of a parameter the C module declared, or nullopt after refusing the module.
std::optional<chimera::ParamRuleBuilder> rule_for(chimera_decl* d, const char* name, const char* what) {
  chimera::ParamRule* rule = decl_of(d).rule_of(text_or_empty(name));
  if (rule == nullptr) {
    decl_of(d).refuse(fmt::format("{} for parameter '{}', which is not declared before it", what, text_or_empty(name)));
    return std::nullopt;
  }
  return chimera::ParamRuleBuilder(*rule);
}
}  // namespace

void chimera_param_at_least(chimera_decl* d, const char* name, double lower) {
  if (auto r = rule_for(d, name, "chimera_param_at_least")) r->at_least(lower);
}
void chimera_param_greater_than(chimera_decl* d, const char* name, double lower) {
  if (auto r = rule_for(d, name, "chimera_param_greater_than")) r->greater_than(lower);
}
void chimera_param_at_most(chimera_decl* d, const char* name, double upper) {
  if (auto r = rule_for(d, name, "chimera_param_at_most")) r->at_most(upper);
}
void chimera_param_less_than(chimera_decl* d, const char* name, double upper) {
  if (auto r = rule_for(d, name, "chimera_param_less_than")) r->less_than(upper);
}
void chimera_param_one_of(chimera_decl* d, const char* name, const char* const* choices, size_t count) {
  std::vector<std::string> list;
  for (size_t i = 0; choices != nullptr && i < count; ++i) list.emplace_back(text_or_empty(choices[i]));
  if (auto r = rule_for(d, name, "chimera_param_one_of")) r->one_of(std::move(list));
}
void chimera_param_whole(chimera_decl* d, const char* name) {
  if (auto r = rule_for(d, name, "chimera_param_whole")) r->whole();
}
void chimera_resource(chimera_decl* d, const char* what) { decl_of(d).resource(text_or_empty(what)); }

double chimera_number(const chimera_params* p, const char* name, double fallback) {
  return name != nullptr ? params_of(p).number(name, fallback) : fallback;
}
int chimera_flag(const chimera_params* p, const char* name, int fallback) {
  return name != nullptr ? static_cast<int>(params_of(p).flag(name, fallback != 0)) : fallback;
}
const char* chimera_text(const chimera_params* p, const char* name) {
  if (name == nullptr) return nullptr;
  const chimera::ParamValue* v = params_of(p).find(name);
  const auto* text = v != nullptr ? std::get_if<std::string>(v) : nullptr;
  return text != nullptr ? text->c_str() : nullptr;
}
size_t chimera_vector(const chimera_params* p, const char* name, double* out, size_t capacity) {
  if (name == nullptr) return 0;
  const chimera::ParamValue* v = params_of(p).find(name);
  const auto* vec = v != nullptr ? std::get_if<chimera::Vector>(v) : nullptr;
  if (vec == nullptr) return 0;
  for (size_t i = 0; i < vec->size() && i < capacity && out != nullptr; ++i) out[i] = (*vec)[i];
  return vec->size();
}

chimera_in chimera_input(chimera_ctx* ctx, const char* port) {
  if (ctx->init == nullptr || port == nullptr) return chimera_in{nullptr, 0, nullptr};
  const chimera::In<double> in = ctx->init->in<double>(port);  // a bad port makes init fail, naming it
  if (!in.bound()) return chimera_in{nullptr, 0, nullptr};
  ctx->inputs.push_back(in);
  return chimera_in{in.values().data(), in.size(), &ctx->inputs.back()};
}
chimera_out chimera_output(chimera_ctx* ctx, const char* port) {
  if (ctx->init == nullptr || port == nullptr) return chimera_out{nullptr, 0};
  const chimera::Out<double> out = ctx->init->out<double>(port);
  return chimera_out{out.bound() ? out.values().data() : nullptr, out.size()};
}
chimera_freshness chimera_fresh(chimera_in in) {
  if (in.port_ == nullptr) return CHIMERA_NO_DATA;
  return static_cast<chimera_freshness>(static_cast<const chimera::In<double>*>(in.port_)->freshness());
}

const chimera_params* chimera_ctx_params(const chimera_ctx* ctx) { return &ctx->params; }
const char* chimera_task_name(const chimera_ctx* ctx) { return ctx->task_name.c_str(); }
const chimera_timing* chimera_timing_of(const chimera_ctx* ctx) { return &ctx->timing; }
double chimera_period_s(const chimera_ctx* ctx) { return static_cast<double>(ctx->timing.period_ns) * 1e-9; }
chimera_status chimera_refuse(chimera_ctx* ctx, const char* param, chimera_status reason) {
  const chimera_status why = reason != nullptr ? reason : "refused";
  if (ctx == nullptr || ctx->init == nullptr || param == nullptr) return why;  // not in init: only the reason
  return ctx->init->refuse(param, why).reason();
}

int chimera_illegal_configuration(const chimera_ctx* ctx) {
  return static_cast<int>(ctx->flags->illegal_configuration());
}

void chimera_register_c_module(const chimera_c_module* module) {
  chimera::Registry& registry = chimera::Registry::global();
  if (module == nullptr) {
    registry.refuse("chimera_register_c_module was given NULL");
    return;
  }
  if (module->abi_version != CHIMERA_C_ABI_VERSION) {
    // Only the first field is read: it keeps its place in every version.
    registry.refuse(fmt::format("a C module was built for C ABI version {}, but this chimera has version {}",
                                module->abi_version, CHIMERA_C_ABI_VERSION));
    return;
  }
  if (const std::string problem = struct_problem(*module); !problem.empty()) {
    registry.refuse(fmt::format("C module {}: {} (was it built against another chimera/module/c_module.h?)",
                                name_for_message(*module), problem));
    return;
  }
  const std::string name = module->name;
  const chimera_c_module* def = module;
  (void)registry.add(
      chimera::ModuleInfo{name, text_or_empty(module->summary), text_or_empty(module->doc),
                          [def](Declarations& d, const Params& p) {
                            chimera_decl decl{&d};
                            const chimera_params params{&p};
                            def->declare(&decl, &params);
                          },
                          [def]() -> std::unique_ptr<chimera::Module> { return std::make_unique<CModule>(*def); }});
}

}  // extern "C"

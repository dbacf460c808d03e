#include "chimera/sim/arm_sim.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <system_error>

#include <mujoco/mujoco.h>

static_assert(sizeof(mjtNum) == sizeof(double), "Chimera's state variables are f64: MuJoCo must use double");

namespace chimera::sim {

namespace {

bool is_readable_file(const std::filesystem::path& p) {
  std::error_code ec;
  return std::filesystem::is_regular_file(p, ec);
}

// Every joint must be one hinge or slide driven by exactly one direct motor, in order, so that
// "joint i" means the same thing in qpos, qvel and ctrl.
Result<void> check_layout(const mjModel* m, const std::string& path) {
  const auto fail = [&](const std::string& why) {
    return Result<void>(make_error(Errc::kInvalidInput, "model '" + path + "': " + why));
  };
  if (m->nu < 1) return fail("it has no actuators");
  if (m->njnt != m->nu || m->nq != m->nu || m->nv != m->nu)
    return fail("needs one actuator per single-dof joint, but has " + std::to_string(m->nu) + " actuators, " +
                std::to_string(m->njnt) + " joints, nq " + std::to_string(m->nq) + ", nv " + std::to_string(m->nv));
  for (int i = 0; i < m->nu; ++i) {
    if (m->actuator_trntype[i] != mjTRN_JOINT || m->actuator_trnid[2 * static_cast<std::ptrdiff_t>(i)] != i)
      return fail("actuator " + std::to_string(i) + " must drive joint " + std::to_string(i));
    if (m->jnt_type[i] != mjJNT_HINGE && m->jnt_type[i] != mjJNT_SLIDE)
      return fail("joint " + std::to_string(i) + " must be a hinge or a slide");
  }
  return {};
}

constexpr std::uint64_t splitmix64(std::uint64_t& state) noexcept {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31U);
}

}  // namespace

std::vector<std::string> model_search_path() {
  // The user's own directories first, so a site can shadow the shipped model without rebuilding.
  std::vector<std::string> dirs;
  // NOLINTNEXTLINE(concurrency-mt-unsafe): read at load time; nothing in Chimera sets the environment
  if (const char* env = std::getenv("CHIMERA_MODEL_PATH"); env != nullptr) {
    std::string_view rest(env);
    while (!rest.empty()) {
      const auto colon = rest.find(':');
      const auto entry = rest.substr(0, colon);
      if (!entry.empty()) dirs.emplace_back(entry);
      if (colon == std::string_view::npos) break;
      rest.remove_prefix(colon + 1);
    }
  }
  // Both are compile-time paths from sim/CMakeLists.txt; a missing one is simply skipped.
#ifdef CHIMERA_SIM_MODEL_DIR
  dirs.emplace_back(CHIMERA_SIM_MODEL_DIR);
#endif
#ifdef CHIMERA_SIM_INSTALLED_MODEL_DIR
  dirs.emplace_back(CHIMERA_SIM_INSTALLED_MODEL_DIR);
#endif
  return dirs;
}

Result<std::string> find_model(std::string_view name) {
  const std::string wanted(name.empty() ? kDefaultModel : name);
  // An explicit path wins; a bare name is looked up like a program on PATH.
  if (is_readable_file(wanted)) return wanted;
  const std::filesystem::path rel(wanted);
  if (!rel.is_absolute()) {
    for (const auto& dir : model_search_path()) {
      const auto candidate = std::filesystem::path(dir) / rel;
      if (is_readable_file(candidate)) return candidate.string();
    }
  }
  // Name the directories in the message: a model that is "not found" is usually looked for in
  // the wrong place.
  std::string searched;
  for (const auto& dir : model_search_path()) searched += (searched.empty() ? "" : ", ") + dir;
  return make_error(Errc::kNotFound,
                    "model '" + wanted + "' not found" +
                        (rel.is_absolute() || searched.empty() ? std::string() : " (searched " + searched + ")"));
}

void ArmSim::ModelDeleter::operator()(mjModel_* m) const noexcept { mj_deleteModel(m); }
void ArmSim::DataDeleter::operator()(mjData_* d) const noexcept { mj_deleteData(d); }

ArmSim::~ArmSim() = default;

Result<std::unique_ptr<ArmSim>> ArmSim::load(std::string_view path, SensorNoise noise) {
  auto found = find_model(path);
  if (!found) return found.error();
  const std::string& file = *found;

  // MuJoCo reports parse errors (with line numbers) into this buffer rather than aborting.
  std::array<char, 1024> error{};
  mjModel* m = mj_loadXML(file.c_str(), nullptr, error.data(), static_cast<int>(error.size()));
  if (m == nullptr)
    return make_error(Errc::kInvalidInput, "cannot load model '" + file +
                                               "': " + (error[0] != '\0' ? error.data() : "unknown MuJoCo error"));
  std::unique_ptr<ArmSim> sim(new ArmSim());
  sim->model_.reset(m);
  if (auto ok = check_layout(m, file); !ok) return ok.error();

  // Simulated time is kept in whole steps of integer ns: exact sums, no floating-point drift.
  sim->timestep_ns_ = std::llround(m->opt.timestep * 1e9);
  if (sim->timestep_ns_ <= 0) return make_error(Errc::kInvalidInput, "model '" + file + "': timestep below 1 ns");
  sim->data_.reset(mj_makeData(m));
  if (!sim->data_) return make_error(Errc::kSystem, "model '" + file + "': MuJoCo could not allocate its data");

  sim->path_ = file;
  sim->ndof_ = m->nu;
  const auto n = static_cast<std::size_t>(m->nu);
  sim->qpos_adr_.resize(n);
  sim->dof_adr_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    sim->qpos_adr_[i] = m->jnt_qposadr[i];
    sim->dof_adr_[i] = m->jnt_dofadr[i];
  }
  // Sized once here: the real-time calls only overwrite them.
  sim->q_meas_.assign(n, 0.0);
  sim->qd_meas_.assign(n, 0.0);
  sim->noise_ = noise;
  sim->reset();
  return sim;
}

void ArmSim::set_torque(std::span<const double> tau) noexcept {
  mjData* d = data_.get();
  for (int i = 0; i < ndof_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double v = k < tau.size() ? tau[k] : 0.0;
    // A NaN from a faulty controller becomes zero torque rather than poisoning the simulation.
    d->ctrl[i] = std::isnan(v) ? 0.0 : std::clamp(v, torque_min(i), torque_max(i));
  }
}

std::span<const double> ArmSim::torque() const noexcept { return {data_->ctrl, static_cast<std::size_t>(ndof_)}; }

double ArmSim::torque_min(int i) const noexcept {
  const mjModel* m = model_.get();
  return m->actuator_ctrllimited[i] != 0 ? m->actuator_ctrlrange[2 * static_cast<std::ptrdiff_t>(i)] : -mjMAXVAL;
}

double ArmSim::torque_max(int i) const noexcept {
  const mjModel* m = model_.get();
  return m->actuator_ctrllimited[i] != 0 ? m->actuator_ctrlrange[2 * static_cast<std::ptrdiff_t>(i) + 1] : mjMAXVAL;
}

void ArmSim::step(std::int64_t dt_ns) noexcept {
  if (dt_ns <= 0) return;
  // A 1.5 ms period on a 1 ms model alternates 1 and 2 steps: the carry is what keeps the sum.
  carry_ns_ += dt_ns;
  const std::int64_t n = carry_ns_ / timestep_ns_;
  carry_ns_ -= n * timestep_ns_;
  const mjModel* m = model_.get();
  mjData* d = data_.get();
  for (std::int64_t k = 0; k < n; ++k) {
    mj_step(m, d);
    ++steps_;
    // MuJoCo sums timesteps in floating point; keep its clock on the exact integer one.
    d->time = time_s();
  }
  if (n > 0) measure();
}

// MuJoCo resets the data itself on a bad number and only counts a warning; the count is how a
// caller learns that the arm it sees is no longer the arm it was driving.
bool ArmSim::diverged() const noexcept {
  const mjData* d = data_.get();
  return d->warning[mjWARN_BADQPOS].number > 0 || d->warning[mjWARN_BADQVEL].number > 0 ||
         d->warning[mjWARN_BADQACC].number > 0;
}

void ArmSim::set_state(std::span<const double> q, std::span<const double> qd) noexcept {
  const mjModel* m = model_.get();
  mjData* d = data_.get();
  for (int i = 0; i < ndof_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    d->qpos[qpos_adr_[k]] = k < q.size() ? q[k] : 0.0;
    d->qvel[dof_adr_[k]] = k < qd.size() ? qd[k] : 0.0;
  }
  // A fresh state must not inherit the previous solver warm start (determinism after a jump).
  mju_zero(d->qacc_warmstart, m->nv);
  mj_forward(m, d);
  measure();
}

void ArmSim::reset() noexcept {
  mj_resetData(model_.get(), data_.get());
  steps_ = 0;
  carry_ns_ = 0;
  // The noise restarts too, so a reset run repeats the first one exactly.
  rng_ = noise_.seed;
  has_spare_ = false;
  mj_forward(model_.get(), data_.get());
  measure();
}

void ArmSim::set_gravity(const std::array<double, 3>& g) noexcept {
  for (int i = 0; i < 3; ++i) model_->opt.gravity[i] = g[static_cast<std::size_t>(i)];
}

// What a sensor would report: the true state, plus noise only in what is handed out.
void ArmSim::measure() noexcept {
  const mjData* d = data_.get();
  const bool noisy = noise_.position_std > 0.0 || noise_.velocity_std > 0.0;
  for (std::size_t i = 0; i < q_meas_.size(); ++i) {
    q_meas_[i] = d->qpos[qpos_adr_[i]];
    qd_meas_[i] = d->qvel[dof_adr_[i]];
    if (noisy) {
      q_meas_[i] += noise_.position_std * gaussian();
      qd_meas_[i] += noise_.velocity_std * gaussian();
    }
  }
}

// Box-Muller on splitmix64: a few lines, fully specified, so noise is identical on every
// platform and library (std::normal_distribution is implementation-defined).
double ArmSim::gaussian() noexcept {
  if (has_spare_) {
    has_spare_ = false;
    return spare_normal_;
  }
  constexpr double kScale = 1.0 / 9007199254740992.0;                               // 2^-53
  const double u1 = (static_cast<double>(splitmix64(rng_) >> 11U) + 1.0) * kScale;  // (0, 1]
  const double u2 = static_cast<double>(splitmix64(rng_) >> 11U) * kScale;
  const double r = std::sqrt(-2.0 * std::log(u1));
  const double phi = 2.0 * std::numbers::pi * u2;
  spare_normal_ = r * std::sin(phi);
  has_spare_ = true;
  return r * std::cos(phi);
}

}  // namespace chimera::sim

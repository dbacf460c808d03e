#include "chimera/sim/arm_sim.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
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
  for (auto* v : {&sim->target_, &sim->target_speed_, &sim->reference_, &sim->reference_speed_,
                  &sim->reference_acceleration_, &sim->feedforward_})
    v->assign(n, 0.0);
  sim->noise_ = noise;
  sim->reset();
  // The servo's default gains come from each joint's inertia in the model's reference posture.
  std::vector<mjtNum> inertia(n * n);
  mj_fullM(m, inertia.data(), sim->data_->qM);
  sim->reference_inertia_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto dof = static_cast<std::size_t>(sim->dof_adr_[i]);
    sim->reference_inertia_[i] = inertia[dof * n + dof];
  }
  sim->gains_ = sim->servo_gains(kDefaultServoBandwidthHz, kDefaultServoMaxSpeed);
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

double ArmSim::joint_min(int i) const noexcept {
  const mjModel* m = model_.get();
  return m->jnt_limited[i] != 0 ? m->jnt_range[2 * static_cast<std::ptrdiff_t>(i)]
                                : -std::numeric_limits<double>::infinity();
}

double ArmSim::joint_max(int i) const noexcept {
  const mjModel* m = model_.get();
  return m->jnt_limited[i] != 0 ? m->jnt_range[2 * static_cast<std::ptrdiff_t>(i) + 1]
                                : std::numeric_limits<double>::infinity();
}

void ArmSim::set_drive(Drive drive) noexcept {
  if (drive == Drive::kPosition && drive_ != Drive::kPosition) hold();
  drive_ = drive;
}

void ArmSim::set_position_target(std::span<const double> q) noexcept {
  // Successive targets a period apart give the target's speed, used until the next one is due.
  // A change faster than max_speed is a jump to go to, not a motion to follow.
  const std::int64_t elapsed_steps = std::max<std::int64_t>(steps_ - target_step_, 1);
  const double elapsed = static_cast<double>(elapsed_steps) * model_->opt.timestep;
  target_interval_ = elapsed_steps;
  target_step_ = steps_;
  for (int i = 0; i < ndof_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (k >= q.size() || std::isnan(q[k])) {
      target_speed_[k] = 0.0;
      continue;
    }
    const double next = std::clamp(q[k], joint_min(i), joint_max(i));
    const double speed = (next - target_[k]) / elapsed;
    target_speed_[k] = std::fabs(speed) <= gains_.max_speed[k] ? speed : 0.0;
    target_[k] = next;
  }
}

ServoGains ArmSim::servo_gains(double bandwidth_hz, double max_speed) const {
  const double w = 2.0 * std::numbers::pi * bandwidth_hz;
  ServoGains g;
  for (std::size_t i = 0; i < reference_inertia_.size(); ++i) {
    const double inertia = reference_inertia_[i];
    g.kp.push_back(inertia * w * w);
    g.kd.push_back(2.0 * inertia * w);
    g.max_speed.push_back(max_speed);
    const double torque = std::min(torque_max(static_cast<int>(i)), -torque_min(static_cast<int>(i)));
    g.max_acceleration.push_back(0.5 * torque / inertia);
  }
  return g;
}

Result<void> ArmSim::set_servo_gains(ServoGains gains) {
  const auto n = static_cast<std::size_t>(ndof_);
  if (gains.kp.size() != n || gains.kd.size() != n || gains.max_speed.size() != n || gains.max_acceleration.size() != n)
    return make_error(Errc::kInvalidInput,
                      "servo gains need " + std::to_string(n) + " entries each (kp, kd, max_speed, max_acceleration)");
  for (std::size_t i = 0; i < n; ++i) {
    if (!(gains.kp[i] >= 0.0) || !(gains.kd[i] >= 0.0) || !std::isfinite(gains.kp[i]) || !std::isfinite(gains.kd[i]))
      return make_error(Errc::kInvalidInput, "servo gains kp and kd must be finite and >= 0");
    if (!(gains.max_speed[i] > 0.0) || !(gains.max_acceleration[i] > 0.0))
      return make_error(Errc::kInvalidInput, "servo max_speed and max_acceleration must be > 0");
  }
  gains_ = std::move(gains);
  return {};
}

// The servo's reference stops where the arm is, and its target with it.
void ArmSim::hold() noexcept {
  const mjData* d = data_.get();
  for (std::size_t i = 0; i < reference_.size(); ++i) {
    reference_[i] = d->qpos[qpos_adr_[i]];
    target_[i] = reference_[i];
    target_speed_[i] = 0.0;
    reference_speed_[i] = 0.0;
    reference_acceleration_[i] = 0.0;
  }
  target_step_ = steps_;
  target_interval_ = 1;
}

// The reference's next step toward a target moving at speed u: the speed from which it can still
// stop on the target at max_acceleration a, on top of u, approached at no more than a, within
// +-max_speed. In discrete time, from speed N a dt the reference covers a dt^2 N (N + 1) / 2 while
// it stops, hence N below; and it never asks for more than reaches the target in this step.
// The acceleration is applied after this step's torque: semi-implicit Euler, as MuJoCo integrates
// the arm itself, so that a perfect model puts the arm on the next reference exactly.
void ArmSim::plan_reference(std::size_t k, double dt, bool target_moving) noexcept {
  const double e = target_[k] - reference_[k];
  const double a = gains_.max_acceleration[k];
  const double n = 0.5 * (std::sqrt(1.0 + 8.0 * std::fabs(e) / (a * dt * dt)) - 1.0);
  const double approach = std::min(n * a * dt, std::fabs(e) / dt);
  const double u = target_moving ? target_speed_[k] : 0.0;
  const double wanted = std::clamp(u + std::copysign(approach, e), -gains_.max_speed[k], gains_.max_speed[k]);
  reference_acceleration_[k] = std::clamp(wanted - reference_speed_[k], -a * dt, a * dt) / dt;
}

// One sample of the arm's own position servo, between mj_step1 (which computed the inertia,
// bias and passive forces of this state) and mj_step2.
void ArmSim::servo_control() noexcept {
  const mjModel* m = model_.get();
  mjData* d = data_.get();
  const double dt = m->opt.timestep;
  // A target not renewed when the next one was due has stopped moving.
  const bool target_moving = steps_ - target_step_ < target_interval_;
  for (std::size_t k = 0; k < reference_.size(); ++k) plan_reference(k, dt, target_moving);
  mj_mulM(m, d, feedforward_.data(), reference_acceleration_.data());
  for (int i = 0; i < ndof_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const int dof = dof_adr_[k];
    const double dynamics = feedforward_[static_cast<std::size_t>(dof)] + d->qfrc_bias[dof] - d->qfrc_passive[dof];
    const double tau = dynamics + gains_.kp[k] * (reference_[k] - d->qpos[qpos_adr_[k]]) +
                       gains_.kd[k] * (reference_speed_[k] - d->qvel[dof]);
    d->ctrl[i] = std::clamp(tau, torque_min(i), torque_max(i));
    reference_speed_[k] += reference_acceleration_[k] * dt;
    reference_[k] += reference_speed_[k] * dt;
  }
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
    if (drive_ == Drive::kPosition) {
      // MuJoCo's split step: the state-dependent terms at this instant, then the servo's torque
      // from them, then integration (with the Euler integrator the same as mj_step).
      mj_step1(m, d);
      servo_control();
      mj_step2(m, d);
    } else {
      mj_step(m, d);
    }
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
  hold();  // a servo in position mode holds the arm where it was put, not where it was
  measure();
}

void ArmSim::reset() noexcept {
  mj_resetData(model_.get(), data_.get());
  steps_ = 0;
  carry_ns_ = 0;
  // The noise restarts too, so a reset run repeats the first one exactly.
  gaussian_.reseed(noise_.seed);
  mj_forward(model_.get(), data_.get());
  hold();
  measure();
}

void ArmSim::set_gravity(const std::array<double, 3>& g) noexcept {
  for (int i = 0; i < 3; ++i) model_->opt.gravity[i] = g[static_cast<std::size_t>(i)];
}

Result<int> ArmSim::find_site(std::string_view name) const {
  const int id = mj_name2id(model_.get(), mjOBJ_SITE, std::string(name).c_str());
  if (id < 0) return make_error(Errc::kNotFound, "model '" + path_ + "' has no site '" + std::string(name) + "'");
  return id;
}

SitePose ArmSim::site_pose(int site) noexcept {
  // After mj_step the stored site poses are those of the state before the step: recompute them
  // from the present joint positions (kinematics only; the next step recomputes everything anyway).
  mj_kinematics(model_.get(), data_.get());
  const mjData* d = data_.get();
  SitePose pose;
  for (std::size_t i = 0; i < 3; ++i) pose.position[i] = d->site_xpos[3 * static_cast<std::ptrdiff_t>(site) + i];
  for (std::size_t i = 0; i < 9; ++i) pose.rotation[i] = d->site_xmat[9 * static_cast<std::ptrdiff_t>(site) + i];
  return pose;
}

// What a sensor would report: the true state, plus noise only in what is handed out.
void ArmSim::measure() noexcept {
  const mjData* d = data_.get();
  const bool noisy = noise_.position_std > 0.0 || noise_.velocity_std > 0.0;
  for (std::size_t i = 0; i < q_meas_.size(); ++i) {
    q_meas_[i] = d->qpos[qpos_adr_[i]];
    qd_meas_[i] = d->qvel[dof_adr_[i]];
    if (noisy) {
      q_meas_[i] += noise_.position_std * gaussian_.next();
      qd_meas_[i] += noise_.velocity_std * gaussian_.next();
    }
  }
}

}  // namespace chimera::sim

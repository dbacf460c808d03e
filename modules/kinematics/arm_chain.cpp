#include "kinematics/arm_chain.hpp"

#include <algorithm>
#include <limits>

#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/frames.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>
#include <urdf_model/model.h>
#include <urdf_parser/urdf_parser.h>

#include "chimera/sim/arm_sim.hpp"

namespace chimera::kinematics {
namespace {

KDL::Frame to_kdl(const urdf::Pose& p) {
  return {KDL::Rotation::Quaternion(p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w),
          KDL::Vector(p.position.x, p.position.y, p.position.z)};
}

// A URDF joint sits at the child link's origin and moves it about (or along) an axis given in
// the child's frame. KDL moves a segment about an axis through a point of the parent's frame and
// then applies the segment's tip frame, so the axis is turned into the parent's frame and the
// origin becomes both the joint's point and the segment's tip.
Result<KDL::Joint> to_kdl_joint(const urdf::Joint& j, const std::string& path) {
  const KDL::Frame origin = to_kdl(j.parent_to_joint_origin_transform);
  const KDL::Vector axis = origin.M * KDL::Vector(j.axis.x, j.axis.y, j.axis.z);
  switch (j.type) {
    case urdf::Joint::FIXED: return KDL::Joint(j.name, KDL::Joint::Fixed);
    case urdf::Joint::REVOLUTE:
    case urdf::Joint::CONTINUOUS: return KDL::Joint(j.name, origin.p, axis, KDL::Joint::RotAxis);
    case urdf::Joint::PRISMATIC: return KDL::Joint(j.name, origin.p, axis, KDL::Joint::TransAxis);
    default:
      return make_error(Errc::kInvalidInput, "URDF '" + path + "': joint '" + j.name +
                                                 "' is neither revolute, continuous, prismatic nor fixed");
  }
}

}  // namespace

ArmChain::ArmChain() = default;
ArmChain::~ArmChain() = default;

Result<std::unique_ptr<ArmChain>> ArmChain::load(std::string_view urdf, std::string_view base, std::string_view tip) {
  auto found = sim::find_model(urdf.empty() ? kDefaultUrdf : urdf);
  if (!found) return found.error();
  const std::string& path = *found;
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(path);
  if (!model) return make_error(Errc::kInvalidInput, "cannot read URDF '" + path + "' (urdfdom's message is above)");

  const std::string base_name(base);
  const std::string tip_name(tip);
  if (!model->getLink(base_name))
    return make_error(Errc::kInvalidInput, "URDF '" + path + "' has no link '" + base_name + "'");
  urdf::LinkConstSharedPtr link = model->getLink(tip_name);
  if (!link) return make_error(Errc::kInvalidInput, "URDF '" + path + "' has no link '" + tip_name + "'");

  // Walk up from the tip to the base, then build the chain from the base down.
  std::vector<urdf::JointConstSharedPtr> joints;
  while (link->name != base_name && link->parent_joint) {
    joints.push_back(link->parent_joint);
    link = model->getLink(link->parent_joint->parent_link_name);
  }
  if (link->name != base_name)
    return make_error(Errc::kInvalidInput,
                      "URDF '" + path + "': link '" + tip_name + "' is not below link '" + base_name + "'");
  std::reverse(joints.begin(), joints.end());

  std::unique_ptr<ArmChain> arm(new ArmChain());
  arm->chain_ = std::make_unique<KDL::Chain>();
  for (const auto& j : joints) {
    if (j->mimic)
      return make_error(Errc::kInvalidInput, "URDF '" + path + "': joint '" + j->name + "' mimics another joint");
    auto joint = to_kdl_joint(*j, path);
    if (!joint) return joint.error();
    arm->chain_->addSegment(KDL::Segment(j->child_link_name, *joint, to_kdl(j->parent_to_joint_origin_transform)));
    if (j->type == urdf::Joint::FIXED) continue;
    arm->joint_names_.push_back(j->name);
    const bool bounded = j->type != urdf::Joint::CONTINUOUS && j->limits;
    constexpr double kInf = std::numeric_limits<double>::infinity();
    arm->lower_.push_back(bounded ? j->limits->lower : -kInf);
    arm->upper_.push_back(bounded ? j->limits->upper : kInf);
  }
  arm->ndof_ = static_cast<int>(arm->joint_names_.size());
  if (arm->ndof_ < 1)
    return make_error(Errc::kInvalidInput,
                      "URDF '" + path + "': no moving joint between '" + base_name + "' and '" + tip_name + "'");
  if (arm->ndof_ > kMaxDof)
    return make_error(Errc::kInvalidInput, "URDF '" + path + "': " + std::to_string(arm->ndof_) +
                                               " joints between base and tip, more than the " +
                                               std::to_string(kMaxDof) + " the solvers take");
  arm->path_ = path;
  arm->fk_ = std::make_unique<KDL::ChainFkSolverPos_recursive>(*arm->chain_);
  arm->jac_solver_ = std::make_unique<KDL::ChainJntToJacSolver>(*arm->chain_);
  arm->q_ = std::make_unique<KDL::JntArray>(static_cast<unsigned int>(arm->ndof_));
  arm->jacobian_ = std::make_unique<KDL::Jacobian>(static_cast<unsigned int>(arm->ndof_));
  return arm;
}

void ArmChain::set_joints(std::span<const double> q) noexcept {
  for (int i = 0; i < ndof_; ++i) (*q_)(static_cast<unsigned int>(i)) = q[static_cast<std::size_t>(i)];
}

namespace {
Pose to_pose(const KDL::Frame& f) noexcept {
  Pose p;
  p.position = Eigen::Vector3d(f.p.x(), f.p.y(), f.p.z());
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) p.rotation(r, c) = f.M(r, c);
  return p;
}
}  // namespace

Pose ArmChain::forward(std::span<const double> q) noexcept {
  set_joints(q);
  KDL::Frame tip;
  (void)fk_->JntToCart(*q_, tip);  // fails only on a size mismatch, which load() rules out
  return to_pose(tip);
}

void ArmChain::evaluate(std::span<const double> q, Pose& pose, JacobianMatrix& jacobian) noexcept {
  set_joints(q);
  KDL::Frame tip;
  (void)fk_->JntToCart(*q_, tip);
  pose = to_pose(tip);
  // KDL's Jacobian: reference point at the tip, expressed in the base frame, rows [v; w].
  (void)jac_solver_->JntToJac(*q_, *jacobian_);
  jacobian = jacobian_->data;
}

}  // namespace chimera::kinematics

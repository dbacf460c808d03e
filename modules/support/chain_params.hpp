#pragma once
// The parameters that name an arm's kinematic chain, shared by the modules that compute through
// one (fwd_kin_jacobian, inv_kin). Not real-time safe.

#include <memory>

#include "chimera/core/result.hpp"
#include "chimera/module/declarations.hpp"
#include "chimera/module/params.hpp"
#include "kinematics/arm_chain.hpp"

namespace chimera::modules {

/// Declares urdf, base and tip.
void declare_chain_params(Declarations& d);

/// The chain those parameters name.
Result<std::unique_ptr<kinematics::ArmChain>> load_chain(const Params& p);

}  // namespace chimera::modules

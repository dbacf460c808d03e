#include "support/chain_params.hpp"

#include <string>

namespace chimera::modules {

void declare_chain_params(Declarations& d) {
  d.param("urdf", std::string(), "", "the arm's URDF; empty: the shipped arm6.urdf (the arm of arm6.xml)");
  d.param("base", std::string(kinematics::kDefaultBaseLink), "", "link of the base frame that poses are in");
  d.param("tip", std::string(kinematics::kDefaultTipLink), "", "link whose pose is x_m (the tool)");
}

Result<std::unique_ptr<kinematics::ArmChain>> load_chain(const Params& p) {
  return kinematics::ArmChain::load(p.text("urdf"), p.text("base", std::string(kinematics::kDefaultBaseLink)),
                                    p.text("tip", std::string(kinematics::kDefaultTipLink)));
}

}  // namespace chimera::modules

// Fault plugin: the Lagrangian and its derivatives are NaN (the host must stop with exit code 4,
// naming the non-finite value and the plugin).
#include <limits>

#include "fault_lagrangian.hpp"

class ReturnsNan : public varia::test::FaultLagrangian<ReturnsNan> {
 public:
  ReturnsNan(const nlohmann::json&, const varia::sdk::Context&) {}
  double evaluation() { return std::numeric_limits<double>::quiet_NaN(); }
};

VARIA_PLUGIN(ReturnsNan, lagrangian, fault_nan)

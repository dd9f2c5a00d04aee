// Fault plugin: every evaluation throws (the SDK turns it into a Status; the host must report the
// file with exit code 3).
#include <stdexcept>

#include "fault_lagrangian.hpp"

class ThrowsOnEvaluation : public varia::test::FaultLagrangian<ThrowsOnEvaluation> {
 public:
  ThrowsOnEvaluation(const nlohmann::json&, const varia::sdk::Context&) {}
  double evaluation() { throw std::runtime_error("deliberate failure in evaluate"); }
};

VARIA_PLUGIN(ThrowsOnEvaluation, lagrangian, fault_evaluate)

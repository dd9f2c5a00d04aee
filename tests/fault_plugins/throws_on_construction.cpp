// Fault plugin: the constructor throws (the SDK's factory turns it into a message; the host must
// report the file with exit code 3).
#include <stdexcept>

#include "fault_lagrangian.hpp"

class ThrowsOnConstruction : public varia::test::FaultLagrangian<ThrowsOnConstruction> {
 public:
  ThrowsOnConstruction(const nlohmann::json&, const varia::sdk::Context&) {
    throw std::runtime_error("deliberate failure in the constructor");
  }
};

VARIA_PLUGIN(ThrowsOnConstruction, lagrangian, fault_construct)

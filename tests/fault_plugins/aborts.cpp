// Fault plugin: an evaluation calls std::abort (SIGABRT raised from the C library, called by the
// plugin). The host must name this file on stderr and end with exit code 3.
#include <cstdlib>

#include "fault_lagrangian.hpp"

class Aborts : public varia::test::FaultAfter<Aborts> {
 public:
  Aborts(const nlohmann::json& parameters, const varia::sdk::Context&) : FaultAfter(parameters) {}
  static void fault() { std::abort(); }
};

VARIA_PLUGIN(Aborts, lagrangian, fault_abort)

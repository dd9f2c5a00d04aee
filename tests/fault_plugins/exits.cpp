// Fault plugin: an evaluation calls std::exit(0) in the middle of a run. The host must not end
// with exit code 0: it names this file and ends with exit code 3, the trajectory whole.
#include <cstdlib>

#include "fault_lagrangian.hpp"

class Exits : public varia::test::FaultAfter<Exits> {
 public:
  Exits(const nlohmann::json& parameters, const varia::sdk::Context&) : FaultAfter(parameters) {}
  static void fault() { std::exit(0); }
};

VARIA_PLUGIN(Exits, lagrangian, fault_exit)

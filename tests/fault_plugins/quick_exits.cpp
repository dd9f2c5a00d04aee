// Fault plugin: an evaluation calls std::quick_exit(0) (which runs no atexit handler) in the middle
// of a run. The host must name this file and end with exit code 3, the trajectory whole.
#include <cstdlib>

#include "fault_lagrangian.hpp"

class QuickExits : public varia::test::FaultAfter<QuickExits> {
 public:
  QuickExits(const nlohmann::json& parameters, const varia::sdk::Context&) : FaultAfter(parameters) {}
  static void fault() { std::quick_exit(0); }
};

VARIA_PLUGIN(QuickExits, lagrangian, fault_quick_exit)

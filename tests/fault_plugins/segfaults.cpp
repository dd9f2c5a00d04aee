// Fault plugin: an evaluation writes through a null pointer (SIGSEGV in the plugin's code). The host
// must name this file on stderr and end with exit code 3, stdout and the trajectory whole.
#include "fault_lagrangian.hpp"

namespace {
int* volatile nowhere = nullptr;  // volatile: the compiler cannot see that it is null
}

class Segfaults : public varia::test::FaultAfter<Segfaults> {
 public:
  Segfaults(const nlohmann::json& parameters, const varia::sdk::Context&) : FaultAfter(parameters) {}
  static void fault() { *nowhere = 1; }
};

VARIA_PLUGIN(Segfaults, lagrangian, fault_segfault)
